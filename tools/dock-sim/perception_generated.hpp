#pragma once
// `dock-sim perception --sections generated`: the dock estimator over worlds drawn by docksim::WorldGenerator
// (tools/sim/include/docksim/world_gen.hpp), per factor, beside the targets (perception_generated.cpp).
#include <cstdint>

#include <nlohmann/json.hpp>

#include "docksim/estimator_overrides.hpp"

namespace docksim_cli {

struct GeneratedOptions {
  int scenes = 5000;     ///< Docking scenes (one scan each).
  int fp_scenes = -1;    ///< Dock-less scenes (three scans each); -1: as many as docking scenes.
  int filter_runs = -1;  ///< 1 s filtered approaches; -1: a fifth of the docking scenes.
  int profiles = 100;    ///< Random profiles in the pool.
  int jobs = 2;          ///< Worker threads; the figures do not depend on it.
  std::uint64_t seed = 1;
  docksim::EstimatorOverrides overrides;  ///< Applied to every estimator's parameters.
};

/// Runs the section; the result is what print_generated prints and --json emits. Deterministic for the options
/// (jobs aside). Prints progress on stderr.
nlohmann::ordered_json run_generated(const GeneratedOptions& o);

/// Prints the section's tables and the targets as plain text.
void print_generated(const nlohmann::ordered_json& j);

}  // namespace docksim_cli
