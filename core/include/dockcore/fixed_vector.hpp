#pragma once
/// @file Fixed-capacity vector: storage inline, no heap, no exceptions. push_back on a full vector fails and says so.
///
/// Two parts, as in ETL: FixedVectorBase<T> is the capacity-free vector every algorithm takes (so one function serves
/// a 720-point board and a 4096-point one), FixedVector<T, N> owns the N elements.

#include <cstddef>

namespace dockcore {

/// A vector of trivially copyable elements over storage it does not own (FixedVector<T, N> gives it). Every
/// operation is O(1). Not copyable by itself: copy the owners.
template <typename T>
class FixedVectorBase {
 public:
  FixedVectorBase(const FixedVectorBase&) = delete;
  FixedVectorBase& operator=(const FixedVectorBase&) = delete;

  /// Appends v; returns false (and changes nothing) when full. O(1).
  bool push_back(const T& v) {
    if (size_ >= capacity_) return false;
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
  bool full() const { return size_ == capacity_; }
  std::size_t capacity() const { return capacity_; }
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

 protected:
  FixedVectorBase(T* storage, std::size_t capacity) : data_(storage), capacity_(capacity) {}
  ~FixedVectorBase() = default;
  /// Takes other's elements (at most capacity()). O(size).
  void assign_from(const FixedVectorBase& other) {
    size_ = other.size_ < capacity_ ? other.size_ : capacity_;
    for (std::size_t i = 0; i < size_; ++i) data_[i] = other.data_[i];
  }

 private:
  T* data_;
  std::size_t capacity_;
  std::size_t size_ = 0;
};

/// Vector of at most N trivially copyable elements held inline.
template <typename T, std::size_t N>
class FixedVector : public FixedVectorBase<T> {
 public:
  static constexpr std::size_t kCapacity = N;

  FixedVector() : FixedVectorBase<T>(data_, N) {}
  FixedVector(const FixedVector& other) : FixedVectorBase<T>(data_, N) { this->assign_from(other); }
  FixedVector& operator=(const FixedVector& other) {
    if (this != &other) this->assign_from(other);
    return *this;
  }
  ~FixedVector() = default;

 private:
  T data_[N > 0 ? N : 1] = {};
};

}  // namespace dockcore
