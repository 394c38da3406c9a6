#include "dockcore/drivers/flat_json.hpp"

#include <cmath>
#include <cstdlib>
#include <cstring>

namespace dockcore::drivers {

const char* to_string(FlatJsonError e) {
  switch (e) {
    case FlatJsonError::kOk: return "ok";
    case FlatJsonError::kSyntax: return "syntax";
    case FlatJsonError::kNested: return "nested";
    case FlatJsonError::kTooManyFields: return "too_many_fields";
    case FlatJsonError::kKeyTooLong: return "key_too_long";
    case FlatJsonError::kValueTooLong: return "value_too_long";
    case FlatJsonError::kBadEscape: return "bad_escape";
    case FlatJsonError::kBadNumber: return "bad_number";
    case FlatJsonError::kDuplicateKey: return "duplicate_key";
    case FlatJsonError::kEmpty: return "empty";
  }
  return "?";
}

namespace {

enum class St : std::uint8_t {
  kStart,       // before '{'
  kKeyOrEnd,    // after '{': '"' or '}'
  kKeyStart,    // after ',': '"'
  kKey,         // inside a key string
  kKeyEscape,   // after '\' in a key
  kColon,       // after a key
  kValueStart,  // after ':'
  kString,      // inside a string value
  kStringEscape,
  kNumber,
  kLiteral,     // true / false / null
  kCommaOrEnd,  // after a value
  kDone,        // after '}': whitespace only
};

bool is_ws(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }
bool is_num_char(char c) { return (c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.' || c == 'e' || c == 'E'; }

/// JSON number grammar: -?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?
bool valid_number(const char* s) {
  std::size_t i = 0;
  if (s[i] == '-') ++i;
  if (s[i] == '0') {
    ++i;
  } else if (s[i] >= '1' && s[i] <= '9') {
    while (s[i] >= '0' && s[i] <= '9') ++i;
  } else {
    return false;
  }
  if (s[i] == '.') {
    ++i;
    if (!(s[i] >= '0' && s[i] <= '9')) return false;
    while (s[i] >= '0' && s[i] <= '9') ++i;
  }
  if (s[i] == 'e' || s[i] == 'E') {
    ++i;
    if (s[i] == '+' || s[i] == '-') ++i;
    if (!(s[i] >= '0' && s[i] <= '9')) return false;
    while (s[i] >= '0' && s[i] <= '9') ++i;
  }
  return s[i] == '\0';
}

}  // namespace

FlatJsonError FlatJson::parse(const char* data, std::size_t len) {
  count_ = 0;
  St st = St::kStart;
  std::size_t klen = 0, vlen = 0;
  Field* cur = nullptr;
  bool any = false;
  auto fail = [this](FlatJsonError e) {
    count_ = 0;
    return e;
  };
  // Closes the current value: terminates it, validates numbers and literals, rejects duplicate keys.
  auto finish_value = [&](Kind kind) -> FlatJsonError {
    cur->value[vlen] = '\0';
    cur->kind = kind;
    if (kind == Kind::kNumber && !valid_number(cur->value)) return FlatJsonError::kBadNumber;
    if (kind == Kind::kBool || kind == Kind::kNull) {
      const char* v = cur->value;
      if (std::strcmp(v, "true") == 0 || std::strcmp(v, "false") == 0) {
        cur->kind = Kind::kBool;
      } else if (std::strcmp(v, "null") == 0) {
        cur->kind = Kind::kNull;
      } else {
        return FlatJsonError::kSyntax;
      }
    }
    for (std::size_t i = 0; i < count_; ++i) {
      if (std::strcmp(fields_[i].key, cur->key) == 0) return FlatJsonError::kDuplicateKey;
    }
    ++count_;
    return FlatJsonError::kOk;
  };

  for (std::size_t i = 0; i <= len; ++i) {
    // One extra step with c = '\0' ends a number or literal that runs to the end of the input.
    const bool end = i == len;
    const char c = end ? '\0' : data[i];
    if (!end && !is_ws(c)) any = true;
    switch (st) {
      case St::kStart:
        if (end) break;
        if (is_ws(c)) continue;
        if (c != '{') return fail(FlatJsonError::kSyntax);
        st = St::kKeyOrEnd;
        continue;
      case St::kKeyOrEnd:
      case St::kKeyStart:
        if (end) break;
        if (is_ws(c)) continue;
        if (c == '}' && st == St::kKeyOrEnd) {
          st = St::kDone;
          continue;
        }
        if (c != '"') return fail(FlatJsonError::kSyntax);
        if (count_ >= kMaxFields) return fail(FlatJsonError::kTooManyFields);
        cur = &fields_[count_];
        klen = 0;
        st = St::kKey;
        continue;
      case St::kKey:
        if (end) break;
        if (c == '"') {
          cur->key[klen] = '\0';
          st = St::kColon;
          continue;
        }
        if (c == '\\') {
          st = St::kKeyEscape;
          continue;
        }
        if (static_cast<unsigned char>(c) < 0x20) return fail(FlatJsonError::kSyntax);
        if (klen + 1 >= kMaxKey) return fail(FlatJsonError::kKeyTooLong);
        cur->key[klen++] = c;
        continue;
      case St::kKeyEscape:
      case St::kStringEscape: {
        if (end) break;
        char out;
        switch (c) {
          case '"': out = '"'; break;
          case '\\': out = '\\'; break;
          case '/': out = '/'; break;
          case 'b': out = '\b'; break;
          case 'f': out = '\f'; break;
          case 'n': out = '\n'; break;
          case 'r': out = '\r'; break;
          case 't': out = '\t'; break;
          default: return fail(FlatJsonError::kBadEscape);
        }
        if (st == St::kKeyEscape) {
          if (klen + 1 >= kMaxKey) return fail(FlatJsonError::kKeyTooLong);
          cur->key[klen++] = out;
          st = St::kKey;
        } else {
          if (vlen + 1 >= kMaxValue) return fail(FlatJsonError::kValueTooLong);
          cur->value[vlen++] = out;
          st = St::kString;
        }
        continue;
      }
      case St::kColon:
        if (end) break;
        if (is_ws(c)) continue;
        if (c != ':') return fail(FlatJsonError::kSyntax);
        st = St::kValueStart;
        continue;
      case St::kValueStart:
        if (end) break;
        if (is_ws(c)) continue;
        vlen = 0;
        if (c == '"') {
          st = St::kString;
        } else if (c == '{' || c == '[') {
          return fail(FlatJsonError::kNested);
        } else if (is_num_char(c)) {
          cur->value[vlen++] = c;
          st = St::kNumber;
        } else if (c == 't' || c == 'f' || c == 'n') {
          cur->value[vlen++] = c;
          st = St::kLiteral;
        } else {
          return fail(FlatJsonError::kSyntax);
        }
        continue;
      case St::kString:
        if (end) break;
        if (c == '"') {
          const FlatJsonError e = finish_value(Kind::kString);
          if (e != FlatJsonError::kOk) return fail(e);
          st = St::kCommaOrEnd;
          continue;
        }
        if (c == '\\') {
          st = St::kStringEscape;
          continue;
        }
        if (static_cast<unsigned char>(c) < 0x20) return fail(FlatJsonError::kSyntax);
        if (vlen + 1 >= kMaxValue) return fail(FlatJsonError::kValueTooLong);
        cur->value[vlen++] = c;
        continue;
      case St::kNumber:
      case St::kLiteral: {
        const bool more = st == St::kNumber ? is_num_char(c) : (c >= 'a' && c <= 'z');
        if (!end && more) {
          if (vlen + 1 >= kMaxValue) return fail(st == St::kNumber ? FlatJsonError::kBadNumber : FlatJsonError::kSyntax);
          cur->value[vlen++] = c;
          continue;
        }
        const FlatJsonError e = finish_value(st == St::kNumber ? Kind::kNumber : Kind::kBool);
        if (e != FlatJsonError::kOk) return fail(e);
        st = St::kCommaOrEnd;
        if (end) break;
        // The byte that ended the value is handled as the start of what follows it.
        if (is_ws(c)) continue;
        if (c == ',') {
          st = St::kKeyStart;
          continue;
        }
        if (c == '}') {
          st = St::kDone;
          continue;
        }
        return fail(FlatJsonError::kSyntax);
      }
      case St::kCommaOrEnd:
        if (end) break;
        if (is_ws(c)) continue;
        if (c == ',') {
          st = St::kKeyStart;
          continue;
        }
        if (c == '}') {
          st = St::kDone;
          continue;
        }
        return fail(FlatJsonError::kSyntax);
      case St::kDone:
        if (end) break;
        if (is_ws(c)) continue;
        return fail(FlatJsonError::kSyntax);
    }
  }
  if (!any) return fail(FlatJsonError::kEmpty);
  if (st != St::kDone) return fail(FlatJsonError::kSyntax);
  return FlatJsonError::kOk;
}

const FlatJson::Field* FlatJson::find(const char* key) const {
  for (std::size_t i = 0; i < count_; ++i) {
    if (std::strcmp(fields_[i].key, key) == 0) return &fields_[i];
  }
  return nullptr;
}

bool FlatJson::get_string(const char* key, const char*& out) const {
  const Field* f = find(key);
  if (f == nullptr || f->kind != Kind::kString) return false;
  out = f->value;
  return true;
}

bool FlatJson::get_number(const char* key, double& out) const {
  const Field* f = find(key);
  if (f == nullptr || f->kind != Kind::kNumber) return false;
  char* endp = nullptr;
  const double v = std::strtod(f->value, &endp);
  if (endp == f->value || *endp != '\0' || !std::isfinite(v)) return false;
  out = v;
  return true;
}

bool FlatJson::get_int(const char* key, std::int64_t lo, std::int64_t hi, std::int64_t& out) const {
  double v = 0;
  if (!get_number(key, v)) return false;
  if (v != std::floor(v) || v < static_cast<double>(lo) || v > static_cast<double>(hi)) return false;
  out = static_cast<std::int64_t>(v);
  return true;
}

bool FlatJson::get_bool(const char* key, bool& out) const {
  const Field* f = find(key);
  if (f == nullptr || f->kind != Kind::kBool) return false;
  out = f->value[0] == 't';
  return true;
}

}  // namespace dockcore::drivers
