#pragma once
/// @file Reading the parameter table's keys (param_table.hpp) from TOML with the strict key reader: the handlers of
/// one table's keys for dockd or a scenario, each checking its type and the table's bounds and storing into the
/// core structs. Host-side start-up code: heap and exceptions are fine here.

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "dockcore/params/param_table.hpp"
#include "dockcore/params/toml_reader.hpp"

namespace dockcore::params {

/// The handler of one entry: checks the value (type, bounds, choices) and stores it through `t`. `t` must outlive
/// the handler. O(1) per value.
template <typename Error>
toml_reader::Handler param_handler(const toml_reader::Reader<Error>& p, const ParamSpec& s, const ParamTargets& t) {
  return [&p, &s, &t](const toml::node& n) {
    switch (s.type) {
      case ParamType::kReal:
      case ParamType::kDegrees:
        s.set(t, p.number(n, s.min, s.max));
        break;
      case ParamType::kInteger:
        s.set(t, static_cast<double>(p.integer(n, static_cast<std::int64_t>(s.min), static_cast<std::int64_t>(s.max))));
        break;
      case ParamType::kBool:
        s.set(t, p.boolean(n) ? 1.0 : 0.0);
        break;
      case ParamType::kChoice: {
        std::vector<std::string> words;
        for (std::size_t i = 0; i < choice_count(s); ++i) words.push_back(choice_word(s, i));
        const std::string w = p.choice(n, words);
        for (std::size_t i = 0; i < words.size(); ++i) {
          if (words[i] == w) s.set(t, static_cast<double>(i));
        }
        break;
      }
    }
  };
}

/// Appends to `h` the handlers of every entry of `table` that `use` takes. `t` must outlive the handlers.
/// O(table size).
template <typename Error>
void add_params(const toml_reader::Reader<Error>& p, toml_reader::Handlers& h, const std::string& table,
                const ParamTargets& t, ParamUse use) {
  std::size_t count = 0;
  const ParamSpec* all = param_table(count);
  for (std::size_t i = 0; i < count; ++i) {
    const ParamSpec& s = all[i];
    if ((s.use & use) != 0 && table == table_of(s, use)) h.emplace_back(s.key, param_handler(p, s, t));
  }
}

/// A sub-table handler made of the entries of `table` alone ("estimator.segments"). O(table size).
template <typename Error>
toml_reader::Handler param_sub(const toml_reader::Reader<Error>& p, const std::string& table, const ParamTargets& t,
                               ParamUse use) {
  return p.sub(table + ".", [&p, table, &t, use]() {
    toml_reader::Handlers h;
    add_params(p, h, table, t, use);
    return h;
  });
}

/// A number stored outside the core structs (a scenario's chassis, camera or sensor; `T` double or Real) under a key
/// that names the same quantity as a dockd entry of the table: it takes that entry's bounds (and, for kDegrees, its
/// degrees-in-the-file), so a value the simulation accepts is one the robot accepts. Throws std::logic_error when
/// the table has no such numeric dockd entry (a programming error, caught by the tests). O(table size).
template <typename Error, typename T>
toml_reader::Handler bounded_by(const toml_reader::Reader<Error>& p, const std::string& table, const std::string& key,
                                T* out) {
  const ParamSpec* s = find_param(table, key, kDockd);
  if (s == nullptr || (s->type != ParamType::kReal && s->type != ParamType::kDegrees)) {
    throw std::logic_error("parameter table has no number " + table + "." + key);
  }
  const bool degrees = s->type == ParamType::kDegrees;
  return [&p, s, out, degrees](const toml::node& n) {
    const double v = p.number(n, s->min, s->max);
    *out = static_cast<T>(degrees ? v * toml_reader::kDeg : v);
  };
}

}  // namespace dockcore::params
