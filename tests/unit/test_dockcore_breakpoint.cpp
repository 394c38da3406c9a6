// Dockcore with seed 000's detector (DockDetector::kBreakpoint) on scans raycast here from the built-in "breakpoint"
// profile against a wall: the detection's pose and covariance (breakpoint_measurement), the filter fed with it, a
// taught target's moved frame, and the configurations Dockcore refuses (wrong profile, free-standing, no detector).
#include <cmath>
#include <cstddef>
#include <string>

#include "dockcore/control/controllers.hpp"
#include "dockcore/dockcore.hpp"
#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/breakpoint_detector.hpp"
#include "dockcore/perception/breakpoint_measurement.hpp"
#include "dockcore/perception/dock_profile.hpp"

#include "breakpoint_scene.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using breakpoint_scene::add_dock_against_wall;
using breakpoint_scene::Scene;

namespace {

const Real kDeg = kPi / 180;

// An LD06-like 0.5° full turn, index 0 at -180°.
constexpr std::size_t kBeams = 720;
const Real kInc = kTwoPi / kBeams;

LaserScanN<kBeams> g_scan;
Seed000Controller g_ctl;
DockcoreN<kBeams> g_core(g_ctl);  // static: ~81 KiB
BreakpointDetector g_bp;          // static: ~37 KiB of working buffers

/// The breakpoint dock at `dock` (dock frame in the lidar's) with its back flush against a wall, raycast into g_scan.
void render(const Pose2& dock) {
  Scene s;
  add_dock_against_wall(s, dock);
  breakpoint_scene::render(s, g_scan, kBeams, -kPi, kInc);
}

/// A dock `d_m` ahead at bearing `bearing_rad`, its face turned by `turn_rad` from facing the lidar.
Pose2 dock_at(Real d_m, Real bearing_rad, Real turn_rad) {
  return Pose2{d_m * std::cos(bearing_rad), d_m * std::sin(bearing_rad), wrap_angle(bearing_rad + kPi + turn_rad)};
}

DockcoreConfig breakpoint_config() {
  DockcoreConfig cfg;
  cfg.detector = DockDetector::kBreakpoint;
  cfg.estimator.range_sigma_m = static_cast<Real>(0.01);
  return cfg;
}

DockProfile profile(const char* name) {
  DockProfile p;
  CHECK(builtin_profile(name, p) == ProfileError::kOk);
  return p;
}

}  // namespace

TEST_GROUP(DockcoreBreakpoint){void setup() override{g_core.attach_breakpoint(&g_bp);
}
}
;

TEST(DockcoreBreakpoint, FindsTheBreakpointDockWithAPoseAndCovariance) {
  CHECK(g_core.configure(profile("breakpoint"), breakpoint_config()));
  CHECK(g_core.configure_status() == ConfigureStatus::kOk);
  const Pose2 truth = dock_at(static_cast<Real>(1.0), 8 * kDeg, 0);
  render(truth);
  const std::uint32_t before = g_bp.counters().detections;
  const DockEstimate* e = g_core.on_scan(g_scan.view(), 1000000, 1000000);
  CHECK(e != nullptr);
  CHECK(e->found);
  CHECK(e->status == EstimateStatus::kOk);
  LONGS_EQUAL(before + 1, g_bp.counters().detections);  // the breakpoint detector ran, not the estimator
  // Noise-free: the centre beam is within one beam (8.7 mm at 1 m) of the contacts' centre, the yaw within a degree.
  CHECK((Vec2(e->pose.x_m, e->pose.y_m) - Vec2(truth.x_m, truth.y_m)).norm() < static_cast<Real>(0.012));
  CHECK(std::fabs(wrap_angle(e->pose.yaw_rad - truth.yaw_rad)) < 1 * kDeg);
  // The covariance: σr² along the centre beam, r²Δθ²/8 across, yaw from a 0.26 m baseline: √2·σ⊥ / 0.26 with σ⊥
  // ≈ 14 mm (10 mm range noise; at 7° off the dock's normal a mark lands on a slot's side wall 9 times in 10).
  const Mat3& c = e->covariance;
  const Real mid = (c(0, 0) + c(1, 1)) / 2;
  const Real half = std::sqrt((c(0, 0) - c(1, 1)) * (c(0, 0) - c(1, 1)) / 4 + c(0, 1) * c(0, 1));
  const Real along = std::sqrt(mid + half);  // the 2x2 block's eigenvalues
  const Real across = std::sqrt(mid - half);
  CHECK(std::fabs(along - static_cast<Real>(0.01)) < static_cast<Real>(1e-4));
  CHECK(std::fabs(across - kInc / std::sqrt(static_cast<Real>(8))) < static_cast<Real>(2e-4));
  const Real yaw_sigma = std::sqrt(e->covariance(2, 2));
  CHECK(yaw_sigma > static_cast<Real>(0.065) && yaw_sigma < static_cast<Real>(0.085));
  // The detection reached the filter.
  CHECK(g_core.filter().initialised());
  CHECK((Vec2(g_core.filter().dock_in_odom().x_m, g_core.filter().dock_in_odom().y_m) - Vec2(e->pose.x_m, e->pose.y_m))
            .norm() < static_cast<Real>(1e-6));
  // No dock in view: nothing found, the filter keeps its estimate.
  for (std::size_t i = 0; i < kBeams; ++i) g_scan.ranges_m[i] = 1;
  e = g_core.on_scan(g_scan.view(), 1100000, 1100000);
  CHECK(e != nullptr);
  CHECK_FALSE(e->found);
  CHECK(e->status == EstimateStatus::kNoCandidates);
}

TEST(DockcoreBreakpoint, ALidarMountAndAMovedFrameAreApplied) {
  // The lidar 0.1 m ahead of the robot centre, turned 5°; the profile's frame moved by a taught target (rigidly).
  DockcoreConfig cfg = breakpoint_config();
  cfg.lidar_mount = Pose2{static_cast<Real>(0.1), 0, 5 * kDeg};
  const Pose2 move{static_cast<Real>(0.004), static_cast<Real>(-0.006), 1 * kDeg};  // native frame in the profile's
  DockProfile moved = profile("breakpoint");
  for (std::size_t i = 0; i < moved.vertex_count; ++i) moved.vertices_m[i] = move.transform(moved.vertices_m[i]);
  Pose2 frame;
  CHECK(breakpoint_outline_frame(moved, &frame));
  CHECK(std::fabs(frame.x_m - move.x_m) < static_cast<Real>(1e-6) && std::fabs(frame.yaw_rad - move.yaw_rad) < 1e-6);
  CHECK(g_core.configure(moved, cfg));
  const Pose2 native_in_lidar = dock_at(static_cast<Real>(0.8), -5 * kDeg, 0);
  render(native_in_lidar);
  const DockEstimate* e = g_core.on_scan(g_scan.view(), 2000000, 2000000);
  CHECK(e != nullptr && e->found);
  const Pose2 truth = cfg.lidar_mount.compose(native_in_lidar).compose(move.inverse());
  CHECK((Vec2(e->pose.x_m, e->pose.y_m) - Vec2(truth.x_m, truth.y_m)).norm() < static_cast<Real>(0.012));
  // Noise-free, the left mark's beam meets the -y slot's side wall here: 4.3° of yaw error, inside the covariance's
  // 2σ (σ ≈ 3.8°), which counts that wall.
  const Real yaw_error = std::fabs(wrap_angle(e->pose.yaw_rad - truth.yaw_rad));
  CHECK(yaw_error > 3 * kDeg);
  CHECK(yaw_error < 2 * std::sqrt(e->covariance(2, 2)));
}

TEST(DockcoreBreakpoint, AMismatchedConfigurationIsRefused) {
  // Another dock's profile: the breakpoint detector cannot find it.
  CHECK_FALSE(g_core.configure(profile("plate-v"), breakpoint_config()));
  CHECK(g_core.configure_status() == ConfigureStatus::kDetectorProfileMismatch);
  CHECK(detector_supports(DockDetector::kBreakpoint, profile("v-marker")) == ConfigureStatus::kDetectorProfileMismatch);
  // The breakpoint outline stretched by 1 cm is another dock.
  DockProfile wide = profile("breakpoint");
  wide.vertices_m[0].y() -= static_cast<Real>(0.01);
  CHECK(detector_supports(DockDetector::kBreakpoint, wide) == ConfigureStatus::kDetectorProfileMismatch);
  // Free-standing: the pattern needs the wall beside the dock.
  DockProfile free = profile("breakpoint");
  free.mounting.kind = DockMountKind::kFreeStanding;
  CHECK_FALSE(g_core.configure(free, breakpoint_config()));
  CHECK(g_core.configure_status() == ConfigureStatus::kDetectorNeedsWall);
  // No detector attached.
  g_core.attach_breakpoint(nullptr);
  CHECK_FALSE(g_core.configure(profile("breakpoint"), breakpoint_config()));
  CHECK(g_core.configure_status() == ConfigureStatus::kDetectorNotAttached);
  // The estimator takes every profile, with or without a breakpoint detector; refusals have names.
  CHECK(g_core.configure(profile("plate-v"), DockcoreConfig{}));
  CHECK(g_core.configure_status() == ConfigureStatus::kOk);
  CHECK(detector_supports(DockDetector::kEstimator, profile("breakpoint")) == ConfigureStatus::kOk);
  STRCMP_EQUAL("breakpoint", to_string(DockDetector::kBreakpoint));
  STRCMP_EQUAL("estimator", to_string(DockDetector::kEstimator));
  STRCMP_EQUAL("ok", to_string(ConfigureStatus::kOk));
  CHECK(std::string(to_string(ConfigureStatus::kDetectorNeedsWall)).find("wall") != std::string::npos);
}

TEST(DockcoreBreakpoint, SeedThresholdsScaleToTheScanResolution) {
  const BreakpointParams one_deg = breakpoint_params_for_scan(kPi / 180);
  LONGS_EQUAL(5, one_deg.neighbour_offset_idx);
  LONGS_EQUAL(7, one_deg.max_pair_spacing_idx);
  const BreakpointParams half_deg = breakpoint_params_for_scan(kPi / 360);
  LONGS_EQUAL(10, half_deg.neighbour_offset_idx);
  LONGS_EQUAL(14, half_deg.max_pair_spacing_idx);
  const BreakpointParams bad = breakpoint_params_for_scan(0);
  LONGS_EQUAL(5, bad.neighbour_offset_idx);
}
