// core kinematics: wheel speeds from hand formulas, round trips, curvature-preserving saturation, acceleration limiter.
// That the simulated chassis' own kinematics agree with these is test_chassis' ChassisKinematics.MatchesCoreKinematics.
#include <cmath>
#include <type_traits>

#include "dockcore/control/kinematics.hpp"

#include "drive_geometries.hpp"
#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using dockcore_test::diff_geom;
using dockcore_test::mec_geom;
using dockcore_test::tw;

namespace {

const double kTol = std::is_same<Real, float>::value ? 1e-4 : 1e-12;

}  // namespace

TEST_GROUP(Kinematics){};

TEST(Kinematics, DiffHandNumbers) {
  // vx 0.2, wz 1: left surface 0.2 - 0.15 = 0.05 m/s -> 1 rad/s; right 0.35 m/s -> 7 rad/s.
  const WheelSpeeds w = twist_to_wheels(diff_geom(), tw(0.2, 0.5, 1.0));
  LONGS_EQUAL(2, w.count);
  REAL_EQUAL(1.0, w.radps[0], kTol);
  REAL_EQUAL(7.0, w.radps[1], kTol);
  REAL_EQUAL(0.0, w.radps[2], 0.0);
  const Twist2 back = wheels_to_twist(diff_geom(), w);
  REAL_EQUAL(0.2, back.vx_mps, kTol);
  REAL_EQUAL(0.0, back.vy_mps, 0.0);  // diff drops vy
  REAL_EQUAL(1.0, back.wz_radps, kTol);
}

TEST(Kinematics, MecanumHandNumbersAndRoundTrip) {
  // Pure sideways left 0.1 m/s, r 0.04: FL -2.5, FR +2.5, RL +2.5, RR -2.5 rad/s.
  WheelSpeeds w = twist_to_wheels(mec_geom(), tw(0, 0.1, 0));
  LONGS_EQUAL(4, w.count);
  REAL_EQUAL(-2.5, w.radps[0], kTol);
  REAL_EQUAL(2.5, w.radps[1], kTol);
  REAL_EQUAL(2.5, w.radps[2], kTol);
  REAL_EQUAL(-2.5, w.radps[3], kTol);
  // Pure yaw 1 rad/s, k = 0.35: left wheels -8.75, right +8.75.
  w = twist_to_wheels(mec_geom(), tw(0, 0, 1));
  REAL_EQUAL(-8.75, w.radps[0], kTol);
  REAL_EQUAL(8.75, w.radps[1], kTol);
  REAL_EQUAL(-8.75, w.radps[2], kTol);
  REAL_EQUAL(8.75, w.radps[3], kTol);
  const Twist2 t = tw(0.13, -0.07, 0.41);
  const Twist2 b = wheels_to_twist(mec_geom(), twist_to_wheels(mec_geom(), t));
  REAL_EQUAL(0.13, b.vx_mps, kTol);
  REAL_EQUAL(-0.07, b.vy_mps, kTol);
  REAL_EQUAL(0.41, b.wz_radps, kTol);
}

TEST(Kinematics, SaturationKeepsCurvature) {
  DriveLimits lim;
  lim.max_vx_mps = static_cast<Real>(0.3);
  lim.max_wz_radps = static_cast<Real>(1.0);
  lim.max_wheel_radps = 0;  // off: only the body limits
  Real f = 0;
  // vx 0.6 (2x over), wz 0.8 (fine): factor 0.5 on both.
  Twist2 s = saturate_twist(diff_geom(), lim, tw(0.6, 0, 0.8), &f);
  REAL_EQUAL(0.5, f, kTol);
  REAL_EQUAL(0.3, s.vx_mps, kTol);
  REAL_EQUAL(0.4, s.wz_radps, kTol);
  REAL_EQUAL(0.6 / 0.8, s.vx_mps / s.wz_radps, kTol);
  // wz binds: 0.1 m/s with 4 rad/s -> factor 0.25.
  s = saturate_twist(diff_geom(), lim, tw(0.1, 0, -4), &f);
  REAL_EQUAL(0.25, f, kTol);
  REAL_EQUAL(0.025, s.vx_mps, kTol);
  REAL_EQUAL(-1.0, s.wz_radps, kTol);
  // Inside every limit: untouched.
  s = saturate_twist(diff_geom(), lim, tw(0.1, 0, 0.2), &f);
  REAL_EQUAL(1.0, f, 0.0);
  REAL_EQUAL(0.1, s.vx_mps, 0.0);
  // Diff drops vy before limiting: a huge vy must not shrink the rest.
  lim.max_vy_mps = static_cast<Real>(0.01);
  s = saturate_twist(diff_geom(), lim, tw(0.1, 5, 0.2), &f);
  REAL_EQUAL(1.0, f, 0.0);
  REAL_EQUAL(0.0, s.vy_mps, 0.0);
  // Non-finite -> zero.
  s = saturate_twist(diff_geom(), lim, tw(std::nan(""), 0, 0), &f);
  REAL_EQUAL(0.0, f, 0.0);
  REAL_EQUAL(0.0, s.vx_mps, 0.0);
}

TEST(Kinematics, SaturationHonoursWheelLimit) {
  DriveLimits lim;
  lim.max_vx_mps = lim.max_vy_mps = lim.max_wz_radps = 0;
  lim.max_wheel_radps = static_cast<Real>(5.0);
  // Diff: vx 0.2, wz 1 -> wheels 1 and 7 rad/s: factor 5/7.
  Real f = 0;
  Twist2 s = saturate_twist(diff_geom(), lim, tw(0.2, 0, 1), &f);
  REAL_EQUAL(5.0 / 7.0, f, kTol);
  WheelSpeeds w = twist_to_wheels(diff_geom(), s);
  REAL_EQUAL(5.0, w.radps[1], kTol);
  REAL_EQUAL(5.0 / 7.0, w.radps[0], kTol);
  REAL_EQUAL(0.2 / 1.0, s.vx_mps / s.wz_radps, kTol);
  // Mecanum: FR = (0.3 + 0.1 + 0.35*0.5)/0.04 = 14.375 rad/s is the largest.
  s = saturate_twist(mec_geom(), lim, tw(0.3, 0.1, 0.5), &f);
  REAL_EQUAL(5.0 / 14.375, f, kTol);
  w = twist_to_wheels(mec_geom(), s);
  for (std::size_t i = 0; i < 4; ++i) CHECK(std::fabs(static_cast<double>(w.radps[i])) <= 5.0 + kTol);
  REAL_EQUAL(5.0, w.radps[1], kTol);
  REAL_EQUAL(3.0, s.vx_mps / s.vy_mps, kTol);
}

TEST(Kinematics, AccelerationLimiterFromRestKeepsCurvature) {
  DriveLimits lim;
  lim.max_linear_accel_mps2 = static_cast<Real>(0.5);
  lim.max_angular_accel_radps2 = static_cast<Real>(2.0);
  const Real dt = static_cast<Real>(0.02);
  Twist2 prev{};
  const Twist2 want = tw(0.2, 0, 0.5);
  int ticks = 0;
  // Against the target as Real holds it (0.2f is 3e-9 off 0.2: the double literal is never reached in float).
  while ((std::fabs(static_cast<double>(prev.vx_mps - want.vx_mps)) > 1e-9) && ticks < 1000) {
    const Twist2 next = limit_acceleration(lim, prev, want, dt);
    CHECK(std::fabs(static_cast<double>(next.vx_mps - prev.vx_mps)) <= 0.01 + kTol);
    CHECK(std::fabs(static_cast<double>(next.wz_radps - prev.wz_radps)) <= 0.04 + kTol);
    REAL_EQUAL(0.4, next.vx_mps / next.wz_radps, kTol);  // curvature of the desired arc, every tick
    prev = next;
    ++ticks;
  }
  // 0.2 m/s at 0.5 m/s^2 (the binding limit; wz needs 0.25 s at 2 rad/s^2) = 0.4 s = 20 ticks.
  LONGS_EQUAL(20, ticks);
}

TEST(Kinematics, AccelerationLimiterCurvatureFlip) {
  DriveLimits lim;
  lim.max_linear_accel_mps2 = static_cast<Real>(0.5);
  lim.max_angular_accel_radps2 = static_cast<Real>(1.0);
  const Real dt = static_cast<Real>(0.1);
  // From a left arc to a right arc: no scaled copy of the target is reachable -> common step along the change.
  const Twist2 prev = tw(0.2, 0, 0.5);
  const Twist2 next = limit_acceleration(lim, prev, tw(0.2, 0, -0.5), dt);
  REAL_EQUAL(0.2, next.vx_mps, kTol);
  REAL_EQUAL(0.4, next.wz_radps, kTol);
  // Stop from a fast arc: decelerates along the same curvature.
  const Twist2 s = limit_acceleration(lim, tw(0.3, 0, 0.6), Twist2{}, dt);
  REAL_EQUAL(0.5, s.vx_mps / s.wz_radps, kTol);
  REAL_EQUAL(0.25, s.vx_mps, kTol);
  // Bad dt: unchanged.
  const Twist2 u = limit_acceleration(lim, prev, Twist2{}, 0);
  REAL_EQUAL(0.2, u.vx_mps, 0.0);
}
