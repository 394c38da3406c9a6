// Runs core's per-scan work with every heap entry point counted; any allocation after set-up is a failure.
// Interposes malloc/calloc/realloc/free (glibc's __libc_* do the work), which also catches operator new.
#include <cstddef>
#include <cstdio>
#include <cstdlib>

#include "dockcore/breakpoint_detector.hpp"
#include "dockcore/dock_pose_estimator.hpp"
#include "dockcore/dock_pose_filter.hpp"
#include "dockcore/dock_profile.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/line_segments.hpp"
#include "dockcore/vmarker_detector.hpp"
#include "docksim/lidar_sim.hpp"
#include "docksim/scenes.hpp"

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void __libc_free(void*);
}

namespace {
volatile bool g_armed = false;
volatile std::size_t g_allocs = 0;
}  // namespace

extern "C" void* malloc(std::size_t n) {
  if (g_armed) g_allocs = g_allocs + 1;
  return __libc_malloc(n);
}
extern "C" void* calloc(std::size_t a, std::size_t b) {
  if (g_armed) g_allocs = g_allocs + 1;
  return __libc_calloc(a, b);
}
extern "C" void* realloc(void* p, std::size_t n) {
  if (g_armed) g_allocs = g_allocs + 1;
  return __libc_realloc(p, n);
}
extern "C" void free(void* p) { __libc_free(p); }

using namespace dockcore;

static int check(const char* what, std::size_t before) {
  const std::size_t n = g_allocs - before;
  std::printf("%-28s allocations: %zu\n", what, n);
  return n == 0 ? 0 : 1;
}

namespace {
// Everything large is static: the point is what the per-scan calls do, not where their buffers live.
LaserScan g_scan;
ScanPoints g_points;
LineSegments g_segments;
DockPoseEstimator g_estimator;
BreakpointDetector g_breakpoint;
}  // namespace

int main() {
  // Set-up (allowed to allocate): a simulated LD06 scan of each built-in dock against a wall, with clutter.
  DockProfile profiles[3];
  builtin_profile("plate-v", profiles[0]);
  builtin_profile("v-marker", profiles[1]);
  builtin_profile("breakpoint", profiles[2]);
  int failures = 0;
  g_armed = true;
  // Self-check: the trap must see an allocation, or a pass below would mean nothing.
  std::size_t b = g_allocs;
  void* volatile probe = std::malloc(16);
  std::free(probe);
  if (g_allocs - b != 1) {
    std::printf("FAIL: allocation trap is not counting\n");
    return 1;
  }
  g_armed = false;
  for (const DockProfile& prof : profiles) {
    docksim::SceneSpec spec;
    spec.profile = prof;
    spec.dock_pose_in_world = docksim::dock_pose_from_lidar(0.9, 0.2, 0.1);
    spec.clutter_level = 2;
    docksim::Rng rng(3);
    const docksim::World world = docksim::build_scene(spec, rng);
    docksim::LidarModel model;
    docksim::lidar_model("ld06", &model);
    docksim::simulate_scan(world, Pose2{}, model, rng, &g_scan, 0);
    VMarkerDetector vmarker;
    VMarkerParams vp;
    const bool is_v = vmarker_geometry_from_profile(prof, vp.geometry) == VMarkerError::kOk;
    if (is_v) vmarker.configure(vp);
    DockPoseFilter filter;

    std::printf("-- %s\n", prof.name);
    g_armed = true;
    b = g_allocs;
    scan_to_points(g_scan.view(), Pose2{}, 0.05, 10.0, g_points);
    failures += check("scan_to_points", b);
    b = g_allocs;
    extract_line_segments(g_points, g_scan.view(), SegmentParams{}, g_segments);
    failures += check("extract_line_segments", b);
    b = g_allocs;
    const VMarkerDetection vd = vmarker.detect(g_segments);
    failures += check("VMarkerDetector::detect", b);
    b = g_allocs;
    const BreakpointDetection bd = g_breakpoint.detect(g_scan.view());
    failures += check("BreakpointDetector::detect", b);
    b = g_allocs;
    g_estimator.configure(prof, EstimatorParams{});
    const DockEstimate e = g_estimator.estimate(g_scan.view(), Pose2{});
    const DockEstimate tracked = g_estimator.estimate(g_scan.view(), Pose2{}, &e.pose);
    failures += check("DockPoseEstimator::estimate", b);
    b = g_allocs;
    filter.update(e.pose, e.covariance, Pose2{}, 0);
    filter.update(tracked.pose, tracked.covariance, Pose2{0.01, 0, 0}, 100000);
    failures += check("DockPoseFilter::update", b);
    g_armed = false;
    std::printf("   (found: estimator %d, breakpoint %d, vmarker %d)\n", e.found, bd.found, is_v && vd.found);
    if (!e.found) {
      // The trap must exercise the full path (candidates, refinement, verification), not an early exit.
      std::printf("FAIL: the estimator did not find the %s dock, so its full path was not exercised\n", prof.name);
      ++failures;
    }
  }
  std::printf("%s\n", failures == 0 ? "PASS: no heap use" : "FAIL: heap used on a per-scan path");
  return failures == 0 ? 0 : 1;
}
