// BreakpointDetector on the simulator's scenes: its own raycaster, clutter, an RPLIDAR-A1-like 1° lidar model,
// noise-free and with dropouts. The detector on scans raycast by hand is test_breakpoint_detector.
#include <cmath>
#include <cstdint>

#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/breakpoint_detector.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "docksim/lidar_sim.hpp"
#include "docksim/rng.hpp"
#include "docksim/scenes.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;

namespace {

const Real kInc = kTwoPi / 360;  // the rplidar-a1 model's beam spacing, 1°
BreakpointDetector g_det;        // static: the detector holds ~37 KB of working buffers

/// Default parameters, counters zeroed.
void reset_detector() {
  g_det.set_params(BreakpointParams{});
  g_det.reset_counters();
}

/// Scans `n` cluttered scenes with the dock at distance d_m, bearing uniform in ±0.2 rad; returns how many were
/// found and, of those, how many had the centre within `tol_beams` beams of the true bearing.
void run_sim(const docksim::LidarModel& model, double d_m, int n, double tol_beams, int* found, int* good) {
  DockProfile prof;
  builtin_profile("breakpoint", prof);
  static LaserScan scan;
  *found = 0;
  *good = 0;
  for (int k = 0; k < n; ++k) {
    docksim::Rng rng(1000 + static_cast<std::uint64_t>(k));
    docksim::SceneSpec spec;
    spec.profile = prof;
    const double b = rng.uniform(-0.2, 0.2);
    spec.dock_pose_in_world = docksim::dock_pose_from_lidar(d_m, b, 0);
    spec.clutter_level = 1;
    const docksim::World w = docksim::build_scene(spec, rng);
    docksim::simulate_scan(w, Pose2{}, model, rng, &scan);
    const BreakpointDetection det = g_det.detect(scan.view());
    if (!det.found) continue;
    ++*found;
    if (std::fabs(det.centre_angle_rad - b) <= tol_beams * kInc) ++*good;
  }
}

docksim::LidarModel ideal_a1() {
  docksim::LidarModel m;
  CHECK_TRUE(docksim::lidar_model("rplidar-a1", &m));
  m.sigma_const_m = 0;
  m.sigma_prop = 0;
  m.dropout_prob = 0;
  m.angular_jitter_rad = 0;
  m.mixed_pixels = false;
  return m;
}

}  // namespace

TEST_GROUP(BreakpointScenes){};

TEST(BreakpointScenes, SimulatedNoiseFreeScenesAreFound) {
  reset_detector();
  for (double d : {0.5, 1.0}) {
    int found = 0;
    int good = 0;
    run_sim(ideal_a1(), d, 40, 1.0, &found, &good);
    CHECK_EQUAL(40, found);
    CHECK_EQUAL(40, good);
  }
}

// 5% dropouts, no noise: completion of one- and two-beam gaps recovers part of the misses (measured over 300 scenes
// per distance: 71% vs 66% at 0.5 m, 69% vs 61% at 1.0 m).
TEST(BreakpointScenes, SimulatedDropoutsGapCompletionHelps) {
  reset_detector();
  docksim::LidarModel m = ideal_a1();
  m.dropout_prob = 0.05;
  int on = 0;
  int off = 0;
  for (double d : {0.5, 1.0}) {
    int found = 0;
    int good = 0;
    g_det.set_params(BreakpointParams{});
    run_sim(m, d, 150, 1.5, &found, &good);
    CHECK_TRUE(good >= found * 95 / 100);
    on += found;
    BreakpointParams no_fill;
    no_fill.gap_fill_max_diff_m = 0;
    g_det.set_params(no_fill);
    run_sim(m, d, 150, 1.5, &found, &good);
    off += found;
  }
  CHECK_TRUE(on > off);
  CHECK_TRUE(on >= 300 / 2);
}
