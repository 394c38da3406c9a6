// dock-sim: dockcore's simulation and benchmark tool. Subcommands register themselves (commands.hpp).
// Exit status: a subcommand's own (0 / 1, 2 for its argument errors); 2 for every command-line error CLI11 finds;
// 0 for --help.
#include <cstdio>
#include <string>
#include <vector>

#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"dock-sim: simulate lidar docking scenes, run dockcore's detectors on them, measure them"};
  app.require_subcommand(1);
  docksim_cli::register_scene(app);
  docksim_cli::register_detect(app);
  docksim_cli::register_perception(app);
  docksim_cli::register_run(app);
  docksim_cli::register_montecarlo(app);
  docksim_cli::register_soak(app);
  docksim_cli::register_features(app);
  docksim_cli::register_params(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::RuntimeError& e) {
    return e.get_exit_code();  // a subcommand's result, already reported by it
  } catch (const CLI::ParseError& e) {
    // An unknown option or word where the subcommand belongs: name it, and for a word the valid subcommands (CLI11
    // would only say that a subcommand is required).
    const std::vector<std::string> rest = app.remaining();
    if (app.get_subcommands().empty() && !rest.empty() && rest.front().rfind('-', 0) == 0) {
      std::fprintf(stderr, "dock-sim: unknown option '%s'\nRun with --help for more information.\n",
                   rest.front().c_str());
      return 2;
    }
    if (app.get_subcommands().empty() && !rest.empty()) {
      std::string valid;
      for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
        valid += (valid.empty() ? "" : ", ") + sub->get_name();
      }
      std::fprintf(stderr, "dock-sim: unknown subcommand '%s' (valid: %s)\nRun with --help for more information.\n",
                   rest.front().c_str(), valid.c_str());
      return 2;
    }
    return app.exit(e) == 0 ? 0 : 2;
  }
  return 0;
}
