// core odometry: integration of measured wheel speeds (straight, arc, mecanum sideways), the feedback stamp rules
// (repeats, gaps, clock steps), a base's own pose, the history that places a scan at its own stamp, and Dockcore's
// wheel feedback into it.
#include <cmath>
#include <cstdint>
#include <type_traits>

#include "dockcore/control/controllers.hpp"
#include "dockcore/control/kinematics.hpp"
#include "dockcore/control/odometry.hpp"
#include "dockcore/dockcore.hpp"
#include "dockcore/perception/dock_profile.hpp"

#include "drive_geometries.hpp"
#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using dockcore_test::diff_geom;
using dockcore_test::mec_geom;

namespace {

const double kTol = std::is_same<Real, float>::value ? 2e-5 : 1e-9;

WheelSpeeds wheels_for(const DriveGeometry& g, double vx, double vy, double wz) {
  return twist_to_wheels(g, dockcore_test::tw(vx, vy, wz));
}

/// Feeds `n` feedbacks of the same wheel speeds every `period_us`, starting at `t0_us`.
void feed(Odometry& o, const DriveGeometry& g, const WheelSpeeds& w, std::uint64_t t0_us, std::uint64_t period_us,
          int n) {
  for (int i = 0; i < n; ++i) CHECK(o.add_wheels(g, w, t0_us + static_cast<std::uint64_t>(i) * period_us));
}

}  // namespace

TEST_GROUP(Odometry){};

TEST(Odometry, StraightAndArcFromWheelSpeeds) {
  const DriveGeometry g = diff_geom();
  Odometry o;
  CHECK_FALSE(o.valid());
  // 0.2 m/s for 1 s (51 feedbacks 20 ms apart: 50 intervals): 0.2 m ahead.
  feed(o, g, wheels_for(g, 0.2, 0, 0), 1000000, 20000, 51);
  CHECK(o.valid());
  REAL_EQUAL(0.2, o.pose().x_m, kTol);
  REAL_EQUAL(0.0, o.pose().y_m, kTol);
  REAL_EQUAL(0.2, o.twist().vx_mps, kTol);
  LONGS_EQUAL(2000000, static_cast<long>(o.stamp_us()));
  // A quarter circle of radius 0.5 m: vx 0.25 m/s, wz 0.5 rad/s for π s. The midpoint rule is exact in yaw and
  // within 0.1 mm in position at 20 ms steps.
  o.reset();
  const double quarter_s = 3.14159265358979323846;
  const int steps = static_cast<int>(std::lround(quarter_s / 0.02));
  const WheelSpeeds arc = wheels_for(g, 0.25, 0, 0.5);
  CHECK(o.add_wheels(g, arc, 1000000));
  feed(o, g, arc, 1020000, 20000, steps);
  const double t = 0.02 * steps;
  REAL_EQUAL(0.5 * std::sin(0.5 * t), o.pose().x_m, 1e-4);
  REAL_EQUAL(0.5 * (1 - std::cos(0.5 * t)), o.pose().y_m, 1e-4);
  REAL_EQUAL(0.5 * t, o.pose().yaw_rad, dockcore_test::real_tol(1.6, 1e-9, 64));
}

TEST(Odometry, MecanumSideways) {
  const DriveGeometry g = mec_geom();
  Odometry o;
  feed(o, g, wheels_for(g, 0, 0.1, 0), 500000, 10000, 101);  // 1 s left at 0.1 m/s
  REAL_EQUAL(0.0, o.pose().x_m, kTol);
  REAL_EQUAL(0.1, o.pose().y_m, kTol);
  REAL_EQUAL(0.0, o.pose().yaw_rad, kTol);
}

TEST(Odometry, StampRulesRepeatsGapsAndClockSteps) {
  const DriveGeometry g = diff_geom();
  const WheelSpeeds w = wheels_for(g, 0.5, 0, 0);
  Odometry o;
  CHECK_FALSE(o.add_wheels(g, w, 0));  // stamp 0: no feedback
  CHECK_FALSE(o.valid());
  CHECK(o.add_wheels(g, w, 1000000));
  REAL_EQUAL(0.0, o.pose().x_m, 0.0);        // the first feedback starts the integration, it has no interval
  CHECK_FALSE(o.add_wheels(g, w, 1000000));  // the same frame again
  CHECK(o.add_wheels(g, w, 1100000));
  REAL_EQUAL(0.05, o.pose().x_m, kTol);
  // A 0.3 s gap (longer than kMaxGapUs): not integrated across, the pose stays.
  CHECK(o.add_wheels(g, w, 1400000));
  REAL_EQUAL(0.05, o.pose().x_m, kTol);
  // Exactly at the limit is a gap too; just under it is integrated.
  CHECK(o.add_wheels(g, w, 1400000 + Odometry::kMaxGapUs));
  REAL_EQUAL(0.05, o.pose().x_m, kTol);
  CHECK(o.add_wheels(g, w, 1400000 + 2 * Odometry::kMaxGapUs - 1));
  REAL_EQUAL(0.05 + 0.5 * 0.199999, o.pose().x_m, kTol);
  // A clock step back: accepted as the new start, nothing integrated.
  const Real x = o.pose().x_m;
  CHECK(o.add_wheels(g, w, 10));
  REAL_EQUAL(x, o.pose().x_m, 0.0);
  LONGS_EQUAL(10, static_cast<long>(o.stamp_us()));
  CHECK(o.add_wheels(g, w, 20010));
  REAL_EQUAL(x + 0.01, o.pose().x_m, kTol);
}

TEST(Odometry, ABasesOwnPoseIsKeptAsGiven) {
  Odometry o;
  const Pose2 p = dockcore_test::pose(1.5, -0.25, 0.75);
  const Twist2 tw{static_cast<Real>(0.1), 0, static_cast<Real>(-0.2)};
  CHECK_FALSE(o.add_pose(p, tw, 0));
  CHECK(o.add_pose(p, tw, 40000));
  CHECK(o.pose().x_m == p.x_m && o.pose().y_m == p.y_m && o.pose().yaw_rad == p.yaw_rad);
  CHECK(o.twist().vx_mps == tw.vx_mps && o.twist().wz_radps == tw.wz_radps);
  CHECK_FALSE(o.add_pose(dockcore_test::pose(0, 0, 0), tw, 40000));  // a repeated stamp changes nothing
  REAL_EQUAL(1.5, o.pose().x_m, kTol);
}

TEST(Odometry, HistoryPlacesAStampAtTheNewestPoseNotAfterIt) {
  Odometry o;
  // Before any feedback: the origin.
  const Pose2 none = o.pose_at(123456);
  CHECK(none.x_m == 0 && none.y_m == 0 && none.yaw_rad == 0);
  const Twist2 still{};
  // Poses x = i cm at t = 1 s + i·20 ms, i = 0..99 (more than the history holds).
  for (int i = 0; i < 100; ++i) {
    CHECK(o.add_pose(dockcore_test::pose(0.01 * i, 0, 0), still, 1000000 + static_cast<std::uint64_t>(i) * 20000));
  }
  REAL_EQUAL(0.99, o.pose_at(1000000 + 99 * 20000).x_m, kTol);          // the newest, exactly
  REAL_EQUAL(0.80, o.pose_at(1000000 + 80 * 20000 + 19999).x_m, kTol);  // between two: the earlier
  REAL_EQUAL(0.99, o.pose_at(9000000).x_m, kTol);                       // after the newest: the newest
  const int oldest = 100 - static_cast<int>(Odometry::kHistory);
  REAL_EQUAL(0.01 * oldest, o.pose_at(1000000 + static_cast<std::uint64_t>(oldest) * 20000).x_m, kTol);
  // Older than every kept sample: the current pose (the scan is placed where the robot is now).
  REAL_EQUAL(0.99, o.pose_at(1000000 + static_cast<std::uint64_t>(oldest - 1) * 20000).x_m, kTol);
  o.reset();
  CHECK_FALSE(o.valid());
  REAL_EQUAL(0.0, o.pose_at(2000000).x_m, 0.0);
}

TEST(Odometry, DockcoreIntegratesWheelFeedbackWithItsConfiguredDrive) {
  // Dockcore::on_wheels is Odometry::add_wheels with DockcoreConfig::drive: the same feedback gives the same pose, bit
  // for bit, under the same stamp rules.
  static SmoothController ctl;
  static DockcoreN<720> core(ctl);
  DockProfile prof;
  CHECK(builtin_profile("plate-v", prof) == ProfileError::kOk);
  DockcoreConfig cfg;
  cfg.drive = mec_geom();
  CHECK(core.configure(prof, cfg));
  const DriveGeometry g = mec_geom();
  Odometry o;
  const WheelSpeeds w = wheels_for(g, 0.1, 0.05, 0.3);
  CHECK_FALSE(core.on_wheels(w, 0));
  for (int i = 0; i < 20; ++i) {
    const std::uint64_t t = 1000000 + static_cast<std::uint64_t>(i) * 20000;
    CHECK(core.on_wheels(w, t));
    CHECK(o.add_wheels(g, w, t));
  }
  CHECK_FALSE(core.on_wheels(w, 1000000 + 19 * 20000));  // a repeated stamp is no new feedback
  CHECK(core.odometry().valid());
  CHECK(core.odometry().pose().x_m == o.pose().x_m && core.odometry().pose().y_m == o.pose().y_m &&
        core.odometry().pose().yaw_rad == o.pose().yaw_rad);
  LONGS_EQUAL(static_cast<long>(o.stamp_us()), static_cast<long>(core.odometry().stamp_us()));
  REAL_EQUAL(0.05, core.odometry().twist().vy_mps, kTol);  // sideways: the mecanum geometry was used
}
