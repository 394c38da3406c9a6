#pragma once
// What the `dock-sim perception` sections over generated worlds share (perception_generated.cpp,
// perception_reflectors.cpp): the target envelope and the correctness / confirmation tolerances, the exclusion and
// miss-cause rules, per-scene seeds, the scene pool, the rate counter and the plain-text table printing.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "angles.hpp"
#include "dockcore/perception/dock_pose_estimator.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "docksim/estimator_overrides.hpp"
#include "docksim/world_gen.hpp"
#include "perception_stats.hpp"

namespace docksim_cli::genbench {

using json = nlohmann::ordered_json;

// Target envelope.
constexpr double kEnvDistanceM = 2.0;
constexpr double kEnvBearingRad = 45 * kDeg;
constexpr double kEnvYawRad = 30 * kDeg;
// A detection is of the dock when it lies this close to the truth (sensor frame); farther it is a wrong detection.
constexpr double kCorrectPosM = 0.10;
constexpr double kCorrectYawRad = 10 * kDeg;
// Three detections on a dock-less scene confirm (a false positive) when each lies this close to the first, world frame.
constexpr double kAgreePosM = 0.05;
constexpr double kAgreeYawRad = 5 * kDeg;
constexpr int kConfirmScans = 3;
constexpr std::uint64_t kScanPeriodUs = 100000;
/// Range bins, m: 0.3-0.6, 0.6-1.0, 1.0-1.5, 1.5-2.0, 2.0-2.5.
constexpr int kRangeBins = 5;
inline constexpr double kRangeEdges[kRangeBins + 1] = {0.3, 0.6, 1.0, 1.5, 2.0, 2.5};

/// Index of the bin of v among `bins` bins whose lower edges are edges[0..bins-1]; the last bin takes everything
/// above. O(bins).
int edge_bin(double v, const double* edges, int bins);

/// True when `e` (errors against the truth, sensor frame) is a detection of the dock. O(1).
inline bool is_correct(const Errors& e) {
  return e.pos_m <= kCorrectPosM && e.yaw_rad <= kCorrectYawRad;
}

/// The estimators' parameters for scene s (from its range noise at 1 m), with `ov` applied. O(1).
inline dockcore::EstimatorParams scene_params(const docksim::GenScene& s, const docksim::EstimatorOverrides& ov = {}) {
  return ov.for_noise(s.sigma_at(1.0));
}

/// Why the scene's profile is left out of the figures ("" when it is not): check_profile for the scene's lidar
/// spacing (rad) and the estimator's range (m), with the pose component when it names one. O(profile check).
std::string exclusion(const dockcore::DockProfile& profile, double beam_spacing_rad, double max_range_m);

/// Why a docking scene's dock was not detected, from the estimate: what the best refused candidate was refused for,
/// whether it lay at the dock (the right pose refused) or elsewhere (the dock never became a candidate that was
/// refined to it), or that another pose was accepted. truth_sensor: the dock in the true lidar frame; mount_inv: the
/// inverse of the mount the estimator was told. O(1).
std::string miss_cause(const dockcore::DockEstimate& e, const dockcore::Pose2& truth_sensor,
                       const dockcore::Pose2& mount_inv);

/// Seed of the scans of scene `index` of scan stream `stream`. O(1).
std::uint64_t scan_seed(std::uint64_t seed, std::uint64_t stream, std::uint64_t index);

/// One thread's estimators (~260 KiB each: heap) and scan buffer.
struct Worker {
  std::vector<std::unique_ptr<dockcore::DockPoseEstimator>> est;
  std::unique_ptr<dockcore::LaserScan> scan = std::make_unique<dockcore::LaserScan>();
  /// `estimators` (>= 1) estimators, unconfigured.
  explicit Worker(int estimators);
  /// Simulates the scan from the scene's lidar at robot pose k into `scan`. O(beams · segments near each beam).
  void simulate(const docksim::GenScene& s, std::size_t k, docksim::Rng& rng, std::uint64_t stamp_us);
};

/// Runs fn(i, worker) for every i in [0, total) on `jobs` threads (>= 1), each thread with its own Worker of
/// `estimators` estimators; progress "\r<label> d / total" on stderr, then the time taken. fn must be safe to call
/// concurrently for different i.
void run_scenes(std::size_t total, int jobs, int estimators, const char* label,
                const std::function<void(std::size_t, Worker&)>& fn);

/// Whether kConfirmScans detections on a dock-less scene confirm: every scan detects, each within kAgreePosM /
/// kAgreeYawRad of the first in the world frame.
struct Confirmation {
  int hits = 0;
  bool agree = true;
  dockcore::Pose2 first{};
  /// Scan k's estimate, robot at robot_in_world. O(1).
  void add(int k, const dockcore::DockEstimate& e, const dockcore::Pose2& robot_in_world);
  bool confirmed() const { return agree && hits == kConfirmScans; }
};

/// A rate: n trials, k hits.
struct Rate {
  int n = 0, k = 0;
  void add(bool hit) {
    ++n;
    k += hit ? 1 : 0;
  }
  /// {"n", "hits", "rate" (null when n is 0)}.
  json to_json() const;
};

// ---- plain-text tables

/// Pads to `width` display columns (UTF-8 aware: σ, ≤ and ° are one column, several bytes); right-aligned if right.
std::string pad(const std::string& s, std::size_t width, bool right = false);
/// printf of scale·v with the one-number format f; "-" for null.
std::string fmt(const json& v, const char* f, double scale = 1);
/// v as a percentage with format f; "-" for null.
std::string pct(const json& v, const char* f = "%.1f %%");
/// A Rate's JSON as "rate % (n)".
std::string rate_n(const json& r, const char* f = "%.1f %%");

struct Column {
  const char* title;
  std::size_t width;
  bool right;
};
/// One row of cells padded to the columns, trailing blanks dropped.
void print_row(const std::vector<Column>& cols, const std::vector<std::string>& cells);
/// The columns' titles as a row.
void print_header(const std::vector<Column>& cols);

}  // namespace docksim_cli::genbench
