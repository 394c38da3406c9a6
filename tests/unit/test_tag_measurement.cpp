// A camera's tag pose as a dock-pose measurement: frames, the covariance model against simulated scatter, refusals.
#include <cmath>
#include <cstdint>
#include <vector>

#include "dockcore/geometry.hpp"
#include "dockcore/perception/tag_measurement.hpp"
#include "docksim/rng.hpp"

#include "real_tolerance.hpp"
#include "tag_observe.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using dockcore_test::observe_tag;
using dockcore_test::with_corners;

namespace {

TagFusionParams params() {
  TagFusionParams p;
  p.mount.x_m = 0.2;
  p.mount.z_m = 0.2;
  p.fx_px = 600;
  p.tag_size_m = 0.08;
  p.dock_tag.id = 3;
  p.dock_tag.z_m = 0.2;
  return p;
}

}  // namespace

TEST_GROUP(TagMeasurement){};

TEST(TagMeasurement, CameraRotationFollowsTheOpticalConvention) {
  // Level, forward: optical z = robot x, optical x (right) = robot −y, optical y (down) = robot −z.
  CameraMount3 m;
  Mat3 r = camera_rotation(m);
  REAL_EQUAL(1, r(0, 2), 1e-6);
  REAL_EQUAL(-1, r(1, 0), 1e-6);
  REAL_EQUAL(-1, r(2, 1), 1e-6);
  // Pitched 10° down: the optical axis points below the horizon.
  m.pitch_rad = deg_to_rad(static_cast<Real>(10));
  r = camera_rotation(m);
  REAL_EQUAL(std::cos(0.17453292519943295), r(0, 2), 1e-6);
  REAL_EQUAL(-std::sin(0.17453292519943295), r(2, 2), 1e-6);
  // Turned 90° to the left: the optical axis is robot +y and the image's right is robot +x.
  m = CameraMount3{};
  m.yaw_rad = deg_to_rad(static_cast<Real>(90));
  r = camera_rotation(m);
  REAL_EQUAL(1, r(1, 2), 1e-6);
  REAL_EQUAL(1, r(0, 0), 1e-6);
}

TEST(TagMeasurement, TagSquarelyAheadGivesTheDockBehindIt) {
  // Camera 0.2 m ahead of the centre at 0.2 m; the tag 1 m ahead of the lens, facing it, 0.2 m above the contacts.
  const TagFusionParams p = params();
  TagObservation o;
  o.id = 3;
  o.translation_m = Vec3(0, 0, 1);
  TagMeasurement m;
  CHECK(tag_to_dock_measurement(o, p, &m) == TagStatus::kFused);
  REAL_EQUAL(1.2, m.dock_in_robot.x_m, 1e-6);
  REAL_EQUAL(0, m.dock_in_robot.y_m, 1e-6);
  REAL_EQUAL(kPi, std::fabs(m.dock_in_robot.yaw_rad), 1e-6);
  REAL_EQUAL(1, m.depth_m, 1e-9);
  // The tag 0.1 m to the image's right is the dock 0.1 m to the robot's right.
  o.translation_m = Vec3(0.1, 0, 1);
  CHECK(tag_to_dock_measurement(o, p, &m) == TagStatus::kFused);
  REAL_EQUAL(-0.1, m.dock_in_robot.y_m, 1e-6);
}

TEST(TagMeasurement, RoundTripThroughAnyMountAndTagPlacement) {
  docksim::Rng rng(11);
  for (int i = 0; i < 200; ++i) {
    TagFusionParams p = params();
    p.mount.x_m = static_cast<Real>(rng.uniform(-0.3, 0.3));
    p.mount.y_m = static_cast<Real>(rng.uniform(-0.2, 0.2));
    p.mount.z_m = static_cast<Real>(rng.uniform(0.05, 0.5));
    p.mount.yaw_rad = static_cast<Real>(rng.uniform(-0.3, 0.3));
    p.mount.pitch_rad = static_cast<Real>(rng.uniform(-0.3, 0.3));
    p.mount.roll_rad = static_cast<Real>(rng.uniform(-0.1, 0.1));
    p.dock_tag.x_m = static_cast<Real>(rng.uniform(-0.05, 0.05));
    p.dock_tag.y_m = static_cast<Real>(rng.uniform(-0.1, 0.1));
    p.dock_tag.z_m = static_cast<Real>(rng.uniform(0.05, 0.5));
    p.dock_tag.yaw_rad = static_cast<Real>(rng.uniform(-0.3, 0.3));
    const Pose2 robot{static_cast<Real>(rng.uniform(0.8, 2.0)), static_cast<Real>(rng.uniform(-0.4, 0.4)),
                      static_cast<Real>(kPi + rng.uniform(-0.4, 0.4))};
    const Pose2 dock{};
    const TagObservation o = observe_tag(robot, dock, p, nullptr, 0, 1);
    TagMeasurement m;
    CHECK(tag_to_dock_measurement(o, p, &m) == TagStatus::kFused);
    const Pose2 truth = robot.inverse().compose(dock);
    // 10 µm: a chain of four 3D rotations, also in the float build.
    REAL_EQUAL(truth.x_m, m.dock_in_robot.x_m, 1e-5);
    REAL_EQUAL(truth.y_m, m.dock_in_robot.y_m, 1e-5);
    REAL_EQUAL(0, wrap_angle(truth.yaw_rad - m.dock_in_robot.yaw_rad), 1e-5);
  }
}

TEST(TagMeasurement, CornerFitRecoversTheDockFromAnyStartNearIt) {
  docksim::Rng rng(23);
  for (int i = 0; i < 100; ++i) {
    TagFusionParams p = params();
    p.mount.y_m = static_cast<Real>(rng.uniform(-0.2, 0.2));
    p.mount.z_m = static_cast<Real>(rng.uniform(0.1, 0.4));
    p.mount.yaw_rad = static_cast<Real>(rng.uniform(-0.3, 0.3));
    p.mount.pitch_rad = static_cast<Real>(rng.uniform(-0.2, 0.2));
    p.mount.roll_rad = static_cast<Real>(rng.uniform(-0.1, 0.1));
    p.dock_tag.y_m = static_cast<Real>(rng.uniform(-0.1, 0.1));
    p.dock_tag.yaw_rad = static_cast<Real>(rng.uniform(-0.3, 0.3));
    const Pose2 robot{static_cast<Real>(rng.uniform(0.8, 1.8)), static_cast<Real>(rng.uniform(-0.3, 0.3)),
                      static_cast<Real>(kPi + rng.uniform(-0.3, 0.3))};
    const TagObservation o = with_corners(observe_tag(robot, Pose2{}, p, nullptr, 0, 1), p);
    const Pose2 truth = robot.inverse();
    const Pose2 start{truth.x_m + static_cast<Real>(rng.uniform(-0.03, 0.03)),
                      truth.y_m + static_cast<Real>(rng.uniform(-0.03, 0.03)),
                      wrap_angle(truth.yaw_rad + static_cast<Real>(rng.uniform(-0.1, 0.1)))};
    TagCornerFit f;
    CHECK(fit_dock_to_tag_corners(o.corners, p, start, &f));
    REAL_EQUAL(truth.x_m, f.dock_in_robot.x_m, 1e-5);
    REAL_EQUAL(truth.y_m, f.dock_in_robot.y_m, 1e-5);
    REAL_EQUAL(0, wrap_angle(truth.yaw_rad - f.dock_in_robot.yaw_rad), 1e-4);
    CHECK(f.rms_px < 1e-3);
    CHECK(f.iterations <= kTagFitMaxIterations);
  }
}

TEST(TagMeasurement, CornersPickTheRightOneOfThePlanarPoseTwins) {
  // The robot on the dock's axis, the dock turned 12° against the line of sight; the detector's pose is the twin
  // (turned −12°), as libapriltag returns it for near face-on tags. The corners are those of the true pose.
  const TagFusionParams p = params();
  const Pose2 robot{1.2, 0, kPi};
  const Real turn = deg_to_rad(static_cast<Real>(12));
  const Pose2 dock{0, 0, turn};
  const Pose2 twin{0, 0, -turn};
  TagObservation o = observe_tag(robot, twin, p, nullptr, 0, 1);
  const TagObservation right = with_corners(observe_tag(robot, dock, p, nullptr, 0, 1), p);
  TagMeasurement m;
  CHECK(tag_to_dock_measurement(o, p, &m) == TagStatus::kFused);
  const Pose2 truth = robot.inverse().compose(dock);
  CHECK(std::fabs(wrap_angle(truth.yaw_rad - m.dock_in_robot.yaw_rad)) > deg_to_rad(static_cast<Real>(20)));
  for (int k = 0; k < 4; ++k) o.corners[k] = right.corners[k];
  o.has_corners = true;
  CHECK(tag_to_dock_measurement(o, p, &m) == TagStatus::kFused);
  REAL_EQUAL(0, wrap_angle(truth.yaw_rad - m.dock_in_robot.yaw_rad), 1e-4);
  REAL_EQUAL(truth.x_m, m.dock_in_robot.x_m, 1e-5);
  REAL_EQUAL(truth.y_m, m.dock_in_robot.y_m, 1e-5);
  CHECK(m.corner_rms_px >= 0 && m.corner_rms_px < 1e-3);
}

TEST(TagMeasurement, CovarianceMatchesTheScatterOfSimulatedMeasurements) {
  // Noise drawn at the model's σ in the camera frame; the robot-frame covariance (rotated through the mount and the
  // tag's offset from the contacts) must match the scatter of the resulting dock poses.
  TagFusionParams p = params();
  p.mount.yaw_rad = static_cast<Real>(0.2);
  p.dock_tag.y_m = static_cast<Real>(0.08);
  p.dock_tag.x_m = static_cast<Real>(-0.02);
  const Pose2 robot{1.1, 0.25, static_cast<Real>(kPi - 0.15)};
  const Pose2 dock{};
  TagMeasurement m0;
  CHECK(tag_to_dock_measurement(observe_tag(robot, dock, p, nullptr, 0, 1), p, &m0) == TagStatus::kFused);
  docksim::Rng rng(5);
  const int n = 4000;
  std::vector<Vec3> e;
  Vec3 mean = Vec3::Zero();
  for (int i = 0; i < n; ++i) {
    TagMeasurement m;
    CHECK(tag_to_dock_measurement(observe_tag(robot, dock, p, &rng, p.sigma_px, 1), p, &m) == TagStatus::kFused);
    const Vec3 d(m.dock_in_robot.x_m - m0.dock_in_robot.x_m, m.dock_in_robot.y_m - m0.dock_in_robot.y_m,
                 wrap_angle(m.dock_in_robot.yaw_rad - m0.dock_in_robot.yaw_rad));
    e.push_back(d);
    mean += d / n;
  }
  Mat3 c = Mat3::Zero();
  for (const Vec3& d : e) c += (d - mean) * (d - mean).transpose() / (n - 1);
  for (int k = 0; k < 3; ++k) {
    const double ratio = c(k, k) / m0.covariance(k, k);
    CHECK_TEXT(ratio > 0.85 && ratio < 1.15, k == 0 ? "x" : k == 1 ? "y" : "yaw");
  }
  // The offset couples yaw into position: the correlation's sign and size follow.
  const double rho_meas = c(0, 2) / std::sqrt(c(0, 0) * c(2, 2));
  const double rho_model = m0.covariance(0, 2) / std::sqrt(m0.covariance(0, 0) * m0.covariance(2, 2));
  DOUBLES_EQUAL(rho_model, rho_meas, 0.1);
  // σ grows with distance: lateral like Z, depth and yaw like Z².
  const Pose2 far{2.2, 0.25, static_cast<Real>(kPi - 0.15)};
  TagMeasurement mf;
  CHECK(tag_to_dock_measurement(observe_tag(far, dock, p, nullptr, 0, 1), p, &mf) == TagStatus::kFused);
  CHECK(mf.covariance(2, 2) > 3 * m0.covariance(2, 2));
}

TEST(TagMeasurement, RefusesWhatIsNoMeasurement) {
  TagFusionParams p = params();
  TagObservation o;
  o.id = 3;
  o.translation_m = Vec3(0, 0, 1);
  TagMeasurement m;
  m.depth_m = 42;
  o.translation_m.z() = 4;  // beyond max_range_m (3 m)
  CHECK(tag_to_dock_measurement(o, p, &m) == TagStatus::kFar);
  o.translation_m.z() = 1;
  o.decision_margin = 10;
  p.min_decision_margin = 20;
  CHECK(tag_to_dock_measurement(o, p, &m) == TagStatus::kWeak);
  p.min_decision_margin = 0;
  o.rotation(0, 0) = 2;  // not a rotation
  CHECK(tag_to_dock_measurement(o, p, &m) == TagStatus::kInvalid);
  o.rotation = Mat3::Identity();
  o.rotation(0, 0) = -1;  // its back towards the camera (a half turn about y)
  o.rotation(2, 2) = -1;
  CHECK(tag_to_dock_measurement(o, p, &m) == TagStatus::kBehind);
  o.rotation = Mat3::Identity();
  p.fx_px = 0;
  CHECK(tag_to_dock_measurement(o, p, &m) == TagStatus::kInvalid);
  REAL_EQUAL(42, m.depth_m, 0);  // untouched by every refusal
  STRCMP_EQUAL("out_of_order", to_string(TagStatus::kOutOfOrder));
}
