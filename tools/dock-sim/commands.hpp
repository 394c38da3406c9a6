#pragma once
// dock-sim subcommands. Each lives in its own file and registers itself on the CLI11 app; main.cpp only wires them.
#include <CLI/CLI.hpp>

namespace docksim_cli {

/// `dock-sim perception`: detector accuracy / false-positive / cost benchmark (perception.cpp).
void register_perception(CLI::App& app);
/// `dock-sim detect`: run the detectors on recorded scans (detect.cpp).
void register_detect(CLI::App& app);
/// `dock-sim scene`: simulate one scene, detect the dock, print the pose and draw an SVG (scene.cpp).
void register_scene(CLI::App& app);
/// `dock-sim run`: one closed-loop docking of a scenario: timeline, outcome, SVG (run.cpp).
void register_run(CLI::App& app);
/// `dock-sim montecarlo`: many seeded starts per controller, comparison table (run.cpp).
void register_montecarlo(CLI::App& app);
/// `dock-sim certify`: a Monte Carlo over a family of robots, with the reliability it demonstrates (certify.cpp).
void register_certify(CLI::App& app);
/// `dock-sim soak`: N consecutive dock -> charge -> undock cycles of one continuous robot (soak.cpp).
void register_soak(CLI::App& app);
/// `dock-sim features`: the estimator's decision features of labelled candidates, CSV (features.cpp).
void register_features(CLI::App& app);
/// `dock-sim params`: the parameter table as Markdown; regenerate or check the docs' key tables (params.cpp).
void register_params(CLI::App& app);
/// `dock-sim replay`: a dockd loop record through a fresh core, every tick compared (replay.cpp).
void register_replay(CLI::App& app);

}  // namespace docksim_cli
