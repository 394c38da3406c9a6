#pragma once
/// @file The command-line tools' answer to an argument error (dockctl, dock-sim): CLI11's message and exit status 2,
/// 0 for --help; an unknown option or word where the subcommand belongs is named, a word with the valid
/// subcommands (CLI11 would only say that a subcommand is required). Header-only; the tool links CLI11.
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace dockcore::cli {

/// Reports `e`, raised by `app.parse`, on stderr as `program: ...` and returns the tool's exit status (0 or 2).
inline int exit_for_parse_error(CLI::App& app, const CLI::ParseError& e, const char* program) {
  const std::vector<std::string> rest = app.remaining();
  if (app.get_subcommands().empty() && !rest.empty()) {
    if (rest.front().rfind('-', 0) == 0) {
      std::fprintf(stderr, "%s: unknown option '%s'\nRun with --help for more information.\n", program,
                   rest.front().c_str());
      return 2;
    }
    std::string valid;
    for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
      valid += (valid.empty() ? "" : ", ") + sub->get_name();
    }
    std::fprintf(stderr, "%s: unknown subcommand '%s' (valid: %s)\nRun with --help for more information.\n", program,
                 rest.front().c_str(), valid.c_str());
    return 2;
  }
  return app.exit(e) == 0 ? 0 : 2;
}

}  // namespace dockcore::cli
