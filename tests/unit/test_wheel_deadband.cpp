// core wheel deadband: scaling a command above the floors while keeping its curvature, the pivot and wheel-limit
// caps, and learning a floor from a stalled wheel (per wheel and direction, bounded, never while told not to).
#include <cmath>
#include <cstdint>

#include "dockcore/control/kinematics.hpp"
#include "dockcore/control/wheel_deadband.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;

namespace {

constexpr std::uint64_t kMs = 1000;
constexpr double kTol = 1e-5;

DriveGeometry diff_drive() {
  DriveGeometry g;
  g.kind = DriveKind::kDifferential;
  g.wheel_radius_m = static_cast<Real>(0.05);
  g.wheel_base_m = static_cast<Real>(0.30);
  return g;
}

WheelSpeeds wheels(Real left, Real right) {
  WheelSpeeds w;
  w.count = 2;
  w.radps[0] = left;
  w.radps[1] = right;
  return w;
}

/// Both wheels at `radps`.
WheelSpeeds both(Real radps) {
  return wheels(radps, radps);
}

/// The default parameters with stall_ms at 250 ms: the tests that time stands against it keep their timings whatever
/// the default.
WheelDeadbandParams stands_timed_at_250_ms() {
  WheelDeadbandParams p;
  p.stall_ms = 250;
  return p;
}

/// Feeds `commanded` and `measured` every 20 ms from `t0_us` for `duration_ms`; returns the time after the last.
std::uint64_t hold(WheelDeadband& d, const WheelSpeeds& commanded, const WheelSpeeds& measured, std::uint64_t t0_us,
                   std::uint64_t duration_ms, bool learn = true) {
  std::uint64_t t = t0_us;
  for (; t <= t0_us + duration_ms * kMs; t += 20 * kMs) d.observe(commanded, measured, t, learn);
  return t;
}

}  // namespace

TEST_GROUP(WheelDeadband){};

TEST(WheelDeadband, NoFloorLeavesEveryCommandAlone) {
  WheelDeadband d;
  d.configure(WheelDeadbandParams{});
  const Twist2 creep{static_cast<Real>(0.01), 0, static_cast<Real>(0.02)};
  DOUBLES_EQUAL(1.0, static_cast<double>(d.scale(diff_drive(), DriveLimits{}, creep)), kTol);
  DOUBLES_EQUAL(1.0, static_cast<double>(d.scale(diff_drive(), DriveLimits{}, Twist2{})), kTol);
}

TEST(WheelDeadband, AKnownFloorScalesTheWholeCommandAndKeepsItsCurvature) {
  WheelDeadbandParams p;
  p.known_radps = static_cast<Real>(0.8);
  WheelDeadband d;
  d.configure(p);
  const DriveGeometry g = diff_drive();
  // 0.03 m/s on a 3 1/m curve: wheels 0.33 and 0.87 rad/s; the inner one must reach 0.8.
  const Twist2 c{static_cast<Real>(0.03), 0, static_cast<Real>(0.09)};
  const Real s = d.scale(g, DriveLimits{}, c);
  const WheelSpeeds w = twist_to_wheels(g, Twist2{c.vx_mps * s, 0, c.wz_radps * s});
  DOUBLES_EQUAL(0.8, static_cast<double>(w.radps[0]), kTol);
  CHECK(w.radps[1] > static_cast<Real>(0.8));
  DOUBLES_EQUAL(static_cast<double>(c.wz_radps / c.vx_mps), static_cast<double>((c.wz_radps * s) / (c.vx_mps * s)),
                kTol);
  // Fast enough already: untouched.
  DOUBLES_EQUAL(1.0, static_cast<double>(d.scale(g, DriveLimits{}, Twist2{static_cast<Real>(0.2), 0, 0})), kTol);
  // Backwards: the reverse floors apply.
  const Real back = d.scale(g, DriveLimits{}, Twist2{static_cast<Real>(-0.02), 0, 0});
  DOUBLES_EQUAL(0.8 / 0.4, static_cast<double>(back), kTol);
}

TEST(WheelDeadband, APivotingWheelStaysInTheDeadbandAndTheWheelLimitCapsTheScale) {
  WheelDeadbandParams p;
  p.known_radps = static_cast<Real>(0.8);
  WheelDeadband d;
  d.configure(p);
  const DriveGeometry g = diff_drive();
  // Nearly a pivot about the left wheel: only the right wheel sets the scale.
  const Twist2 pivot{static_cast<Real>(0.01), 0, static_cast<Real>(0.0625)};  // wheels ≈ 0.0125 and 0.3875 rad/s
  const Real s = d.scale(g, DriveLimits{}, pivot);
  const WheelSpeeds w = twist_to_wheels(g, Twist2{pivot.vx_mps * s, 0, pivot.wz_radps * s});
  DOUBLES_EQUAL(0.8, static_cast<double>(w.radps[1]), kTol);
  CHECK(std::fabs(w.radps[0]) < static_cast<Real>(0.8));
  DriveLimits lim;
  lim.max_wheel_radps = static_cast<Real>(0.5);
  const Real capped = d.scale(g, lim, Twist2{static_cast<Real>(0.01), 0, 0});  // wheels 0.2 rad/s
  DOUBLES_EQUAL(2.5, static_cast<double>(capped), kTol);
}

TEST(WheelDeadband, AStalledWheelRaisesItsOwnFloorForItsOwnDirectionOnly) {
  WheelDeadband d;
  d.configure(WheelDeadbandParams{});
  const WheelSpeeds cmd = both(static_cast<Real>(0.6));
  // The left wheel stands, the right one follows.
  const std::uint64_t stall_ms = WheelDeadbandParams{}.stall_ms;
  const std::uint64_t t = hold(d, cmd, wheels(0, static_cast<Real>(0.58)), 0, stall_ms - 20);
  DOUBLES_EQUAL(0.0, static_cast<double>(d.floor_radps(0, false)), kTol);  // not yet stall_ms
  hold(d, cmd, wheels(0, static_cast<Real>(0.58)), t, 40);
  DOUBLES_EQUAL(0.75, static_cast<double>(d.floor_radps(0, false)), kTol);  // 1.25 × 0.6
  DOUBLES_EQUAL(0.0, static_cast<double>(d.floor_radps(0, true)), kTol);
  DOUBLES_EQUAL(0.0, static_cast<double>(d.floor_radps(1, false)), kTol);
  LONGS_EQUAL(1, d.raises());
}

TEST(WheelDeadband, AWheelSlowToFollowOrToldNotToLearnIsNoStall) {
  WheelDeadband d;
  d.configure(WheelDeadbandParams{});
  const WheelSpeeds cmd = both(static_cast<Real>(0.6));
  // Standing for most of stall_ms (latency and motor lag), then following: the stall never lasts stall_ms.
  std::uint64_t t = hold(d, cmd, wheels(0, 0), 0, WheelDeadbandParams{}.stall_ms - 60);
  t = hold(d, cmd, wheels(static_cast<Real>(0.5), static_cast<Real>(0.5)), t, 2000);
  // Held by something the caller knows of (the dock, an obstacle): nothing is learned however long.
  hold(d, cmd, wheels(0, 0), t, 5000, false);
  LONGS_EQUAL(0, d.raises());
  DOUBLES_EQUAL(0.0, static_cast<double>(d.floor_radps(0, false)), kTol);
}

TEST(WheelDeadband, FloorsGrowStepByStepUpToTheBoundAndConfigureForgetsThem) {
  WheelDeadbandParams p;
  p.max_radps = static_cast<Real>(1.0);
  WheelDeadband d;
  d.configure(p);
  const DriveGeometry g = diff_drive();
  const Twist2 creep{static_cast<Real>(-0.03), 0, 0};  // backing in: 0.6 rad/s on both wheels, backwards
  std::uint64_t t = 0;
  for (int k = 0; k < 10; ++k) {
    const Real s = d.scale(g, DriveLimits{}, creep);
    const WheelSpeeds sent = twist_to_wheels(g, Twist2{creep.vx_mps * s, 0, 0});
    t = hold(d, sent, wheels(0, 0), t, 520);  // a drive that never moves
  }
  DOUBLES_EQUAL(1.0, static_cast<double>(d.floor_radps(0, true)), kTol);
  DOUBLES_EQUAL(1.0, static_cast<double>(d.floor_radps(1, true)), kTol);
  DOUBLES_EQUAL(0.0, static_cast<double>(d.floor_radps(0, false)), kTol);
  // 0.6 → 0.75 → 0.9375 → 1.0 (bound) on each wheel, then no more.
  LONGS_EQUAL(6, d.raises());
  d.configure(p);
  DOUBLES_EQUAL(0.0, static_cast<double>(d.floor_radps(0, true)), kTol);
  LONGS_EQUAL(0, d.raises());
}

// What a drive taught one configuration goes on into the next (dockd configuring the core for another dock): the
// floors and their count, clamped as configure() clamps the known deadband; a stall in progress is not carried.
TEST(WheelDeadband, RestoredFloorsAreTheLearnedOnesWithinThisConfigurationsBounds) {
  const WheelDeadbandParams p = stands_timed_at_250_ms();
  WheelDeadband taught;
  taught.configure(p);
  const WheelSpeeds cmd = both(static_cast<Real>(0.6));
  std::uint64_t t = hold(taught, cmd, wheels(0, static_cast<Real>(0.6)), 0, 300);  // the left wheel stands
  LONGS_EQUAL(1, taught.raises());
  DOUBLES_EQUAL(0.75, static_cast<double>(taught.floor_radps(0, false)), kTol);
  hold(taught, cmd, wheels(0, static_cast<Real>(0.6)), t, 200);  // standing again: a stall in progress

  WheelDeadband next;
  next.configure(p);
  next.restore_floors(taught.floors());
  DOUBLES_EQUAL(0.75, static_cast<double>(next.floor_radps(0, false)), kTol);
  DOUBLES_EQUAL(0.0, static_cast<double>(next.floor_radps(1, false)), kTol);
  LONGS_EQUAL(1, next.raises());
  // The carried stall would have raised the floor 60 ms from now; a fresh one needs its whole stall_ms.
  t = hold(next, wheels(static_cast<Real>(0.75), static_cast<Real>(0.75)), wheels(0, static_cast<Real>(0.75)), t, 200);
  LONGS_EQUAL(1, next.raises());

  WheelDeadbandParams bounded = p;
  bounded.known_radps = static_cast<Real>(0.3);
  bounded.max_radps = static_cast<Real>(0.7);
  WheelDeadband clamped;
  clamped.configure(bounded);
  clamped.restore_floors(taught.floors());
  DOUBLES_EQUAL(0.7, static_cast<double>(clamped.floor_radps(0, false)), kTol);  // at most max_radps
  DOUBLES_EQUAL(0.3, static_cast<double>(clamped.floor_radps(1, false)), kTol);  // at least the known deadband
}

TEST(WheelDeadband, ACommandAtItsFloorUpToRoundingStillStalls) {
  WheelDeadbandParams p;
  p.known_radps = static_cast<Real>(0.75);
  WheelDeadband d;
  d.configure(p);
  // What scale() sends meets the floor only up to rounding: a hair below it is still a command at the floor.
  const Real at_floor = static_cast<Real>(0.75) * (1 - static_cast<Real>(1e-5));
  hold(d, wheels(at_floor, at_floor), wheels(0, 0), 0, 520);
  DOUBLES_EQUAL(0.9375, static_cast<double>(d.floor_radps(0, false)), 1e-4);
  // Clearly below the floor is no stall of that floor: such a command is one scale() never sends.
  WheelDeadband e;
  e.configure(p);
  hold(e, wheels(static_cast<Real>(0.5), static_cast<Real>(0.5)), wheels(0, 0), 0, 520);
  LONGS_EQUAL(0, e.raises());
}

// A wheel whose deadband lies inside the range the controller's corrections sweep stands, turns and stands again;
// no stand lasts stall_ms, but they add up.
TEST(WheelDeadband, StandsInterruptedByShortTurnsAddUpToAStall) {
  const WheelDeadbandParams p = stands_timed_at_250_ms();
  WheelDeadband d;
  d.configure(p);
  const WheelSpeeds cmd = both(static_cast<Real>(0.6));
  const WheelSpeeds turning = wheels(static_cast<Real>(0.55), static_cast<Real>(0.55));
  std::uint64_t t = 0;
  for (int k = 0; k < 2; ++k) {
    t = hold(d, cmd, wheels(0, static_cast<Real>(0.55)), t, 100);  // the left wheel stands ~100 ms
    t = hold(d, cmd, turning, t, 60);                              // and turns for a moment
  }
  LONGS_EQUAL(0, d.raises());  // about 200 ms stood in all
  hold(d, cmd, wheels(0, static_cast<Real>(0.55)), t, 100);
  LONGS_EQUAL(1, d.raises());
  DOUBLES_EQUAL(0.75, static_cast<double>(d.floor_radps(0, false)), kTol);
  DOUBLES_EQUAL(0.0, static_cast<double>(d.floor_radps(1, false)), kTol);
}

// The stiffer wheel of a creep: the heading corrections carry its command above its deadband, where it turns for
// longer than stall_ms, and below it, where it stands again. Turning faster than it stood says nothing of a deadband
// below, so the stands still add up, and the floor comes from the latest stand (the first one, a start from rest at a
// smaller command, would teach a floor the wheel still stands above).
TEST(WheelDeadband, TurningFasterThanItStoodKeepsTheStandsAndTheLatestOneSetsTheFloor) {
  const WheelDeadbandParams p = stands_timed_at_250_ms();
  WheelDeadband d;
  d.configure(p);
  const auto left_stands = [](Real radps) { return wheels(0, radps); };
  std::uint64_t t = hold(d, both(static_cast<Real>(0.3)), left_stands(static_cast<Real>(0.3)), 0, 140);  // 140 ms
  t = hold(d, both(static_cast<Real>(0.9)), both(static_cast<Real>(0.88)), t, 400);       // turns well past stall_ms
  t = hold(d, both(static_cast<Real>(0.7)), left_stands(static_cast<Real>(0.7)), t, 80);  // 100 ms more
  LONGS_EQUAL(0, d.raises());
  hold(d, both(static_cast<Real>(0.7)), left_stands(static_cast<Real>(0.7)), t, 20);
  LONGS_EQUAL(1, d.raises());
  DOUBLES_EQUAL(0.875, static_cast<double>(d.floor_radps(0, false)), kTol);  // 1.25 × 0.7, not × 0.3
  DOUBLES_EQUAL(0.0, static_cast<double>(d.floor_radps(1, false)), kTol);
}

// A stand that ends in stall_ms of following was the drive being slow, and a command that stops or turns round
// starts afresh: neither lets two stands add up.
TEST(WheelDeadband, FollowingForStallMsOrAStoppedCommandForgetsTheStands) {
  const WheelDeadbandParams p = stands_timed_at_250_ms();
  const WheelSpeeds cmd = both(static_cast<Real>(0.6));
  const WheelSpeeds standing = wheels(0, 0);
  {
    WheelDeadband d;
    d.configure(p);
    std::uint64_t t = hold(d, cmd, standing, 0, 200);
    t = hold(d, cmd, wheels(static_cast<Real>(0.55), static_cast<Real>(0.55)), t, 260);
    hold(d, cmd, standing, t, 200);
    LONGS_EQUAL(0, d.raises());
  }
  {
    WheelDeadband d;
    d.configure(p);
    std::uint64_t t = hold(d, cmd, standing, 0, 200);
    t = hold(d, wheels(0, 0), standing, t, 20);
    hold(d, cmd, standing, t, 200);
    LONGS_EQUAL(0, d.raises());
  }
  {
    WheelDeadband d;
    d.configure(p);
    std::uint64_t t = hold(d, cmd, standing, 0, 200);
    t = hold(d, wheels(static_cast<Real>(-0.6), static_cast<Real>(-0.6)), standing, t, 20);
    hold(d, cmd, standing, t, 200);
    LONGS_EQUAL(0, d.raises());
  }
}

namespace {

/// The left wheel on a first-order motor (time constant tau_s) behind a deadband: it runs towards `command` when
/// |command| reaches `deadband`, towards standing otherwise; the right one is not commanded. Observed every 20 ms from
/// `t0_us` for `duration_ms`; returns the time after the last, and leaves the motor's speed in `*speed`.
std::uint64_t motor(WheelDeadband& d, Real command, Real deadband, double tau_s, Real* speed, std::uint64_t t0_us,
                    std::uint64_t duration_ms) {
  std::uint64_t t = t0_us;
  const Real a = static_cast<Real>(1.0 - std::exp(-0.02 / tau_s));
  for (; t <= t0_us + duration_ms * kMs; t += 20 * kMs) {
    const Real target = std::fabs(command) >= deadband ? command : 0;
    *speed += a * (target - *speed);
    d.observe(wheels(command, 0), wheels(*speed, 0), t, true);
  }
  return t;
}

}  // namespace

TEST(WheelDeadband, ASlowMotorRunningDownInItsDeadbandIsCaughtBeforeItFallsUnderAQuarter) {
  WheelDeadband d;
  d.configure(WheelDeadbandParams{});
  // Turning at 1.2 rad/s, then commanded 0.9 under a 1.0 rad/s deadband: with a 0.25 s motor the wheel takes
  // 0.35 s to run down under a quarter of the command, far longer than the creep's corrections stay there.
  Real speed = static_cast<Real>(1.2);
  std::uint64_t t = motor(d, static_cast<Real>(1.2), 1, 0.25, &speed, 0, 500);
  LONGS_EQUAL(0, d.raises());
  t = motor(d, static_cast<Real>(0.9), 1, 0.25, &speed, t, WheelDeadbandParams{}.stall_ms + 120);
  CHECK(speed > static_cast<Real>(0.25 * 0.9));  // the old test alone would not have begun the stall
  LONGS_EQUAL(1, d.raises());
  DOUBLES_EQUAL(1.25 * 0.9, static_cast<double>(d.floor_radps(0, false)), kTol);
}

TEST(WheelDeadband, ASlowMotorStartingOrTurningRoundIsNoStall) {
  WheelDeadband d;
  d.configure(WheelDeadbandParams{});
  // A 0.25 s motor without a deadband, started from rest and later turned round: under a quarter of the command for
  // longer than stall_ms each time from reverse (0.25 s), but speeding up towards it all the while.
  Real speed = 0;
  std::uint64_t t = motor(d, static_cast<Real>(0.8), 0, 0.25, &speed, 0, 1000);
  t = motor(d, static_cast<Real>(-0.8), 0, 0.25, &speed, t, 1000);
  motor(d, static_cast<Real>(0.8), 0, 0.25, &speed, t, 1000);
  LONGS_EQUAL(0, d.raises());
}

TEST(WheelDeadband, ARepeatedStampAddsNoTime) {
  WheelDeadband d;
  d.configure(WheelDeadbandParams{});
  const WheelSpeeds cmd = both(static_cast<Real>(0.6));
  // A chassis that has fallen silent: the last feedback (standing) is handed over tick after tick.
  for (int i = 0; i < 100; ++i) d.observe(cmd, wheels(0, 0), 40 * kMs, true);
  LONGS_EQUAL(0, d.raises());
}
