// dock-sim: dockcore's simulation and benchmark tool. Subcommands register themselves (commands.hpp).
#include <cstdio>

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
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  return 0;
}
