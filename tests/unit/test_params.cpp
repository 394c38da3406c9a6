// The parameter table and the two files that read it: every key dockd's config and dock-sim's scenarios both take
// accepts the same values in both (found by walking both parsers' key lists, not by trusting the table), and the
// docs' generated key tables regenerate as they are.
#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include "config.hpp"
#include "dockcore/params/param_table.hpp"
#include "docksim/scenario.hpp"

#include "CppUTest/TestHarness.h"

namespace {

using dockcore::params::kDockd;
using dockcore::params::kScenario;
using dockcore::params::ParamUse;

// The scenario parser's controller-name list is a function-local static: made before the first test, so the leak
// check does not count it.
const bool kControllerNamesMade = !docksim::controller_names().empty();

/// The message of parsing `text` as `use`'s file, without its "t.toml:line:col: " prefix; "" when it parses.
std::string error_of(ParamUse use, const std::string& text) {
  std::string m;
  try {
    if (use == kDockd) {
      dockd::parse_config_toml(text, "t.toml");
    } else {
      docksim::parse_scenario_toml(text, "t.toml");
    }
  } catch (const dockd::ConfigError& e) {
    m = e.what();
  } catch (const docksim::ScenarioError& e) {
    m = e.what();
  }
  const std::string prefix = "t.toml:";
  if (m.compare(0, prefix.size(), prefix) == 0) {
    const std::size_t a = m.find(':', prefix.size());
    const std::size_t b = a == std::string::npos ? a : m.find(':', a + 1);
    if (b != std::string::npos) m = m.substr(b + 2);
  }
  return m;
}

/// TOML that sets `path` ("robot.limits.max_wheel_radps") to the literal `value`.
std::string set_text(const std::string& path, const std::string& value) {
  const std::size_t dot = path.rfind('.');
  if (dot == std::string::npos) return path + " = " + value + "\n";
  return "[" + path.substr(0, dot) + "]\n" + path.substr(dot + 1) + " = " + value + "\n";
}

/// The keys a table of `use`'s file takes ("" = the top level), from the parser's own unknown-key message.
std::set<std::string> keys_of(ParamUse use, const std::string& table) {
  const std::string probe = table.empty() ? std::string("zz_probe") : table + ".zz_probe";
  const std::string m = error_of(use, set_text(probe, "1"));
  const std::string open = "(expected ";
  const std::size_t a = m.find(open);
  const std::size_t b = m.rfind(')');
  std::set<std::string> out;
  if (a == std::string::npos || b == std::string::npos || b < a) return out;
  std::string list = m.substr(a + open.size(), b - a - open.size()) + ", ";
  for (std::size_t p = 0, q; (q = list.find(", ", p)) != std::string::npos; p = q + 2)
    out.insert(list.substr(p, q - p));
  return out;
}

/// What a refusal says about the accepted values: the range, the type or the choices; "" for any other outcome.
std::string verdict(const std::string& m) {
  for (const char* marker : {"is out of range [", "must be ", "is not one of "}) {
    const std::size_t a = m.find(marker);
    if (a != std::string::npos) return m.substr(a);
  }
  return m.empty() ? "accepted" : "";
}

struct Walk {
  std::size_t leaves = 0;  ///< Shared keys compared.
  std::vector<std::string> mismatches;
};

/// Compares every key both files take under `table`, recursing into the sub-tables both take.
void walk(const std::string& table, Walk& w) {
  const std::set<std::string> d = keys_of(kDockd, table), s = keys_of(kScenario, table);
  for (const std::string& k : d) {
    if (s.count(k) == 0) continue;
    const std::string path = table.empty() ? k : table + "." + k;
    bool is_table = false;
    for (const char* value : {"1e300", "9223372036854775807", "-9223372036854775807", "\"zz_probe\"", "true"}) {
      const std::string md = error_of(kDockd, set_text(path, value)), ms = error_of(kScenario, set_text(path, value));
      is_table = is_table || md.find("must be a table") != std::string::npos;
      const std::string vd = verdict(md), vs = verdict(ms);
      if ((!vd.empty() || !vs.empty()) && vd != vs) {
        w.mismatches.push_back(path + " = " + value + ": dockd '" + md + "', scenario '" + ms + "'");
      }
    }
    if (is_table) {
      walk(path, w);
    } else {
      ++w.leaves;
    }
  }
}

}  // namespace

TEST_GROUP(Params){};

TEST(Params, EveryKeyOfBothFilesAcceptsTheSameValues) {
  Walk w;
  walk("", w);
  for (const std::string& m : w.mismatches) std::printf("mismatch: %s\n", m.c_str());
  CHECK_EQUAL(0u, w.mismatches.size());
  // The walk must have found the shared keys (limits, footprint, task, estimator, controllers): about 80.
  CHECK(w.leaves >= 70);
}

TEST(Params, WalkSeesADifference) {
  // The comparison itself can fail: two different ranges are told apart.
  CHECK(verdict("k = 1e+300 is out of range [0, 500]") != verdict("k = 1e+300 is out of range [0, 1000]"));
  CHECK(keys_of(kDockd, "robot.limits").count("max_wheel_radps") == 1);
  CHECK(keys_of(kScenario, "robot.limits").count("max_wheel_radps") == 1);
}

TEST(Params, TableEntriesAreConsistent) {
  std::size_t n = 0;
  const dockcore::params::ParamSpec* t = dockcore::params::param_table(n);
  std::set<std::string> seen[2];
  for (std::size_t i = 0; i < n; ++i) {
    CHECK(t[i].min <= t[i].max);
    CHECK(t[i].meaning != nullptr && t[i].meaning[0] != '\0');
    for (const ParamUse use : {kDockd, kScenario}) {
      if ((t[i].use & use) == 0) continue;
      const std::string path = std::string(dockcore::params::table_of(t[i], use)) + "." + t[i].key;
      CHECK_TEXT(seen[use - 1].insert(path).second, path.c_str());  // each key once per file
    }
  }
}

TEST(Params, DefaultsInTheDocsAreTheParsersDefaults) {
  // An empty file leaves every table key at the default the generated docs print.
  const dockd::DockdConfig c = dockd::parse_config_toml("", "t.toml");
  const docksim::Scenario sc = docksim::parse_scenario_toml("", "t.toml");
  CHECK(c.limits.max_wheel_radps == dockcore::DriveLimits{}.max_wheel_radps);
  CHECK(c.task.max_retries == dockcore::TaskParams{}.max_retries);
  CHECK(sc.task.max_retries == dockcore::TaskParams{}.max_retries);
  // The scenarios' simulated robot drives at 0.4 m/s by default, and the docs say so.
  CHECK(sc.limits.max_vx_mps == static_cast<dockcore::Real>(0.4));
  const std::string md = dockcore::params::markdown_table("robot.limits", kScenario);
  CHECK(md.find("| `max_vx_mps` | m/s | 0.4 | 0–5 |") != std::string::npos);
}

TEST(Params, DocBlocksRegenerateAndBadMarkersAreReported) {
  std::string error;
  const std::string doc = "intro\n<!-- params dockd task -->\nold rows\n<!-- /params -->\nafter\n";
  const std::string fresh = dockcore::params::update_param_blocks(doc, error);
  STRCMP_EQUAL("", error.c_str());
  CHECK(fresh.find("| `max_retries` | – | 3 | 0–20 |") != std::string::npos);
  CHECK(fresh.find("old rows") == std::string::npos);
  CHECK(fresh.find("after\n") != std::string::npos);
  STRCMP_EQUAL(fresh.c_str(), dockcore::params::update_param_blocks(fresh, error).c_str());
  dockcore::params::update_param_blocks("<!-- params dockd nowhere -->\n<!-- /params -->\n", error);
  CHECK(error.find("nowhere") != std::string::npos);
  dockcore::params::update_param_blocks("<!-- params dockd task -->\nrows\n", error);
  CHECK(error.find("without") != std::string::npos);
}
