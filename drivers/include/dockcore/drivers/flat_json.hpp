#pragma once
/// @file A byte-at-a-time parser for one flat JSON object ({"key": value, ...}; values are strings, numbers, true,
/// false or null — no nested objects or arrays). The UDP host commands and camera datagrams are such objects.
/// No heap: fixed field and string capacities; anything beyond them is an error, never a truncation. Cost O(bytes).

#include <cstddef>
#include <cstdint>

namespace dockcore::drivers {

/// Why a flat JSON object was refused.
enum class FlatJsonError : std::uint8_t {
  kOk = 0,
  kSyntax,         ///< Not a JSON object (bad character, missing quote/colon/comma/brace, trailing garbage).
  kNested,         ///< A value is an object or array.
  kTooManyFields,  ///< More than FlatJson::kMaxFields keys.
  kKeyTooLong,     ///< A key longer than FlatJson::kMaxKey - 1 bytes.
  kValueTooLong,   ///< A string or number longer than FlatJson::kMaxValue - 1 bytes.
  kBadEscape,      ///< A string escape other than \" \\ \/ \b \f \n \r \t (\u is refused: commands are ASCII).
  kBadNumber,      ///< A number that is not a JSON number.
  kDuplicateKey,   ///< The same key twice.
  kEmpty,          ///< Nothing but whitespace.
};

/// Stable snake_case name ("syntax", ...). Never null. O(1).
const char* to_string(FlatJsonError e);

/// The parsed object. Values are kept as text plus their kind; typed getters convert on demand.
class FlatJson {
 public:
  static constexpr std::size_t kMaxFields = 12;
  static constexpr std::size_t kMaxKey = 24;
  static constexpr std::size_t kMaxValue = 64;

  enum class Kind : std::uint8_t { kString, kNumber, kBool, kNull };

  /// Parses `len` bytes (no terminator needed; whitespace allowed around the object; one trailing newline is
  /// whitespace). On error the field list is empty. O(len).
  FlatJsonError parse(const char* data, std::size_t len);

  std::size_t size() const { return count_; }
  /// Key of field i (i < size()), NUL-terminated.
  const char* key(std::size_t i) const { return fields_[i].key; }
  /// True when `key` is present.
  bool has(const char* key) const { return find(key) != nullptr; }
  /// String value of `key`; false when absent or not a string.
  bool get_string(const char* key, const char*& out) const;
  /// Number value of `key` as a double; false when absent, not a number or not finite.
  bool get_number(const char* key, double& out) const;
  /// Integer value of `key` in [lo, hi]; false when absent, not a number, fractional, or out of range.
  bool get_int(const char* key, std::int64_t lo, std::int64_t hi, std::int64_t& out) const;
  bool get_bool(const char* key, bool& out) const;

 private:
  struct Field {
    char key[kMaxKey];
    char value[kMaxValue];
    Kind kind;
  };
  const Field* find(const char* key) const;

  Field fields_[kMaxFields];
  std::size_t count_ = 0;
};

}  // namespace dockcore::drivers
