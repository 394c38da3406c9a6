// Scripted chassis model (tools/sim): kinematics, motor dynamics, encoders, odometry drift, dock contact, battery.
// Expected numbers come from hand kinematics; the sim's own helpers are only used where the test says so.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <type_traits>

#include "dockcore/control/kinematics.hpp"
#include "dockcore/geometry.hpp"
#include "docksim/battery.hpp"
#include "docksim/chassis.hpp"

#include "drive_geometries.hpp"
#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

using namespace docksim;
using dockcore::kPi;

// Counts heap allocations while armed, to show step() never allocates. Interposes malloc (glibc's __libc_malloc does
// the work; operator new ends there too). Sanitizer runtimes own malloc, so the check is compiled out under them.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define CHASSIS_ALLOC_TRAP 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define CHASSIS_ALLOC_TRAP 0
#endif
#endif
#ifndef CHASSIS_ALLOC_TRAP
#define CHASSIS_ALLOC_TRAP 1
#endif

namespace {
volatile bool g_count_alloc = false;
volatile std::size_t g_allocs = 0;
}  // namespace
#if CHASSIS_ALLOC_TRAP
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void __libc_free(void*);
void* malloc(std::size_t n) {
  if (g_count_alloc) g_allocs = g_allocs + 1;
  return __libc_malloc(n);
}
void* calloc(std::size_t a, std::size_t b) {
  if (g_count_alloc) g_allocs = g_allocs + 1;
  return __libc_calloc(a, b);
}
void* realloc(void* p, std::size_t n) {
  if (g_count_alloc) g_allocs = g_allocs + 1;
  return __libc_realloc(p, n);
}
void free(void* p) { __libc_free(p); }
}
#endif

namespace {

constexpr double kDt = 0.005;
constexpr double kR = 0.05;  // wheel radius
constexpr double kB = 0.30;  // diff wheel base
constexpr double kLx = 0.20, kLy = 0.15;

// Every imperfection off: what remains is exact kinematics.
ChassisParams ideal(DriveKind kind) {
  ChassisParams p;
  p.dt_s = kDt;
  p.geometry.kind = kind;
  p.geometry.wheel_radius_m = kR;
  p.geometry.wheel_base_m = kB;
  p.geometry.lx_m = kLx;
  p.geometry.ly_m = kLy;
  p.motor.latency_steps = 0;
  p.motor.time_constant_s = 0;
  p.motor.max_accel_radps2 = 0;
  p.motor.max_speed_radps = 0;
  p.motor.deadband_radps = 0;
  p.noise.slip_sigma = 0;
  p.noise.encoder_cpr = 1 << 20;
  p.noise.speed_window_steps = 1;
  return p;
}

WheelRadps diff_cmd(double left, double right) { return WheelRadps{left, right, 0, 0}; }
WheelRadps all4(double a, double b, double c, double d) { return WheelRadps{a, b, c, d}; }

double px(const ChassisState& s) { return static_cast<double>(s.true_pose.x_m); }
double py(const ChassisState& s) { return static_cast<double>(s.true_pose.y_m); }
double pyaw(const ChassisState& s) { return static_cast<double>(s.true_pose.yaw_rad); }

// Robot pose that puts the pads (front, centre, 0.225 m ahead of the body origin for the default 0.45 m footprint)
// at dock-frame position (-press, lateral) with heading error yaw_err, for a dock at `dock`.
Pose2 pose_for_pad(const Pose2& dock, double press, double lateral, double yaw_err, double pad_x_body = 0.225) {
  const double pad_wx = static_cast<double>(dock.x_m) + std::cos(static_cast<double>(dock.yaw_rad)) * -press -
                        std::sin(static_cast<double>(dock.yaw_rad)) * lateral;
  const double pad_wy = static_cast<double>(dock.y_m) + std::sin(static_cast<double>(dock.yaw_rad)) * -press +
                        std::cos(static_cast<double>(dock.yaw_rad)) * lateral;
  const double yaw = static_cast<double>(dock.yaw_rad) + kPi + yaw_err;
  using dockcore::Real;
  return Pose2{static_cast<Real>(pad_wx - std::cos(yaw) * pad_x_body),
               static_cast<Real>(pad_wy - std::sin(yaw) * pad_x_body), static_cast<Real>(yaw)};
}

}  // namespace

TEST_GROUP(ChassisKinematics){};

TEST(ChassisKinematics, HelpersMatchHandFormulas) {
  DriveGeometry g;
  g.kind = DriveKind::kDifferential;
  g.wheel_radius_m = kR;
  g.wheel_base_m = kB;
  // v = 0.5, w = 1: left surface 0.5 - 0.15 = 0.35 → 7 rad/s, right 0.65 → 13 rad/s.
  WheelRadps w = body_twist_to_wheel_radps(g, BodyTwist{0.5, 0.0, 1.0});
  REAL_EQUAL(7.0, w[0], 1e-12);
  REAL_EQUAL(13.0, w[1], 1e-12);
  BodyTwist t = wheel_radps_to_body_twist(g, w);
  REAL_EQUAL(0.5, t.vx_mps, 1e-12);
  REAL_EQUAL(0.0, t.vy_mps, 1e-12);
  REAL_EQUAL(1.0, t.wz_radps, 1e-12);

  g.kind = DriveKind::kMecanum;
  g.lx_m = kLx;
  g.ly_m = kLy;
  // vx 0.2, vy 0.1, w 0.5, lx+ly = 0.35: FL 0.2-0.1-0.175 = -0.075, FR 0.475, RL 0.125, RR 0.275 (m/s) / 0.05.
  w = body_twist_to_wheel_radps(g, BodyTwist{0.2, 0.1, 0.5});
  REAL_EQUAL(-1.5, w[0], 1e-12);
  REAL_EQUAL(9.5, w[1], 1e-12);
  REAL_EQUAL(2.5, w[2], 1e-12);
  REAL_EQUAL(5.5, w[3], 1e-12);
  t = wheel_radps_to_body_twist(g, w);
  REAL_EQUAL(0.2, t.vx_mps, 1e-12);
  REAL_EQUAL(0.1, t.vy_mps, 1e-12);
  REAL_EQUAL(0.5, t.wz_radps, 1e-12);
}

// The chassis' wheel kinematics against core's (dockcore::twist_to_wheels / wheels_to_twist) on the geometries of
// core's kinematics suite: both directions agree for differential and mecanum drives.
TEST(ChassisKinematics, MatchesCoreKinematics) {
  using dockcore_test::diff_geom;
  using dockcore_test::mec_geom;
  using dockcore_test::tw;
  const double tol = std::is_same<dockcore::Real, float>::value ? 1e-4 : 1e-12;
  const double cases[][3] = {{0.2, 0, 0.5}, {-0.1, 0.05, -1.2}, {0, -0.2, 0.3}, {0.31, 0.12, 0}};
  for (int kind = 0; kind < 2; ++kind) {
    const dockcore::DriveGeometry g = kind == 0 ? diff_geom() : mec_geom();
    DriveGeometry sg;
    sg.kind = kind == 0 ? DriveKind::kDifferential : DriveKind::kMecanum;
    sg.wheel_radius_m = static_cast<double>(g.wheel_radius_m);
    sg.wheel_base_m = static_cast<double>(g.wheel_base_m);
    sg.lx_m = static_cast<double>(g.lx_m);
    sg.ly_m = static_cast<double>(g.ly_m);
    for (const auto& c : cases) {
      const dockcore::WheelSpeeds w = dockcore::twist_to_wheels(g, tw(c[0], c[1], c[2]));
      const WheelRadps s = body_twist_to_wheel_radps(sg, BodyTwist{c[0], c[1], c[2]});
      for (std::size_t i = 0; i < kMaxWheels; ++i) REAL_EQUAL(s[i], static_cast<double>(w.radps[i]), tol);
      const BodyTwist sb = wheel_radps_to_body_twist(sg, s);
      const dockcore::Twist2 b = dockcore::wheels_to_twist(g, w);
      REAL_EQUAL(sb.vx_mps, b.vx_mps, tol);
      REAL_EQUAL(sb.vy_mps, b.vy_mps, tol);
      REAL_EQUAL(sb.wz_radps, b.wz_radps, tol);
    }
  }
}

TEST(ChassisKinematics, DiffStraightLineFromRotatedStart) {
  Chassis c(ideal(DriveKind::kDifferential), 1);
  c.set_true_pose(Pose2{1.0, 2.0, 0.3});
  c.command_wheels(diff_cmd(10.0, 10.0));  // 0.5 m/s
  c.run_for(2.0);
  // With no lag the wheels reach speed within the first step (trapezoid: half a step of travel lost).
  const double d = 0.5 * (2.0 - kDt / 2);
  REAL_EQUAL(1.0 + d * std::cos(0.3), px(c.state()), 1e-9);
  REAL_EQUAL(2.0 + d * std::sin(0.3), py(c.state()), 1e-9);
  REAL_EQUAL(0.3, pyaw(c.state()), 1e-12);
  REAL_EQUAL(2.0, c.state().time_s, 1e-9);
}

TEST(ChassisKinematics, DiffPureRotation) {
  Chassis c(ideal(DriveKind::kDifferential), 1);
  c.command_wheels(diff_cmd(-3.0, 3.0));  // surface ±0.15 m/s over 0.3 m → 1 rad/s
  c.run_for(1.0);
  REAL_EQUAL(1.0 - kDt / 2, pyaw(c.state()), 1e-9);
  REAL_EQUAL(0.0, px(c.state()), 1e-12);
  REAL_EQUAL(0.0, py(c.state()), 1e-12);
}

TEST(ChassisKinematics, DiffArcIsExactCircle) {
  Chassis c(ideal(DriveKind::kDifferential), 1);
  c.command_wheels(diff_cmd(7.0, 13.0));  // v 0.5, w 1 → radius 0.5
  c.step();                               // spin-up step
  const double x0 = px(c.state()), y0 = py(c.state()), th0 = pyaw(c.state());
  c.run_for(2.0);  // 400 steps of a constant twist
  const double th1 = th0 + 2.0;
  // Circle of radius v/w = 0.5 about the centre to the robot's left.
  const double cx = x0 - 0.5 * std::sin(th0), cy = y0 + 0.5 * std::cos(th0);
  REAL_EQUAL(cx + 0.5 * std::sin(th1), px(c.state()), 1e-9);
  REAL_EQUAL(cy - 0.5 * std::cos(th1), py(c.state()), 1e-9);
  REAL_EQUAL(th1, pyaw(c.state()), 1e-9);
}

TEST(ChassisKinematics, MecanumSidewaysAndRotation) {
  Chassis c(ideal(DriveKind::kMecanum), 1);
  // vy = +0.3 m/s (left): FL -, FR +, RL +, RR - at 0.3/0.05 = 6 rad/s.
  c.command_wheels(all4(-6.0, 6.0, 6.0, -6.0));
  c.run_for(1.0);
  REAL_EQUAL(0.0, px(c.state()), 1e-12);
  REAL_EQUAL(0.3 * (1.0 - kDt / 2), py(c.state()), 1e-9);
  REAL_EQUAL(0.0, pyaw(c.state()), 1e-12);

  Chassis r(ideal(DriveKind::kMecanum), 1);
  // w = 1 rad/s: surface ±(lx+ly) = ±0.35 m/s → 7 rad/s; FL and RL backwards.
  r.command_wheels(all4(-7.0, 7.0, -7.0, 7.0));
  r.run_for(1.0);
  REAL_EQUAL(1.0 - kDt / 2, pyaw(r.state()), 1e-9);
  REAL_EQUAL(0.0, px(r.state()), 1e-12);
  REAL_EQUAL(0.0, py(r.state()), 1e-12);

  Chassis f(ideal(DriveKind::kMecanum), 1);
  f.command_wheels(all4(4.0, 4.0, 4.0, 4.0));  // 0.2 m/s forward
  f.run_for(1.5);
  REAL_EQUAL(0.2 * (1.5 - kDt / 2), px(f.state()), 1e-9);
  REAL_EQUAL(0.0, py(f.state()), 1e-12);
}

TEST_GROUP(ChassisDynamics){};

TEST(ChassisDynamics, DeadbandStopsSmallCommands) {
  ChassisParams p = ideal(DriveKind::kDifferential);
  p.motor.deadband_radps = 0.3;
  Chassis c(p, 1);
  c.command_wheels(diff_cmd(0.29, -0.29));
  c.run_for(1.0);
  REAL_EQUAL(0.0, px(c.state()), 0.0);
  REAL_EQUAL(0.0, pyaw(c.state()), 0.0);
  LONGS_EQUAL(0, c.state().encoder_counts[0]);
  REAL_EQUAL(0.0, c.state().wheel_target_radps[0], 0.0);
  c.command_wheels(diff_cmd(0.31, 0.31));
  c.run_for(1.0);
  REAL_EQUAL(0.31 * kR * (1.0 - kDt / 2), px(c.state()), 1e-9);
}

TEST(ChassisDynamics, LatencyDelaysResponseByExactSteps) {
  ChassisParams p = ideal(DriveKind::kDifferential);
  p.motor.time_constant_s = 0.03;  // lag on, so the whole response curve must shift, not just its start
  ChassisParams pl = p;
  pl.motor.latency_steps = 7;
  Chassis ref(p, 1), late(pl, 1);
  ref.command_wheels(diff_cmd(8.0, 8.0));
  late.command_wheels(diff_cmd(8.0, 8.0));
  double ref_speed[60];
  for (int k = 0; k < 60; ++k) {
    ref.step();
    ref_speed[k] = ref.state().wheel_true_radps[0];
  }
  for (int k = 0; k < 7; ++k) {
    late.step();
    REAL_EQUAL(0.0, late.state().wheel_true_radps[0], 0.0);
  }
  for (int k = 0; k < 53; ++k) {
    late.step();
    REAL_EQUAL(ref_speed[k], late.state().wheel_true_radps[0], 0.0);
  }
  CHECK(ref_speed[0] > 0.5);
}

TEST(ChassisDynamics, FirstOrderLagReaches63PercentAtTau) {
  ChassisParams p = ideal(DriveKind::kDifferential);
  p.motor.time_constant_s = 0.05;  // 10 steps
  Chassis c(p, 1);
  c.command_wheels(diff_cmd(10.0, 10.0));
  c.step();
  REAL_EQUAL(10.0 * (1.0 - std::exp(-0.1)), c.state().wheel_true_radps[0], 1e-9);
  for (int k = 1; k < 10; ++k) c.step();
  REAL_EQUAL(10.0 * (1.0 - std::exp(-1.0)), c.state().wheel_true_radps[0], 1e-9);  // 6.321
  REAL_EQUAL(6.321, c.state().wheel_true_radps[1], 1e-3);
}

TEST(ChassisDynamics, AccelerationLimitRespected) {
  ChassisParams p = ideal(DriveKind::kDifferential);
  p.motor.max_accel_radps2 = 20.0;
  Chassis c(p, 1);
  c.command_wheels(diff_cmd(10.0, -10.0));
  double prev = 0;
  for (int k = 1; k <= 100; ++k) {
    c.step();
    const double w = c.state().wheel_true_radps[0];
    CHECK(w - prev <= 20.0 * kDt + 1e-12);
    CHECK(w <= 10.0 + 1e-12);
    prev = w;
    if (k == 50) REAL_EQUAL(5.0, w, 1e-9);  // 20 rad/s² × 0.25 s
  }
  REAL_EQUAL(10.0, c.state().wheel_true_radps[0], 1e-9);
  REAL_EQUAL(-10.0, c.state().wheel_true_radps[1], 1e-9);
}

TEST(ChassisDynamics, CommandTimeoutStopsMotors) {
  ChassisParams p = ideal(DriveKind::kDifferential);
  p.motor.command_timeout_s = 0.5;
  Chassis c(p, 1);
  c.command_wheels(diff_cmd(5.0, 5.0));
  c.run_for(0.5);
  REAL_EQUAL(5.0, c.state().wheel_true_radps[0], 1e-12);
  c.step();
  REAL_EQUAL(0.0, c.state().wheel_true_radps[0], 1e-12);
}

TEST_GROUP(ChassisSensing){};

TEST(ChassisSensing, EncoderCountsMatchDistance) {
  ChassisParams p = ideal(DriveKind::kDifferential);
  p.noise.encoder_cpr = 4096;
  Chassis c(p, 1);
  c.command_wheels(diff_cmd(12.0, 12.0));
  c.run_for(1.7);
  const double dist = px(c.state());
  const double expect = dist / (2 * kPi * kR) * 4096;  // ≈ 11079 counts
  CHECK(expect > 10000);
  REAL_EQUAL(expect, c.state().encoder_counts[0], 1.0);
  REAL_EQUAL(expect, c.state().encoder_counts[1], 1.0);
}

TEST(ChassisSensing, EncodersWrapLikeInt32AndOdometryFollows) {
  ChassisParams p = ideal(DriveKind::kDifferential);
  p.noise.encoder_cpr = 4096;
  p.noise.encoder_initial_count = 2147483647 - 1000;
  Chassis c(p, 1);
  c.command_wheels(diff_cmd(12.0, 12.0));
  c.run_for(1.0);  // ≈ 7800 counts: passes INT32_MAX
  const double counted = (1.0 - kDt / 2) * 12.0 / (2 * kPi) * 4096;
  const std::int64_t expect = static_cast<std::int64_t>(2147483647 - 1000) + static_cast<std::int64_t>(counted) -
                              (std::int64_t{1} << 32);
  CHECK(c.state().encoder_counts[0] < 0);
  REAL_EQUAL(static_cast<double>(expect), c.state().encoder_counts[0], 1.0);
  REAL_EQUAL(px(c.state()), static_cast<double>(c.state().odom_pose.x_m), 2 * 2 * kPi * kR / 4096);
}

TEST(ChassisSensing, MeasuredSpeedFromEncoders) {
  ChassisParams p = ideal(DriveKind::kDifferential);
  p.noise.encoder_cpr = 4096;
  p.noise.speed_window_steps = 8;
  Chassis c(p, 1);
  c.command_wheels(diff_cmd(6.0, -6.0));
  c.run_for(0.5);
  // One count over an 8-step window is 2π/4096/0.04 = 0.038 rad/s of resolution.
  REAL_EQUAL(6.0, c.state().wheel_measured_radps[0], 0.04);
  REAL_EQUAL(-6.0, c.state().wheel_measured_radps[1], 0.04);
}

TEST(ChassisSensing, OdometryRadiusErrorScalesDistance) {
  ChassisParams p = ideal(DriveKind::kDifferential);
  p.noise.odom_radius_error = 0.02;
  Chassis c(p, 1);
  c.command_wheels(diff_cmd(10.0, 10.0));
  c.run_for(2.0);
  const double truth = px(c.state());
  REAL_EQUAL(1.02 * truth, static_cast<double>(c.state().odom_pose.x_m), 1e-5);
  REAL_EQUAL(0.02 * truth, static_cast<double>(c.state().odom_pose.x_m) - truth, 1e-5);  // ≈ 2 cm
}

TEST(ChassisSensing, OdometryBaseErrorScalesRotation) {
  ChassisParams p = ideal(DriveKind::kDifferential);
  p.noise.odom_base_error = 0.05;
  Chassis c(p, 1);
  c.command_wheels(diff_cmd(-3.0, 3.0));
  c.run_for(1.0);
  REAL_EQUAL(pyaw(c.state()) / 1.05, static_cast<double>(c.state().odom_pose.yaw_rad), 1e-6);
}

TEST(ChassisSensing, OdometryRadiusDifferenceCurvesStraightLine) {
  ChassisParams p = ideal(DriveKind::kDifferential);
  p.noise.odom_radius_diff = 0.01;  // left wheel believed 0.5 % larger, right 0.5 % smaller
  Chassis c(p, 1);
  c.command_wheels(diff_cmd(10.0, 10.0));
  c.run_for(2.0);
  const double d = px(c.state());
  REAL_EQUAL(0.0, pyaw(c.state()), 1e-12);
  // Believed heading change = (s_R - s_L)/b = -0.01·d/b.
  REAL_EQUAL(-0.01 * d / kB, static_cast<double>(c.state().odom_pose.yaw_rad), 1e-6);
  CHECK(static_cast<double>(c.state().odom_pose.y_m) < -0.01);  // curves right by ≈ d²·0.01/(2b) = 1.7 cm
  REAL_EQUAL(-0.01 * d * d / (2 * kB), static_cast<double>(c.state().odom_pose.y_m), 1e-4);
}

TEST(ChassisSensing, MecanumOdometryBaseError) {
  ChassisParams p = ideal(DriveKind::kMecanum);
  p.noise.odom_base_error = -0.04;
  Chassis c(p, 1);
  c.command_wheels(all4(-7.0, 7.0, -7.0, 7.0));
  c.run_for(1.0);
  REAL_EQUAL(pyaw(c.state()) / 0.96, static_cast<double>(c.state().odom_pose.yaw_rad), 1e-6);
}

TEST(ChassisSensing, WhiteSlipSpreadMatchesSigma) {
  // White slip σ per wheel per step: forward error after N steps has σ_x = step_travel·σ·sqrt(N/2).
  ChassisParams p = ideal(DriveKind::kDifferential);
  p.noise.slip_sigma = 0.05;
  p.noise.slip_correlation_s = 0;
  const int runs = 200, steps = 400;
  double sum = 0, sum2 = 0;
  for (int s = 0; s < runs; ++s) {
    Chassis c(p, 1000 + static_cast<std::uint64_t>(s));
    c.command_wheels(diff_cmd(10.0, 10.0));
    c.step();  // spin-up
    const double x0 = px(c.state()), o0 = static_cast<double>(c.state().odom_pose.x_m);
    for (int k = 0; k < steps; ++k) c.step();
    const double err = (px(c.state()) - x0) - (static_cast<double>(c.state().odom_pose.x_m) - o0);
    sum += err;
    sum2 += err * err;
  }
  const double mean = sum / runs;
  const double sd = std::sqrt(sum2 / runs - mean * mean);
  const double expect = 0.5 * kDt * 0.05 * std::sqrt(steps / 2.0);  // 1.77 mm
  REAL_EQUAL(expect, sd, 0.2 * expect);
  REAL_EQUAL(0.0, mean, 4 * expect / std::sqrt(static_cast<double>(runs)));
}

TEST_GROUP(ChassisDock){};

TEST(ChassisDock, CannotPassThroughAndStalls) {
  ChassisParams p = ideal(DriveKind::kDifferential);
  Chassis c(p, 1);
  const Pose2 dock{2.0, 0.0, kPi};  // face looks back at the robot at the origin
  c.set_dock(DockPlacement{dock, 0.15, false});
  c.command_wheels(diff_cmd(4.0, 4.0));  // 0.2 m/s
  c.run_for(12.0);                        // would travel 2.4 m
  // Pad (0.225 ahead) stops at the hard stop 8 mm past the contact plane: body x = 2.008 - 0.225.
  REAL_EQUAL(2.0 + 0.008 - 0.225, px(c.state()), 1e-9);
  CHECK_TRUE(c.state().stalled);
  CHECK_TRUE(c.state().at_hard_stop);
  REAL_EQUAL(4.0, c.state().wheel_target_radps[0], 0.0);
  REAL_EQUAL(0.0, c.state().wheel_measured_radps[0], 0.05);
  REAL_EQUAL(0.008, c.state().press_m, 1e-9);
  CHECK_TRUE(c.state().contact);
  // Backing off releases the stall.
  c.command_wheels(diff_cmd(-4.0, -4.0));
  c.run_for(0.5);
  CHECK_FALSE(c.state().stalled);
  CHECK(px(c.state()) < 1.7);
}

// Something the lidar does not see holds the pads stop_short_m before the contact plane: the same hard stop, moved
// forward; the contacts never close and the wheels stall, and odometry stops with the robot.
TEST(ChassisDock, HeldShortOfTheContactsStallsWithoutContact) {
  ChassisParams p = ideal(DriveKind::kDifferential);
  Chassis c(p, 1);
  const Pose2 dock{2.0, 0.0, kPi};
  DockPlacement d{dock, 0.15, false};
  d.stop_short_m = 0.02;
  c.set_dock(d);
  c.command_wheels(diff_cmd(4.0, 4.0));
  c.run_for(12.0);
  REAL_EQUAL(2.0 - 0.02 - 0.225, px(c.state()), 1e-9);
  REAL_EQUAL(-0.02, c.state().press_m, 1e-9);
  CHECK_TRUE(c.state().stalled);
  CHECK_TRUE(c.state().at_hard_stop);
  CHECK_FALSE(c.state().contact);
  REAL_EQUAL(0.0, c.state().wheel_measured_radps[0], 0.05);
  const double odom_x = c.state().odom_pose.x_m;
  c.run_for(2.0);
  REAL_EQUAL(odom_x, c.state().odom_pose.x_m, 1e-6);
  CHECK_FALSE(c.state().contact);
}

TEST(ChassisDock, RealisticMotorsAndYawedApproachStillStop) {
  ChassisParams p;  // defaults: latency, lag, accel limit, deadband, slip on
  Chassis c(p, 7);
  const Pose2 dock{1.0, 0.3, -kPi / 2};  // face looks towards -y
  c.set_dock(DockPlacement{dock, 0.20, false});
  c.set_true_pose(Pose2{1.0, 0.3 - 1.0, kPi / 2 + 0.05});  // 1 m in front, heading at the dock, 2.9° off
  c.command_twist(BodyTwist{0.25, 0, 0});
  double min_press_gap = 1e9;
  for (int k = 0; k < 2000; ++k) {
    c.step();
    min_press_gap = std::min(min_press_gap, 0.008 - c.state().press_m);
  }
  CHECK(min_press_gap >= -1e-9);  // never beyond the hard stop
  CHECK_TRUE(c.state().stalled);
  CHECK_FALSE(c.state().contact);  // 2.9° off: outside the yaw tolerance
}

TEST(ChassisDock, RearPadsBackwardsDocking) {
  ChassisParams p = ideal(DriveKind::kDifferential);
  p.footprint.pad_side = PadSide::kRear;
  Chassis c(p, 1);
  c.set_dock(DockPlacement{Pose2{2.0, 0.0, kPi}, 0.15, false});
  c.set_true_pose(Pose2{0.0, 0.0, kPi});  // rear (pads) towards the dock
  c.command_wheels(diff_cmd(-4.0, -4.0));
  c.run_for(12.0);
  REAL_EQUAL(2.0 + 0.008 - 0.225, px(c.state()), 1e-9);
  REAL_EQUAL(0.0, c.state().pad_yaw_error_rad, 1e-9);
  CHECK_TRUE(c.state().contact);
  CHECK_TRUE(c.state().stalled);
}

TEST(ChassisDock, OutsideFaceWidthPassesBy) {
  Chassis c(ideal(DriveKind::kDifferential), 1);
  c.set_dock(DockPlacement{Pose2{2.0, 0.0, kPi}, 0.15, false});
  c.set_true_pose(Pose2{0.0, 0.16, 0.0});  // pads 16 mm beyond the face's edge
  c.command_wheels(diff_cmd(4.0, 4.0));
  c.run_for(12.0);
  CHECK(px(c.state()) > 2.2);
  CHECK_FALSE(c.state().stalled);
}

TEST(ChassisDock, ContactToleranceEdges) {
  const Pose2 dock{0.5, -0.2, 0.7};
  struct Case {
    double press, lateral, yaw;
    bool contact;
  };
  const double deg = kPi / 180;
  const Case cases[] = {
      {0.005, 0.0099, 0.0, true},       {0.005, 0.0101, 0.0, false},
      {0.005, -0.0099, 0.0, true},      {0.005, -0.0101, 0.0, false},
      {0.005, 0.0, 1.99 * deg, true},   {0.005, 0.0, 2.01 * deg, false},
      {0.005, 0.0, -1.99 * deg, true},  {0.005, 0.0, -2.01 * deg, false},
      {0.0031, 0.0, 0.0, true},         {0.0029, 0.0, 0.0, false},
      {0.0079, 0.0, 0.0, true},         {-0.01, 0.0, 0.0, false},
  };
  for (const Case& k : cases) {
    Chassis c(ideal(DriveKind::kDifferential), 1);
    c.set_dock(DockPlacement{dock, 0.15, false});
    c.set_true_pose(pose_for_pad(dock, k.press, k.lateral, k.yaw));
    c.step();  // no command: stays put
    REAL_EQUAL(k.press, c.state().press_m, 1e-9);
    REAL_EQUAL(k.lateral, c.state().pad_lateral_m, 1e-9);
    REAL_EQUAL(k.yaw, c.state().pad_yaw_error_rad, 1e-9);
    CHECK_EQUAL(k.contact, c.state().contact);
  }
}

TEST(ChassisDock, ChargingAfterDelayNotWithDeadDockOrInhibited) {
  ChassisParams p = ideal(DriveKind::kDifferential);
  p.contact.charge_delay_s = 0.5;
  const Pose2 dock{0.0, 0.0, 0.0};
  Chassis c(p, 1);
  c.set_dock(DockPlacement{dock, 0.15, false});
  c.set_true_pose(pose_for_pad(dock, 0.005, 0.0, 0.0));
  c.step();
  CHECK_TRUE(c.state().contact);  // closed at t = 5 ms
  for (int k = 0; k < 99; ++k) {
    c.step();
    CHECK_FALSE(c.state().charging);
    REAL_EQUAL(0.0, c.state().charge_current_a, 0.0);
  }
  c.step();  // t = 0.505 s: 0.5 s after contact
  CHECK_TRUE(c.state().charging);
  REAL_EQUAL(5.0, c.state().charge_current_a, 1e-12);
  REAL_EQUAL(5.0 - 0.8, c.state().battery_current_a, 1e-12);
  c.set_charging_inhibited(true);
  c.step();
  CHECK_FALSE(c.state().charging);
  CHECK(c.state().battery_current_a < 0);
  c.set_charging_inhibited(false);
  c.step();
  CHECK_FALSE(c.state().charging);  // the delay starts again
  c.run_for(0.5);
  CHECK_TRUE(c.state().charging);

  Chassis dead(p, 1);
  dead.set_dock(DockPlacement{dock, 0.15, true});
  dead.set_true_pose(pose_for_pad(dock, 0.005, 0.0, 0.0));
  dead.run_for(3.0);
  CHECK_TRUE(dead.state().contact);
  CHECK_FALSE(dead.state().charging);
  REAL_EQUAL(-0.8, dead.state().battery_current_a, 1e-12);
}

TEST(ChassisDock, MecanumStallsAgainstDock) {
  Chassis c(ideal(DriveKind::kMecanum), 1);
  c.set_dock(DockPlacement{Pose2{1.0, 0.0, kPi}, 0.15, false});
  c.command_wheels(all4(4.0, 4.0, 4.0, 4.0));
  c.run_for(8.0);
  REAL_EQUAL(1.008 - 0.225, px(c.state()), 1e-9);
  CHECK_TRUE(c.state().stalled);
  CHECK_TRUE(c.state().contact);
}

TEST_GROUP(ChassisBattery){};

TEST(ChassisBattery, OcvTableInterpolates) {
  BatteryParams bp;
  REAL_EQUAL(21.0, battery_ocv_v(bp, 0.0), 1e-12);
  REAL_EQUAL(29.4, battery_ocv_v(bp, 1.0), 1e-12);
  REAL_EQUAL(0.5 * (25.90 + 26.25), battery_ocv_v(bp, 0.45), 1e-12);
  REAL_EQUAL(29.4, battery_ocv_v(bp, 1.5), 1e-12);
}

TEST(ChassisBattery, SocRisesWhenChargingFallsWhenDriving) {
  ChassisParams p = ideal(DriveKind::kDifferential);
  p.contact.charge_delay_s = 0.0;
  const Pose2 dock{0.0, 0.0, 0.0};
  Chassis c(p, 1);
  c.set_dock(DockPlacement{dock, 0.15, false});
  c.set_true_pose(pose_for_pad(dock, 0.005, 0.0, 0.0));
  const double soc0 = c.state().battery_soc;
  REAL_EQUAL(0.5, soc0, 0.0);
  c.run_for(60.0);
  // Net +4.2 A for 60 s into 20 Ah.
  REAL_EQUAL(soc0 + 4.2 * 60 / 3600 / 20, c.state().battery_soc, 1e-9);
  const BatteryParams& bp = p.battery;
  REAL_EQUAL(battery_ocv_v(bp, c.state().battery_soc) + 4.2 * 0.08, c.state().battery_voltage_v, 1e-9);

  Chassis d(p, 1);
  d.command_wheels(diff_cmd(10.0, 10.0));  // 0.5 m/s: 0.8 + 4·0.5 = 2.8 A
  d.run_for(60.0);
  REAL_EQUAL(0.5 - 2.8 * 60 / 3600 / 20, d.state().battery_soc, 1e-6);
  REAL_EQUAL(-2.8, d.state().battery_current_a, 1e-9);
  CHECK(d.state().battery_voltage_v < battery_ocv_v(bp, d.state().battery_soc));
}

TEST(ChassisBattery, ChargeTapersNearFull) {
  ChassisParams p = ideal(DriveKind::kDifferential);
  p.contact.charge_delay_s = 0.0;
  const Pose2 dock{0.0, 0.0, 0.0};
  Chassis c(p, 1);
  c.set_dock(DockPlacement{dock, 0.15, false});
  c.set_true_pose(pose_for_pad(dock, 0.005, 0.0, 0.0));
  c.set_battery_soc(0.975);  // halfway through the 0.95..1 taper
  c.step();
  REAL_EQUAL(2.5, c.state().charge_current_a, 1e-6);
}

TEST_GROUP(ChassisHooks){};

TEST(ChassisHooks, PoseJumpMovesTruthNotOdometry) {
  Chassis c(ideal(DriveKind::kDifferential), 1);
  c.apply_pose_jump(0.1, -0.05, 0.2);
  c.step();
  REAL_EQUAL(0.1, px(c.state()), 1e-12);
  REAL_EQUAL(-0.05, py(c.state()), 1e-12);
  REAL_EQUAL(0.2, pyaw(c.state()), 1e-12);
  REAL_EQUAL(0.0, static_cast<double>(c.state().odom_pose.x_m), 0.0);
}

TEST(ChassisHooks, FreezeHoldsReportsAndIgnoresCommands) {
  Chassis c(ideal(DriveKind::kDifferential), 1);
  c.command_wheels(diff_cmd(10.0, 10.0));
  c.run_for(0.5);
  const ChassisState before = c.state();
  c.set_frozen(true, FreezeMotion::kHoldLastCommand);
  CHECK_FALSE(c.state().responding);
  c.command_wheels(diff_cmd(0.0, 0.0));  // lost
  c.run_for(0.5);
  CHECK_FALSE(c.state().responding);
  REAL_EQUAL(0.5 * (1.0 - kDt / 2), px(c.state()), 1e-9);  // kept driving
  LONGS_EQUAL(before.encoder_counts[0], c.state().encoder_counts[0]);
  REAL_EQUAL(static_cast<double>(before.odom_pose.x_m), static_cast<double>(c.state().odom_pose.x_m), 0.0);
  c.set_frozen(false);
  c.step();
  CHECK_TRUE(c.state().responding);
  // Odometry catches up in one go from the true counters.
  REAL_EQUAL(px(c.state()), static_cast<double>(c.state().odom_pose.x_m), 1e-5);

  Chassis s(ideal(DriveKind::kDifferential), 1);
  s.command_wheels(diff_cmd(10.0, 10.0));
  s.run_for(0.5);
  s.set_frozen(true, FreezeMotion::kStop);
  s.run_for(0.5);
  REAL_EQUAL(0.5 * (0.5 - kDt / 2) + 0.5 * kDt / 2, px(s.state()), 1e-9);  // braked within one step
}

TEST_GROUP(ChassisDeterminism){};

namespace {
ChassisParams noisy() {
  ChassisParams p;  // defaults: slip 1 %, lag, latency, accel limit, deadband
  p.noise.slip_sigma = 0.03;
  p.noise.odom_radius_error = 0.01;
  p.noise.odom_radius_diff = 0.004;
  return p;
}
void drive(Chassis& c, int steps) {
  for (int k = 0; k < steps; ++k) {
    if (k % 20 == 0) c.command_twist(BodyTwist{0.3 * std::sin(k * 0.01), 0.0, 0.8 * std::cos(k * 0.013)});
    c.step();
  }
}
bool same_bits(const ChassisState& a, const ChassisState& b) {
  auto eq = [](double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; };
  bool ok = eq(a.true_pose.x_m, b.true_pose.x_m) && eq(a.true_pose.y_m, b.true_pose.y_m) &&
            eq(a.true_pose.yaw_rad, b.true_pose.yaw_rad) && eq(a.odom_pose.x_m, b.odom_pose.x_m) &&
            eq(a.odom_pose.y_m, b.odom_pose.y_m) && eq(a.odom_pose.yaw_rad, b.odom_pose.yaw_rad) &&
            eq(a.battery_soc, b.battery_soc) && eq(a.time_s, b.time_s);
  for (std::size_t i = 0; i < kMaxWheels; ++i) {
    ok = ok && a.encoder_counts[i] == b.encoder_counts[i] && eq(a.wheel_true_radps[i], b.wheel_true_radps[i]) &&
         eq(a.wheel_measured_radps[i], b.wheel_measured_radps[i]);
  }
  return ok;
}
}  // namespace

TEST(ChassisDeterminism, SameSeedSameBits) {
  Chassis a(noisy(), 42), b(noisy(), 42), other(noisy(), 43);
  drive(a, 1000);
  drive(b, 1000);
  drive(other, 1000);
  CHECK_TRUE(same_bits(a.state(), b.state()));
  CHECK_FALSE(same_bits(a.state(), other.state()));
  // Slip made truth and odometry part ways, so the noise really was on.
  CHECK(std::fabs(static_cast<double>(a.state().true_pose.x_m - a.state().odom_pose.x_m)) > 1e-4);
}

TEST(ChassisDeterminism, StepDoesNotAllocate) {
  if (!CHASSIS_ALLOC_TRAP) return;
  ChassisParams p = noisy();
  p.geometry.kind = DriveKind::kMecanum;
  Chassis c(p, 5);
  c.set_dock(DockPlacement{Pose2{0.6, 0.0, kPi}, 0.15, false});
  g_allocs = 0;
  g_count_alloc = true;
  void* volatile probe = std::malloc(16);  // the counter must work, or a zero below means nothing
  const std::size_t after_probe = g_allocs;
  std::free(probe);
  for (int k = 0; k < 2000; ++k) {
    c.command_twist(BodyTwist{0.2, 0.0, 0.0});
    c.step();
  }
  g_count_alloc = false;
  LONGS_EQUAL(1, after_probe);
  LONGS_EQUAL(1, g_allocs);
  CHECK_TRUE(c.state().at_hard_stop);  // the run exercised the contact path too
}
