#include "json_writer.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>

namespace dockd {

namespace {
// Room kept back by every field for finish(): "}", "\n" and the terminator.
constexpr std::size_t kReserve = 3;
}  // namespace

JsonWriter::JsonWriter(char* buf, std::size_t size) : buf_(buf), size_(size) {
  if (buf_ == nullptr || size_ < kReserve + 1) {
    ok_ = false;
    size_ = 0;
    return;
  }
  buf_[0] = '{';
  len_ = 1;
}

bool JsonWriter::put(const char* s, std::size_t n) {
  if (!ok_ || len_ + n + kReserve > size_) {
    ok_ = false;
    return false;
  }
  std::memcpy(buf_ + len_, s, n);
  len_ += n;
  return true;
}

bool JsonWriter::put_escaped(const char* s, std::size_t max_bytes, bool* cut) {
  static const char kHex[] = "0123456789abcdef";
  if (cut != nullptr) *cut = false;
  if (s == nullptr) return ok_;
  for (std::size_t i = 0; s[i] != '\0'; ++i) {
    if (i >= max_bytes) {
      if (cut != nullptr) *cut = true;
      break;
    }
    const unsigned char u = static_cast<unsigned char>(s[i]);
    if (s[i] == '"' || s[i] == '\\') {
      const char e[2] = {'\\', s[i]};
      if (!put(e, 2)) return false;
    } else if (u < 0x20) {
      const char e[6] = {'\\', 'u', '0', '0', kHex[u >> 4], kHex[u & 0xF]};
      if (!put(e, 6)) return false;
    } else if (!put(&s[i], 1)) {
      return false;
    }
  }
  return ok_;
}

bool JsonWriter::key(const char* k) {
  if (!ok_) return false;
  if (!first_ && !put(",", 1)) return false;
  if (!put("\"", 1) || !put_escaped(k, static_cast<std::size_t>(-1), nullptr) || !put("\":", 2)) return false;
  first_ = false;
  return true;
}

bool JsonWriter::put_real(double v, int decimals) {
  if (!std::isfinite(v)) return put("null", 4);
  char b[48];
  const int d = decimals < 0 ? 0 : (decimals > 9 ? 9 : decimals);
  const int n = std::snprintf(b, sizeof b, "%.*f", d, v);
  if (n <= 0 || static_cast<std::size_t>(n) >= sizeof b) return put("null", 4);  // beyond ±1e38: not a reading
  return put(b, static_cast<std::size_t>(n));
}

JsonWriter& JsonWriter::str(const char* k, const char* value) {
  return str_cut(k, value, static_cast<std::size_t>(-1));
}

JsonWriter& JsonWriter::str_cut(const char* k, const char* value, std::size_t max_bytes) {
  bool cut = false;
  if (key(k) && put("\"", 1) && put_escaped(value, max_bytes, &cut) && (!cut || put("...", 3))) put("\"", 1);
  return *this;
}

JsonWriter& JsonWriter::boolean(const char* k, bool value) {
  if (key(k)) put(value ? "true" : "false", value ? 4 : 5);
  return *this;
}

JsonWriter& JsonWriter::uint(const char* k, std::uint64_t value) {
  char b[24];
  const int n = std::snprintf(b, sizeof b, "%llu", static_cast<unsigned long long>(value));
  if (key(k)) put(b, static_cast<std::size_t>(n));
  return *this;
}

JsonWriter& JsonWriter::sint(const char* k, std::int64_t value) {
  char b[24];
  const int n = std::snprintf(b, sizeof b, "%lld", static_cast<long long>(value));
  if (key(k)) put(b, static_cast<std::size_t>(n));
  return *this;
}

JsonWriter& JsonWriter::real(const char* k, double value, int decimals) {
  if (key(k)) put_real(value, decimals);
  return *this;
}

JsonWriter& JsonWriter::reals(const char* k, const double* values, std::size_t count, int decimals) {
  if (!key(k) || !put("[", 1)) return *this;
  for (std::size_t i = 0; i < count; ++i) {
    if ((i > 0 && !put(",", 1)) || !put_real(values[i], decimals)) return *this;
  }
  put("]", 1);
  return *this;
}

JsonWriter& JsonWriter::uints(const char* k, const std::uint32_t* values, std::size_t count) {
  if (!key(k) || !put("[", 1)) return *this;
  for (std::size_t i = 0; i < count; ++i) {
    char b[16];
    const int n = std::snprintf(b, sizeof b, "%u", static_cast<unsigned>(values[i]));
    if ((i > 0 && !put(",", 1)) || !put(b, static_cast<std::size_t>(n))) return *this;
  }
  put("]", 1);
  return *this;
}

JsonWriter& JsonWriter::raw(const char* k, const char* value, std::size_t len) {
  if (key(k)) put(value, len);
  return *this;
}

JsonWriter& JsonWriter::fields(const char* body, std::size_t len) {
  if (len == 0 || !ok_) return *this;
  if (!first_ && !put(",", 1)) return *this;
  if (put(body, len)) first_ = false;
  return *this;
}

void JsonWriter::rollback(std::size_t m) {
  if (size_ == 0 || m < 1 || m > len_) return;
  len_ = m;
  first_ = m == 1;
  ok_ = true;
}

std::size_t JsonWriter::finish(bool newline) {
  if (!ok_ || size_ == 0) return 0;
  buf_[len_++] = '}';  // kReserve keeps room for these
  if (newline) buf_[len_++] = '\n';
  buf_[len_] = '\0';
  const std::size_t n = len_;
  ok_ = false;  // finished: nothing more is written
  return n;
}

}  // namespace dockd
