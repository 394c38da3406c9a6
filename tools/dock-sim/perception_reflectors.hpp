#pragma once
// `dock-sim perception --sections reflectors`: the dock estimator reading reflector stripes as the dock's code, over
// worlds drawn by docksim::WorldGenerator in reflector mode (world_gen.hpp), beside the targets
// (perception_reflectors.cpp).
#include <cstdint>

#include <nlohmann/json.hpp>

#include "docksim/estimator_overrides.hpp"

namespace docksim_cli {

struct ReflectorOptions {
  int scenes = 5000;              ///< Docking scenes (one scan each).
  int fp_scenes = -1;             ///< Dock-less scenes (three scans each); -1: as many as docking scenes.
  int profiles = 100;             ///< Random profiles in the pool.
  int jobs = 2;                   ///< Worker threads; the figures do not depend on it.
  bool read_range = false;        ///< Also measure the readable-range table (per lidar and region width).
  int read_range_scenes = 10000;  ///< Docking scenes per (lidar, region width) of the readable-range table.
  docksim::EstimatorOverrides overrides;  ///< Applied to every estimator's parameters (stripe_hypotheses among them).
  std::uint64_t seed = 1;
};

/// Runs the section; the result is what print_reflectors prints and --json emits. Deterministic for the options
/// (jobs aside). Prints progress on stderr. Cost: about one estimator call per scan and case.
nlohmann::ordered_json run_reflectors(const ReflectorOptions& o);

/// Prints the section's tables and the targets as plain text.
void print_reflectors(const nlohmann::ordered_json& j);

}  // namespace docksim_cli
