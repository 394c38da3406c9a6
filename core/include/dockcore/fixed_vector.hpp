#pragma once
/// @file Fixed-capacity vector: storage inline, no heap, no exceptions. push_back on a full vector fails and says so.

#include <cstddef>

namespace dockcore {

/// Vector of at most N trivially copyable elements held inline. Every operation is O(1) except clear-free copy.
template <typename T, std::size_t N>
class FixedVector {
 public:
  static constexpr std::size_t kCapacity = N;

  /// Appends v; returns false (and changes nothing) when full. O(1).
  bool push_back(const T& v) {
    if (size_ >= N) return false;
    data_[size_++] = v;
    return true;
  }
  /// Removes the last element; no-op when empty. O(1).
  void pop_back() {
    if (size_ > 0) --size_;
  }
  void clear() { size_ = 0; }
  /// Shrinks to n elements (n > size() is ignored). O(1).
  void truncate(std::size_t n) {
    if (n < size_) size_ = n;
  }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  bool full() const { return size_ == N; }
  static constexpr std::size_t capacity() { return N; }
  /// Element access; precondition i < size().
  T& operator[](std::size_t i) { return data_[i]; }
  const T& operator[](std::size_t i) const { return data_[i]; }
  T& back() { return data_[size_ - 1]; }
  const T& back() const { return data_[size_ - 1]; }
  T* begin() { return data_; }
  T* end() { return data_ + size_; }
  const T* begin() const { return data_; }
  const T* end() const { return data_ + size_; }
  T* data() { return data_; }
  const T* data() const { return data_; }

 private:
  T data_[N > 0 ? N : 1] = {};
  std::size_t size_ = 0;
};

}  // namespace dockcore
