#pragma once
/// Strict TOML key reader shared by dockd's config (app/dockd/config.cpp) and dock-sim's scenarios
/// (tools/sim/src/scenario.cpp): every key of a table is dispatched to a handler; an unknown key, a wrong type or a
/// value out of range is an `Error` carrying "source:line:col: message" and the position. Host-side start-up code:
/// heap and exceptions are fine here (never in core).
///
/// Usage: build a `Handlers` list of (key, handler) pairs with the factories (num, real, integ, flag, str, sub, ...)
/// and call each(table, "section.", handlers). Cost: O(keys × handlers) per table.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <toml++/toml.h>

#include "dockcore/geometry.hpp"

namespace dockcore::params::toml_reader {

inline constexpr double kDeg = 3.14159265358979323846 / 180.0;

using Handler = std::function<void(const toml::node&)>;
using Handlers = std::vector<std::pair<std::string, Handler>>;

/// "a table", "an integer", ...: for "must be X, not Y" messages.
inline const char* type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::date: return "a date";
    case toml::node_type::time: return "a time";
    case toml::node_type::date_time: return "a date-time";
    default: return "nothing";
  }
}

/// Directory part of `path` with its trailing '/' ("" for a bare name): relative file references resolve from the
/// file that names them.
inline std::string dir_of(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

/// `Error` must be constructible as Error(message, line, column).
template <typename Error>
class Reader {
 public:
  /// `source` names the text in messages (a file path, or e.g. "<string>").
  explicit Reader(std::string source) : src_(std::move(source)) {}

  [[noreturn]] void fail(const toml::source_region& where, const std::string& what) const {
    const int line = static_cast<int>(where.begin.line);
    const int col = static_cast<int>(where.begin.column);
    throw Error(src_ + ":" + std::to_string(line) + ":" + std::to_string(col) + ": " + what, line, col);
  }

  /// Dispatches every key of `t` to its handler; unknown keys are errors naming the expected ones. `path` is the
  /// table's prefix in messages ("robot.").
  void each(const toml::table& t, const std::string& path, const Handlers& hs) const {
    for (auto&& [key, value] : t) {
      const std::string k(key.str());
      const Handler* h = nullptr;
      for (const auto& p : hs) {
        if (p.first == k) h = &p.second;
      }
      if (h == nullptr) {
        std::string expected;
        for (const auto& p : hs) expected += (expected.empty() ? "" : ", ") + p.first;
        fail(key.source(), "unknown key '" + path + k + "' (expected " + expected + ")");
      }
      key_ = path + k;
      where_[key_] = value.source();
      (*h)(value);
    }
  }

  const toml::table& table(const toml::node& n) const {
    const toml::table* t = n.as_table();
    if (t == nullptr) fail(n.source(), key_ + " must be a table, not " + type_name(n));
    return *t;
  }

  /// An integer or float in [lo, hi], finite.
  double number(const toml::node& n, double lo, double hi) const {
    double v = 0;
    if (const auto* f = n.as_floating_point()) {
      v = f->get();
    } else if (const auto* i = n.as_integer()) {
      v = static_cast<double>(i->get());
    } else {
      fail(n.source(), key_ + " must be a number, not " + type_name(n));
    }
    if (!std::isfinite(v)) fail(n.source(), key_ + " is not finite");
    if (v < lo || v > hi) {
      std::ostringstream s;
      s << key_ << " = " << v << " is out of range [" << lo << ", " << hi << "]";
      fail(n.source(), s.str());
    }
    return v;
  }

  std::int64_t integer(const toml::node& n, std::int64_t lo, std::int64_t hi) const {
    const auto* i = n.as_integer();
    if (i == nullptr) fail(n.source(), key_ + " must be an integer, not " + type_name(n));
    const std::int64_t v = i->get();
    if (v < lo || v > hi) {
      fail(n.source(), key_ + " = " + std::to_string(v) + " is out of range [" + std::to_string(lo) + ", " +
                           std::to_string(hi) + "]");
    }
    return v;
  }

  bool boolean(const toml::node& n) const {
    const auto* b = n.as_boolean();
    if (b == nullptr) fail(n.source(), key_ + " must be true or false, not " + type_name(n));
    return b->get();
  }

  std::string string(const toml::node& n) const {
    const auto* s = n.as_string();
    if (s == nullptr) fail(n.source(), key_ + " must be a string, not " + type_name(n));
    return s->get();
  }

  /// A string that must be one of `options`.
  std::string choice(const toml::node& n, const std::vector<std::string>& options) const {
    const std::string s = string(n);
    if (std::find(options.begin(), options.end(), s) == options.end()) {
      std::string all;
      for (const auto& o : options) all += (all.empty() ? "" : ", ") + o;
      fail(n.source(), key_ + " = \"" + s + "\" is not one of " + all);
    }
    return s;
  }

  // Handler factories: each stores the checked value through the pointer.
  Handler num(double* out, double lo, double hi) const {
    return [this, out, lo, hi](const toml::node& n) { *out = number(n, lo, hi); };
  }
  /// Given in degrees, stored in radians.
  Handler deg(double* out_rad, double lo_deg, double hi_deg) const {
    return [this, out_rad, lo_deg, hi_deg](const toml::node& n) { *out_rad = number(n, lo_deg, hi_deg) * kDeg; };
  }
  Handler real(Real* out, double lo, double hi) const {
    return [this, out, lo, hi](const toml::node& n) { *out = static_cast<Real>(number(n, lo, hi)); };
  }
  /// Given in degrees, stored in radians.
  Handler real_deg(Real* out_rad, double lo_deg, double hi_deg) const {
    return [this, out_rad, lo_deg, hi_deg](const toml::node& n) {
      *out_rad = static_cast<Real>(number(n, lo_deg, hi_deg) * kDeg);
    };
  }
  template <typename T>
  Handler integ(T* out, std::int64_t lo, std::int64_t hi) const {
    return [this, out, lo, hi](const toml::node& n) { *out = static_cast<T>(integer(n, lo, hi)); };
  }
  Handler flag(bool* out) const {
    return [this, out](const toml::node& n) { *out = boolean(n); };
  }
  Handler str(std::string* out) const {
    return [this, out](const toml::node& n) { *out = string(n); };
  }
  /// A sub-table read with the handlers `make` builds (built when the table is met, so they may refer to state set
  /// by earlier keys).
  Handler sub(const std::string& path, std::function<Handlers()> make) const {
    return [this, path, make](const toml::node& n) { each(table(n), path, make()); };
  }

  /// The key being read ("section.key"), for messages of custom handlers.
  const std::string& key() const { return key_; }
  const std::string& src() const { return src_; }
  /// Whether `key` ("section.key") was given in the text read so far.
  bool given(const std::string& key) const { return where_.find(key) != where_.end(); }
  /// Where `key` ("section.key") was given; `fallback` when it was not (cross-key errors point at the key).
  toml::source_region where(const std::string& key, const toml::source_region& fallback) const {
    const auto it = where_.find(key);
    return it != where_.end() ? it->second : fallback;
  }

 private:
  std::string src_;
  mutable std::string key_;
  mutable std::map<std::string, toml::source_region> where_;
};

}  // namespace dockcore::params::toml_reader
