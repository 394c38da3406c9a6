// dock-sim: dockcore's simulation and benchmark tool. Subcommands register themselves (commands.hpp).
// Exit status: a subcommand's own (0 / 1, 2 for its argument errors); 2 for every command-line error CLI11 finds;
// 0 for --help.
#include <cstdio>
#include <string>
#include <vector>

#include "commands.hpp"
#include "dockcore/cli/parse_errors.hpp"

int main(int argc, char** argv) {
  CLI::App app{"dock-sim: simulate lidar docking scenes, run dockcore's detectors on them, measure them"};
  app.require_subcommand(1);
  docksim_cli::register_scene(app);
  docksim_cli::register_detect(app);
  docksim_cli::register_perception(app);
  docksim_cli::register_run(app);
  docksim_cli::register_montecarlo(app);
  docksim_cli::register_certify(app);
  docksim_cli::register_soak(app);
  docksim_cli::register_features(app);
  docksim_cli::register_params(app);
  docksim_cli::register_replay(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::RuntimeError& e) {
    return e.get_exit_code();  // a subcommand's result, already reported by it
  } catch (const CLI::ParseError& e) {
    return dockcore::cli::exit_for_parse_error(app, e, "dock-sim");
  }
  return 0;
}
