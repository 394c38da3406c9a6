// Runs core's per-scan work with every heap entry point counted; any allocation after set-up is a failure.
// Counts through tests/support/malloc_count.hpp (malloc/calloc/realloc interposed), which also catches operator new.
#include <cstddef>
#include <cstdio>
#include <cmath>
#include <cstdlib>

#include "dockcore/control/controllers.hpp"
#include "dockcore/dockcore.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/breakpoint_detector.hpp"
#include "dockcore/perception/dock_pose_estimator.hpp"
#include "dockcore/perception/dock_pose_filter.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "dockcore/perception/line_segments.hpp"
#include "dockcore/perception/vmarker_detector.hpp"
#include "docksim/lidar_sim.hpp"
#include "docksim/scenes.hpp"
#include "../support/malloc_count.hpp"

using dockcore_test::g_allocs;
using dockcore_test::g_armed;

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
SmoothController g_smooth;
Dockcore g_core(g_smooth);  // ~330 KiB: static, as dockd keeps it
}  // namespace

// The whole stack as dockd runs it: Dockcore::on_scan at 10 Hz and Dockcore::tick at 50 Hz with the smooth
// controller, docking a unicycle robot at a plate-v dock against a wall. Only the facade calls are armed: the
// lidar simulator and the robot model are host code and may allocate. Returns the failures (0 or 1).
static int facade_run() {
  DockProfile prof;
  builtin_profile("plate-v", prof);
  DockcoreConfig cfg;
  if (!g_core.configure(prof, cfg)) {
    std::printf("FAIL: Dockcore::configure\n");
    return 1;
  }
  docksim::World world;
  world.add_dock(prof, Pose2{0, 0, 0});
  world.add_polyline({Vec2(-0.10, -3.0), Vec2(-0.10, 3.0)});
  docksim::LidarModel model;
  docksim::lidar_model("ld06", &model);
  docksim::Rng rng(5);
  Pose2 robot{1.3, 0.15, kPi - 0.2};  // truth = odometry (no slip)
  const Real half_length = cfg.footprint.half_length_m;
  const std::uint64_t tick_us = 20000;
  std::uint64_t now_us = 1000000, contact_since_us = 0;
  bool contact = false, charge_enable = false, reached_align = false;
  std::size_t armed_allocs = 0;
  TaskState last = TaskState::kNotTasking;
  for (int k = 0; k < 600; ++k) {
    const std::size_t b_odom = g_allocs;
    g_armed = true;
    g_core.on_odometry(robot, Twist2{}, now_us);
    g_armed = false;
    armed_allocs += g_allocs - b_odom;
    if (k % 5 == 0) {
      docksim::simulate_scan(world, robot, model, rng, &g_scan, now_us);  // host side, not armed
      const std::size_t b0 = g_allocs;
      g_armed = true;
      g_core.on_scan(g_scan.view(), now_us, now_us);
      g_armed = false;
      armed_allocs += g_allocs - b0;
    }
    TickInput in;
    in.now_us = now_us;
    if (k == 0) {
      QueuedCommand dock;
      dock.command = HostCommand{HostCommandType::kDock, 0};
      g_core.submit(dock);
    }
    in.contact = contact;
    in.charge_current_a = contact && charge_enable && now_us - contact_since_us >= 500000 ? static_cast<Real>(2) : 0;
    const std::size_t b1 = g_allocs;
    g_armed = true;
    const TickOutput o = g_core.tick(in);
    g_armed = false;
    armed_allocs += g_allocs - b1;
    last = o.status.state;
    if (last == TaskState::kAlign) reached_align = true;
    charge_enable = o.status.charge_enable;
    // Unicycle step; the dock face stops the robot's front.
    const Real dt = static_cast<Real>(tick_us) * static_cast<Real>(1e-6);
    robot.yaw_rad = wrap_angle(robot.yaw_rad + o.cmd.wz_radps * dt);
    robot.x_m += o.cmd.vx_mps * std::cos(robot.yaw_rad) * dt;
    robot.y_m += o.cmd.vx_mps * std::sin(robot.yaw_rad) * dt;
    const Vec2 front = robot.transform(Vec2(half_length, 0));
    if (front.x() < 0 && std::fabs(front.y()) < static_cast<Real>(0.3)) robot.x_m -= front.x();
    const Vec2 f2 = robot.transform(Vec2(half_length, 0));
    const bool c = f2.x() <= static_cast<Real>(0.002) && std::fabs(f2.y()) < static_cast<Real>(0.05);
    if (c && !contact) contact_since_us = now_us;
    contact = c;
    now_us += tick_us;
  }
  std::printf("-- Dockcore facade (smooth, 600 ticks, 120 scans): final state %s, fused %u\n", to_string(last),
              static_cast<unsigned>(g_core.filter().fused()));
  std::printf("%-28s allocations: %zu\n", "Dockcore on_odometry + on_scan + tick", armed_allocs);
  int failures = armed_allocs == 0 ? 0 : 1;
  if (!reached_align || g_core.filter().fused() < 10) {
    // The run must exercise the controller and the filter, not sit in REACH_TASKING_POINT.
    std::printf("FAIL: the facade run never aligned on a tracked dock\n");
    ++failures;
  }
  return failures;
}

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
  failures += facade_run();
  std::printf("%s\n", failures == 0 ? "PASS: no heap use" : "FAIL: heap used on a per-scan path");
  return failures == 0 ? 0 : 1;
}
