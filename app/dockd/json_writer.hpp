#pragma once
/// @file JsonWriter: one JSON object written field by field into a caller's fixed buffer — dockd's status, replies
/// and event lines all come from it.
///
/// Keys and strings are escaped (quote, backslash, control bytes as \u00XX); reals are printed with a fixed number of
/// decimals ("%.Nf"), a non-finite real as null. Once a field does not fit, that field and every later call write
/// nothing and finish() returns 0: a cut-off object never leaves. mark()/rollback() drop an optional group of fields
/// that did not fit and clear the overflow. No allocation; every call is O(bytes written).

#include <cstddef>
#include <cstdint>

namespace dockd {

class JsonWriter {
 public:
  /// Starts the object ("{") in `buf` of `size` bytes (≥ 3: "{}" and its terminator). `buf` must outlive the writer.
  JsonWriter(char* buf, std::size_t size);

  JsonWriter& str(const char* key, const char* value);  ///< "key":"value" (escaped); a null value writes "".
  /// "key":"value" escaped and cut at `max_bytes` of the value, then "..." when it was longer.
  JsonWriter& str_cut(const char* key, const char* value, std::size_t max_bytes);
  JsonWriter& boolean(const char* key, bool value);
  JsonWriter& uint(const char* key, std::uint64_t value);
  JsonWriter& sint(const char* key, std::int64_t value);
  /// "key":value with `decimals` (0–9) digits after the point; null when not finite.
  JsonWriter& real(const char* key, double value, int decimals);
  /// "key":[v0,v1,...] as real() writes each.
  JsonWriter& reals(const char* key, const double* values, std::size_t count, int decimals);
  JsonWriter& uints(const char* key, const std::uint32_t* values, std::size_t count);
  /// "key":value with `value` (`len` bytes, already JSON: an array or object its caller built) copied as it is.
  JsonWriter& raw(const char* key, const char* value, std::size_t len);
  /// Fields another writer made (its body(): `"k":v,...` without braces), copied as they are; nothing when empty.
  JsonWriter& fields(const char* body, std::size_t len);

  /// Where the object stands now, for rollback(); 0 once a field did not fit, so a rollback to it never clears an
  /// overflow that happened before the mark (the object stays refused).
  std::size_t mark() const { return ok_ ? len_ : 0; }
  /// Drops everything written after `m` (a mark()) and clears the overflow; nothing for a mark() of 0.
  void rollback(std::size_t m);
  /// Writes an optional group of fields (`write()` calls this writer) and drops the whole group when it did not fit,
  /// so the object keeps what came before it. O(bytes written by the group).
  template <class WriteGroup>
  JsonWriter& optional_group(WriteGroup&& write) {
    const std::size_t m = mark();
    write();
    if (!ok()) rollback(m);
    return *this;
  }
  /// False once a field did not fit (until a rollback).
  bool ok() const { return ok_; }
  /// The fields written so far (after "{"), not terminated; body_len() bytes.
  const char* body() const { return buf_ + 1; }
  std::size_t body_len() const { return len_ - 1; }

  /// Closes the object ("}") and terminates it; with `newline`, a '\n' follows the brace (an event line). Returns
  /// the length (without the terminator), or 0 when a field did not fit or the closing does not. Call once.
  std::size_t finish(bool newline = false);

 private:
  bool key(const char* k);
  bool put(const char* s, std::size_t n);
  bool put_escaped(const char* s, std::size_t max_bytes, bool* cut);
  bool put_real(double v, int decimals);

  char* buf_;
  std::size_t size_;
  std::size_t len_ = 0;
  bool ok_ = true;
  bool first_ = true;
};

}  // namespace dockd
