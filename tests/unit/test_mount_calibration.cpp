// core mount calibration: a robot swinging in place before a dock, seen from a lidar mounted off its configured pose.
// The dock's detections (with range-like noise) sweep an arc about the robot's centre; the fit finds the lidar's
// sideways error, takes out a slipping centre's odometry translation, and refuses swings it cannot measure.
#include <cmath>
#include <cstdint>

#include "dockcore/geometry.hpp"
#include "dockcore/perception/mount_calibration.hpp"
#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using dockcore_test::pose;

namespace {

constexpr double kPiD = 3.14159265358979323846;
double deg(double d) {
  return d * kPiD / 180.0;
}

/// Deterministic noise in [-1, 1] (a linear congruential sequence: the same on every platform).
struct Noise {
  std::uint32_t state = 12345u;
  double next() {
    state = state * 1664525u + 1013904223u;
    return static_cast<double>(state >> 8) / static_cast<double>(1u << 23) - 1.0;
  }
};

struct Swing {
  Pose2 true_mount = pose(0.10, 0.0, deg(3));
  Pose2 configured_mount = pose(0.10, 0.0, deg(3));
  Pose2 dock_in_world = pose(0, 0, 0);
  double start_x_m = 0.80;  // the robot's centre, facing the dock (heading pi)
  double start_y_m = 0.02;
  double amplitude_deg = 25;
  double step_deg = 1.5;
  double noise_m = 0.002;  // uniform ±, on each detection's position
  double drift_m = 0;      // the centre's slide towards the dock while it turns from +A to -A (odometry sees
                           // it when told): a wheel that stands in one direction
  bool odometry_sees_drift = true;
  bool rear = false;  // the dock behind the robot (rear pads): heading 0
  double jump_m = 0;  // a jump of the detections half-way through

  MountCalibrationResult run(Real max_correction_m = static_cast<Real>(0.03)) const {
    MountCalibration cal;
    const double heading0 = rear ? 0.0 : kPiD;
    cal.begin(configured_mount, pose(start_x_m, start_y_m, heading0));
    Noise noise;
    const double a = amplitude_deg;
    const int steps = static_cast<int>(4 * a / step_deg);
    for (int i = 0; i <= steps; ++i) {
      // +A, then -A, then back: the heading offset of step i.
      const double t = static_cast<double>(i) * step_deg;
      const double off = t <= a ? t : (t <= 3 * a ? 2 * a - t : t - 4 * a);
      const double leg = static_cast<double>(i) / steps * 2 - 0.5;  // 0..1 while turning from +A to -A
      const double slide = drift_m * (leg < 0 ? 0.0 : (leg > 1 ? 1.0 : leg)) * (rear ? 1.0 : -1.0);
      const Pose2 body = pose(start_x_m + slide, start_y_m, heading0 + deg(off));
      const Pose2 odom = odometry_sees_drift ? body : pose(start_x_m, start_y_m, heading0 + deg(off));
      Pose2 seen = body.compose(true_mount).inverse().compose(dock_in_world);
      seen.x_m += static_cast<Real>(noise_m * noise.next() + (i > steps / 2 ? jump_m : 0.0));
      seen.y_m += static_cast<Real>(noise_m * noise.next());
      cal.add(seen, odom);
    }
    return cal.solve(max_correction_m);
  }
};

}  // namespace

TEST_GROUP(MountCalibration){};

TEST(MountCalibration, ASwingFindsTheLidarsSidewaysErrorAndMovesTheMountByIt) {
  Swing s;
  s.true_mount = pose(0.10, 0.012, deg(3));  // 12 mm left of where it is configured
  const MountCalibrationResult r = s.run();
  CHECK(r.status == MountCalibrationStatus::kOk);
  STRCMP_EQUAL("ok", to_string(r.status));
  // Along the lidar's own y axis, turned 3° from the robot's.
  const double expected = 0.012 * std::cos(deg(3));
  REAL_EQUAL(expected, r.lateral_error_m, 0.001);
  REAL_EQUAL(0.012, r.mount.y_m, 0.001);
  REAL_EQUAL(0.10, r.mount.x_m, 0.001);
  REAL_EQUAL(deg(3), r.mount.yaw_rad, 1e-9);
  CHECK(r.rms_m < 0.003);
  CHECK(r.sweep_rad > deg(40));
  CHECK(r.detections > 60);
}

// A lidar turned from its configured yaw sees the robot's centre elsewhere in its own frame: the swing measures where
// that centre is (what placing the robot needs), not the turn, which the mount keeps as configured.
TEST(MountCalibration, TheCentreIsMeasuredNotTheTurn) {
  Swing s;
  s.true_mount = pose(0.10, 0.0, deg(4));  // turned 1° more than configured
  const MountCalibrationResult r = s.run();
  CHECK(r.status == MountCalibrationStatus::kOk);
  REAL_EQUAL(deg(3), r.mount.yaw_rad, 1e-9);
  const Vec2 centre = r.mount.inverse_transform(Vec2(0, 0));
  const Vec2 truth = s.true_mount.inverse_transform(Vec2(0, 0));
  REAL_EQUAL(static_cast<double>(truth.y()), centre.y(), 0.001);
}

TEST(MountCalibration, TheDockBehindTheRobotWorksAlike) {
  Swing s;
  s.rear = true;
  s.start_x_m = -0.80;  // the robot on the dock's other side, facing away from it
  s.true_mount = pose(0.10, -0.009, deg(3));
  const MountCalibrationResult r = s.run();
  CHECK(r.status == MountCalibrationStatus::kOk);
  REAL_EQUAL(-0.009, r.mount.y_m, 0.001);
}

TEST(MountCalibration, TheCentresOwnSlideIsTakenOutWhenOdometrySeesIt) {
  Swing s;
  s.true_mount = pose(0.10, 0.010, deg(3));
  s.drift_m = 0.015;  // the centre slides 15 mm towards the dock during one leg
  const MountCalibrationResult seen = s.run();
  CHECK(seen.status == MountCalibrationStatus::kOk);
  REAL_EQUAL(0.010, seen.mount.y_m, 0.001);
  // Without it in the odometry the slide reads as a bent arc: the measure is off or refused.
  s.odometry_sees_drift = false;
  const MountCalibrationResult blind = s.run();
  CHECK(blind.status != MountCalibrationStatus::kOk || std::fabs(static_cast<double>(blind.mount.y_m) - 0.010) > 0.002);
}

TEST(MountCalibration, SwingsItCannotMeasureChangeNothing) {
  {
    MountCalibration cal;
    cal.begin(pose(0.1, 0, 0), pose(0.8, 0, kPiD));
    for (int i = 0; i < 5; ++i) cal.add(pose(0.7, 0.01 * i, 0), pose(0.8, 0, kPiD + deg(i)));
    const MountCalibrationResult r = cal.solve(static_cast<Real>(0.03));
    CHECK(r.status == MountCalibrationStatus::kTooFewDetections);
    REAL_EQUAL(0.0, r.lateral_error_m, 1e-12);
    REAL_EQUAL(0.1, r.mount.x_m, 1e-9);
  }
  {
    Swing s;
    s.amplitude_deg = 6;
    s.step_deg = 0.5;
    const MountCalibrationResult r = s.run();
    CHECK(r.status == MountCalibrationStatus::kTooNarrow);
    STRCMP_EQUAL("too_narrow", to_string(r.status));
  }
  {
    Swing s;
    s.jump_m = 0.03;  // the detections jump 3 cm half-way (another object taken for the dock, a bump)
    const MountCalibrationResult r = s.run();
    CHECK(r.status == MountCalibrationStatus::kPoorFit);
    REAL_EQUAL(0.0, r.mount.y_m, 1e-9);
  }
  {
    Swing s;
    s.true_mount = pose(0.10, 0.05, deg(3));  // 5 cm: not a bracket's error; the configuration is wrong
    const MountCalibrationResult r = s.run();
    CHECK(r.status == MountCalibrationStatus::kTooFar);
    REAL_EQUAL(0.05 * std::cos(deg(3)), r.lateral_error_m, 0.002);
    REAL_EQUAL(0.0, r.mount.y_m, 1e-9);
  }
  STRCMP_EQUAL("interrupted", to_string(MountCalibrationStatus::kInterrupted));
}
