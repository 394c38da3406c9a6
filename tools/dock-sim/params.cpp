// dock-sim params: the parameter table (dockcore/params/param_table.hpp) as Markdown: one table's keys for dockd's
// config or a scenario, or the generated key tables of docs/dockd.md and docs/scenarios.md rewritten (--update) or
// checked (--check).
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "dockcore/params/param_table.hpp"

namespace docksim_cli {
namespace {

struct ParamsOptions {
  std::string table;
  std::string file_kind = "scenario";
  std::vector<std::string> update, check;
};

bool read_text(const std::string& path, std::string& out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream s;
  s << in.rdbuf();
  out = s.str();
  return !in.bad();
}

int run(const ParamsOptions& o) {
  if (o.update.empty() && o.check.empty()) {
    if (o.table.empty()) {
      std::fprintf(stderr, "dock-sim params: give --table, --update or --check\n");
      return 2;
    }
    const std::string md = dockcore::params::markdown_table(
        o.table, o.file_kind == "dockd" ? dockcore::params::kDockd : dockcore::params::kScenario);
    if (md.empty()) {
      std::fprintf(stderr, "dock-sim params: %s has no table '%s'\n", o.file_kind.c_str(), o.table.c_str());
      return 2;
    }
    std::fputs(md.c_str(), stdout);
    return 0;
  }
  int status = 0;
  for (int pass = 0; pass < 2; ++pass) {
    const bool write = pass == 0;
    for (const std::string& path : write ? o.update : o.check) {
      std::string text, error;
      if (!read_text(path, text)) {
        std::fprintf(stderr, "dock-sim params: cannot read %s\n", path.c_str());
        return 2;
      }
      const std::string fresh = dockcore::params::update_param_blocks(text, error);
      if (!error.empty()) {
        std::fprintf(stderr, "dock-sim params: %s: %s\n", path.c_str(), error.c_str());
        return 2;
      }
      if (fresh == text) continue;
      if (write) {
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        out << fresh;
        if (!out) {
          std::fprintf(stderr, "dock-sim params: cannot write %s\n", path.c_str());
          return 2;
        }
        std::printf("dock-sim params: updated %s\n", path.c_str());
      } else {
        std::fprintf(stderr,
                     "dock-sim params: %s: the key tables differ from the parameter table; regenerate them with "
                     "dock-sim params --update %s\n",
                     path.c_str(), path.c_str());
        status = 1;
      }
    }
  }
  return status;
}

}  // namespace

void register_params(CLI::App& app) {
  auto o = std::make_shared<ParamsOptions>();
  CLI::App* sub = app.add_subcommand(
      "params",
      "The parameter table every dockd config and scenario key of dockcore's core structs comes from: print one "
      "table's keys as Markdown, or regenerate (--update) / check (--check) the marked key tables of Markdown files "
      "(<!-- params dockd|scenario TABLE --> ... <!-- /params -->). Exit 0; 1 when --check finds a stale table; 2 for "
      "errors.");
  sub->add_option("--table", o->table, "TOML table to print, e.g. task, robot.limits, estimator.segments");
  sub->add_option("--for", o->file_kind, "Whose keys: dockd or scenario")->check(CLI::IsMember({"dockd", "scenario"}));
  sub->add_option("--update", o->update, "Markdown files whose marked tables are rewritten");
  sub->add_option("--check", o->check, "Markdown files whose marked tables must be current (exit 1 otherwise)");
  sub->callback([o]() {
    const int rc = run(*o);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace docksim_cli
