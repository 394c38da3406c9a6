#include "dockcore/perception/dock_pose_filter.hpp"
#include "docksim/rng.hpp"

#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;

namespace {
Mat3 diag_cov(double sxy, double syaw) {
  Mat3 c = Mat3::Zero();
  c(0, 0) = c(1, 1) = sxy * sxy;
  c(2, 2) = syaw * syaw;
  return c;
}
}  // namespace

TEST_GROUP(DockPoseFilter){};

TEST(DockPoseFilter, FirstDetectionInitialisesInOdomFrame) {
  DockPoseFilter f;
  const Pose2 odom{1.0, 2.0, kPi / 2};
  const Pose2 det{0.5, 0.0, kPi};  // dock 0.5 m ahead, facing the robot
  CHECK_EQUAL(static_cast<int>(FilterUpdate::kInitialised),
              static_cast<int>(f.update(det, diag_cov(0.005, 0.01), odom, 100)));
  // Robot at (1,2) facing +y: the dock lies at (1, 2.5), its x axis pointing -y.
  REAL_EQUAL(1.0, f.dock_in_odom().x_m, 1e-12);
  REAL_EQUAL(2.5, f.dock_in_odom().y_m, 1e-12);
  REAL_EQUAL(-kPi / 2, f.dock_in_odom().yaw_rad, 1e-12);
  const Pose2 back = f.dock_in_robot(odom);
  REAL_EQUAL(0.5, back.x_m, 1e-12);
  REAL_EQUAL(0.0, back.y_m, 1e-12);
}

TEST(DockPoseFilter, AveragingReducesNoiseAsOneOverRootN) {
  DockPoseFilter f;
  docksim::Rng rng(7);
  const double sigma = 0.01;
  const Pose2 odom{};
  double sq = 0;
  const int trials = 200;
  for (int t = 0; t < trials; ++t) {
    f.reset();
    for (int k = 0; k < 16; ++k) {
      const Pose2 det = dockcore_test::pose(0.8 + rng.normal(0, sigma), 0.1 + rng.normal(0, sigma), kPi + rng.normal(0, 0.01));
      f.update(det, diag_cov(sigma, 0.01), odom, static_cast<std::uint64_t>(k));
    }
    const double e = f.dock_in_odom().x_m - 0.8;
    sq += e * e;
  }
  const double rms = std::sqrt(sq / trials);
  // 16 fused detections: σ/4 = 2.5 mm (plus the 2 mm model floor in the weights, which only weights equally).
  CHECK(rms < 0.0035);
  CHECK(rms > 0.0015);
  CHECK(std::sqrt(f.covariance_odom()(0, 0)) < 0.004);
}

TEST(DockPoseFilter, YawInnovationWrapsAcrossPi) {
  DockPoseFilter f;
  const Pose2 odom{};
  f.update(Pose2{1.0, 0.0, kPi - 0.01}, diag_cov(0.005, 0.02), odom, 0);
  CHECK_EQUAL(static_cast<int>(FilterUpdate::kFused),
              static_cast<int>(f.update(Pose2{1.0, 0.0, -kPi + 0.01}, diag_cov(0.005, 0.02), odom, 1)));
  // The mean of +179.4° and -179.4° is 180°, not 0°.
  CHECK(std::fabs(std::fabs(f.dock_in_odom().yaw_rad) - kPi) < 0.005);
}

TEST(DockPoseFilter, OdometryMotionKeepsDockFixedAndGrowsCovariance) {
  DockPoseFilter f;
  f.update(Pose2{1.0, 0.0, kPi}, diag_cov(0.003, 0.01), Pose2{}, 0);
  const double before = f.covariance_odom()(0, 0);
  // Robot drives 0.5 m forward and turns 90°: the dock is now 0.5 m away on the robot's right.
  const Pose2 odom{0.5, 0.0, kPi / 2};
  f.predict(odom);
  CHECK(f.covariance_odom()(0, 0) > before);
  const Pose2 d = f.dock_in_robot(odom);
  REAL_EQUAL(0.0, d.x_m, 1e-12);
  REAL_EQUAL(-0.5, d.y_m, 1e-12);
  REAL_EQUAL(kPi / 2, d.yaw_rad, 1e-12);
}

TEST(DockPoseFilter, JumpIsGatedThenReinitialises) {
  DockPoseFilter f;
  const Pose2 odom{};
  for (int k = 0; k < 5; ++k) f.update(Pose2{1.0, 0.0, kPi}, diag_cov(0.005, 0.01), odom, 0);
  const Pose2 pushed{1.0, 0.4, kPi - 0.5};
  CHECK_EQUAL(static_cast<int>(FilterUpdate::kGated), static_cast<int>(f.update(pushed, diag_cov(0.005, 0.01), odom, 1)));
  REAL_EQUAL(0.0, f.dock_in_odom().y_m, 1e-9);
  CHECK_EQUAL(static_cast<int>(FilterUpdate::kGated), static_cast<int>(f.update(pushed, diag_cov(0.005, 0.01), odom, 2)));
  CHECK_EQUAL(static_cast<int>(FilterUpdate::kReinitialised),
              static_cast<int>(f.update(pushed, diag_cov(0.005, 0.01), odom, 3)));
  REAL_EQUAL(0.4, f.dock_in_odom().y_m, 1e-12);
  CHECK_EQUAL(1u, f.reinitialisations());
  CHECK_EQUAL(2u, f.gated());
}

TEST(DockPoseFilter, NonFiniteInputChangesNothing) {
  DockPoseFilter f;
  f.update(Pose2{1.0, 0.0, kPi}, diag_cov(0.005, 0.01), Pose2{}, 0);
  CHECK_EQUAL(static_cast<int>(FilterUpdate::kInvalid),
              static_cast<int>(f.update(Pose2{std::nan(""), 0, 0}, diag_cov(0.005, 0.01), Pose2{}, 1)));
  REAL_EQUAL(1.0, f.dock_in_odom().x_m, 1e-12);
  CHECK_EQUAL(1u, f.fused());
}

// The sequential test: agreeing detections add their evidence; a single strong scan, gated detections or a restart
// do not confirm.
TEST(DockPoseFilter, EvidenceOfAgreeingDetectionsConfirms) {
  DockPoseFilter f;
  const Pose2 odom{};
  const Pose2 dock{1.0, 0.0, kPi};
  f.update(dock, diag_cov(0.005, 0.01), odom, 0, 20.0);
  CHECK_FALSE(f.confirmed());  // one scan, however strong
  REAL_EQUAL(20.0, f.evidence_nats(), 1e-12);
  DockPoseFilter g;
  for (int k = 0; k < 3; ++k) g.update(dock, diag_cov(0.005, 0.01), odom, static_cast<std::uint64_t>(k), 3.5);
  CHECK_FALSE(g.confirmed());  // 10.5 nats < 12
  g.update(dock, diag_cov(0.005, 0.01), odom, 3, 3.5);
  CHECK_TRUE(g.confirmed());
  CHECK_EQUAL(4u, g.fused_since_start());
  // A gated jump adds nothing; three of them restart the test from the newest detection.
  const Pose2 elsewhere{1.0, 0.5, kPi - 0.5};
  g.update(elsewhere, diag_cov(0.005, 0.01), odom, 4, 9.0);
  REAL_EQUAL(14.0, g.evidence_nats(), 1e-12);
  g.update(elsewhere, diag_cov(0.005, 0.01), odom, 5, 9.0);
  g.update(elsewhere, diag_cov(0.005, 0.01), odom, 6, 9.0);
  CHECK_FALSE(g.confirmed());
  REAL_EQUAL(9.0, g.evidence_nats(), 1e-12);
  g.reset();
  CHECK_FALSE(g.confirmed());
  REAL_EQUAL(0.0, g.evidence_nats(), 1e-12);
}

TEST(DockPoseFilter, TagMeasurementsAddNoEvidenceAndCountNoScans) {
  DockPoseFilter f;
  const Pose2 odom{};
  const Pose2 det{1.0, 0.0, kPi};
  CHECK(f.update_tag(det, diag_cov(0.005, 0.05), odom, 100) == FilterUpdate::kInitialised);
  for (int i = 0; i < 20; ++i) CHECK(f.update_tag(det, diag_cov(0.005, 0.05), odom, 200 + i) == FilterUpdate::kFused);
  REAL_EQUAL(0, f.evidence_nats(), 0);
  LONGS_EQUAL(0, f.fused_since_start());
  CHECK_FALSE(f.confirmed());
  CHECK_FALSE(f.lidar_since_start());
  LONGS_EQUAL(21, f.tag_fused());
  LONGS_EQUAL(0, f.fused());  // the lidar's counter
  // One lidar detection with all the evidence is still one scan: not confirmed; a second confirms.
  CHECK(f.update(det, diag_cov(0.005, 0.01), odom, 300, 20) == FilterUpdate::kFused);
  CHECK_FALSE(f.confirmed());
  CHECK(f.update(det, diag_cov(0.005, 0.01), odom, 400, 0) == FilterUpdate::kFused);
  CHECK(f.confirmed());
}

TEST(DockPoseFilter, TagsRestartTheFilterOnlyWhileItRestsOnTags) {
  const Pose2 odom{};
  const Pose2 det{1.0, 0.0, kPi};
  const Pose2 moved{1.0, 0.3, kPi};
  // Tags alone: three jumps in a row restart it at the new place (the robot was pushed).
  DockPoseFilter a;
  a.update_tag(det, diag_cov(0.005, 0.05), odom, 1);
  CHECK(a.update_tag(moved, diag_cov(0.005, 0.05), odom, 2) == FilterUpdate::kGated);
  CHECK(a.update_tag(moved, diag_cov(0.005, 0.05), odom, 3) == FilterUpdate::kGated);
  CHECK(a.update_tag(moved, diag_cov(0.005, 0.05), odom, 4) == FilterUpdate::kReinitialised);
  REAL_EQUAL(0.3, a.dock_in_odom().y_m, 1e-9);
  // With a lidar detection fused since the start, a disagreeing tag is gated however often.
  DockPoseFilter b;
  b.update(det, diag_cov(0.005, 0.01), odom, 1, 5);
  for (int i = 0; i < 10; ++i) CHECK(b.update_tag(moved, diag_cov(0.005, 0.05), odom, 2 + i) == FilterUpdate::kGated);
  LONGS_EQUAL(10, b.tag_gated());
  LONGS_EQUAL(0, b.reinitialisations());
  REAL_EQUAL(0.0, b.dock_in_odom().y_m, 1e-9);
  // Non-finite tag input changes nothing.
  CHECK(b.update_tag(Pose2{std::nan(""), 0, 0}, diag_cov(0.005, 0.05), odom, 20) == FilterUpdate::kInvalid);
}
