// The four docking controllers step by step, without a plant: names and phase names, seed 004's defaults, the
// graceful law's curvature, smooth's LINEUP axis tracker, a lost target, contact. The dockings in closed loop (an
// ideal plant and the simulated chassis) are test_controllers_closed_loop.
#include <cmath>
#include <cstdint>

#include "dockcore/control/controllers.hpp"

#include "docking_starts.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using dockcore_test::kCtlDt;
using dockcore_test::kPadReach;
using dockcore_test::kPiD;
using dockcore_test::Start;
using dockcore_test::start_pose;
using dockcore_test::wrapd;

TEST_GROUP(Controllers){};

TEST(Controllers, NamesAndPhaseNames) {
  Seed000Controller a;
  Seed004Controller b;
  Seed003Controller c;
  SmoothController d;
  STRCMP_EQUAL("seed000", a.name());
  STRCMP_EQUAL("seed004", b.name());
  STRCMP_EQUAL("seed003", c.name());
  STRCMP_EQUAL("smooth", d.name());
  const char* nine[] = {"READY", "POSITION", "ROTATE", "LATERAL", "LATERAL_ORI_CONFIRM", "LATERAL_ROTATE",
                        "FRONT_BACK_ORI_CONFIRM", "FRONT_BACK", "FINISH"};
  for (std::uint8_t i = 0; i < 9; ++i) STRCMP_EQUAL(nine[i], b.phase_name(i));
  STRCMP_EQUAL("UNKNOWN", b.phase_name(200));
  STRCMP_EQUAL("SEED_SUCCESS", c.phase_name(static_cast<std::uint8_t>(Seed003Phase::kSeedSuccess)));
  DOUBLES_EQUAL(0.01, b.params().angle_tolerance_rad, 1e-7);
  DOUBLES_EQUAL(0.53, b.params().relative_distance_m, 1e-7);
  DOUBLES_EQUAL(-0.01, b.params().robot_distance_tolerance_m, 1e-7);
  DOUBLES_EQUAL(0.6, b.params().angle_kp, 1e-7);
  DOUBLES_EQUAL(0.4, b.params().distance_kp, 1e-7);
}

TEST(Controllers, EveryPhaseHasItsName) {
  const Seed000Controller a;
  const Seed004Controller b;
  const Seed003Controller c;
  const SmoothController d;
  const char* seed000[] = {"ROTATE", "DRIVE", "DOCKED"};
  for (std::uint8_t i = 0; i < 3; ++i) STRCMP_EQUAL(seed000[i], a.phase_name(i));
  STRCMP_EQUAL("DOCKED", a.phase_name(static_cast<std::uint8_t>(Seed000Phase::kDocked)));
  STRCMP_EQUAL("UNKNOWN", a.phase_name(3));
  STRCMP_EQUAL("FINAL_APPROACH", b.phase_name(static_cast<std::uint8_t>(Seed004Phase::kFinalApproach)));
  STRCMP_EQUAL("DOCKED", b.phase_name(static_cast<std::uint8_t>(Seed004Phase::kDocked)));
  STRCMP_EQUAL("UNKNOWN", b.phase_name(11));
  const char* seed003[] = {"STAGE1", "STAGE2", "SEED_SUCCESS", "FINAL_APPROACH", "DOCKED"};
  for (std::uint8_t i = 0; i < 5; ++i) STRCMP_EQUAL(seed003[i], c.phase_name(i));
  STRCMP_EQUAL("DOCKED", c.phase_name(static_cast<std::uint8_t>(Seed003Phase::kDocked)));
  STRCMP_EQUAL("UNKNOWN", c.phase_name(5));
  const char* smooth[] = {"APPROACH", "SLOWDOWN", "CREEP", "DOCKED", "LINEUP"};
  for (std::uint8_t i = 0; i < 5; ++i) STRCMP_EQUAL(smooth[i], d.phase_name(i));
  STRCMP_EQUAL("DOCKED", d.phase_name(static_cast<std::uint8_t>(SmoothPhase::kDocked)));
  STRCMP_EQUAL("UNKNOWN", d.phase_name(5));
}

TEST(Controllers, SetPicksEachControllerByNameWithItsParameters) {
  Seed000Params p000;
  p000.forward_speed_mps = static_cast<Real>(0.15);
  Seed004Params p004;
  p004.angle_kp = static_cast<Real>(0.7);
  Seed003Params p003;
  p003.holonomic = true;
  SmoothParams ps;
  ps.v_max_mps = static_cast<Real>(0.2);
  ControllerSet set(p000, p004, p003, ps);
  POINTERS_EQUAL(&set.seed000, set.by_name("seed000"));
  POINTERS_EQUAL(&set.seed004, set.by_name("seed004"));
  POINTERS_EQUAL(&set.seed003, set.by_name("seed003"));
  POINTERS_EQUAL(&set.smooth, set.by_name("smooth"));
  for (const char* other : {"", "Smooth", "seed00", "smooth ", "seed005"}) POINTERS_EQUAL(nullptr, set.by_name(other));
  DOUBLES_EQUAL(0.15, set.seed000.params().forward_speed_mps, 1e-7);
  DOUBLES_EQUAL(0.7, set.seed004.params().angle_kp, 1e-7);
  CHECK(set.seed003.params().holonomic);
  DOUBLES_EQUAL(0.2, set.smooth.params().v_max_mps, 1e-7);
}

TEST(Controllers, GracefulCurvatureSigns) {
  // Target dead ahead with the same heading: straight.
  DOUBLES_EQUAL(0.0, SmoothController::graceful_curvature(1, 0, 0, 3, 2), 1e-12);
  // Target 0.3 rad to the left, aligned with the line of sight: δ = −0.3 → κ = (2·0.3 + 4·sin 0.3)/1 > 0 (left).
  DOUBLES_EQUAL(2 * 0.3 + 4 * std::sin(0.3), SmoothController::graceful_curvature(1, 0, static_cast<Real>(-0.3), 3, 2),
                1e-6);
}

// smooth's LINEUP axis tracker near the dock: the commanded curvature w/v is the cubic's from the pose to the axis
// (y = 0, heading π) after the remaining travel, with the horizon floors of SmoothParams (0.10 m heading, 0.30 m
// lateral, 0.03 m margin); far off the axis the graceful law keeps control.
TEST(Controllers, SmoothLineupCurvature) {
  ControlInput in;
  in.dt_s = static_cast<Real>(kCtlDt);
  in.dock_valid = true;
  Pose2 robot;  // robot centre in the dock frame
  SmoothController d;
  // 10 mm left of the axis (dock frame y > 0 = the robot's right when facing the dock), aligned, pads 0.20 m out:
  // left = 0.17 m, lateral horizon floored at 0.30 → κ = 6·0.01/0.30² = 0.667 1/m, a left turn (w > 0).
  robot.x_m = static_cast<Real>(kPadReach + 0.20);
  robot.y_m = static_cast<Real>(0.01);
  robot.yaw_rad = static_cast<Real>(kPiD);
  in.dock_in_robot = robot.inverse();
  ControlOutput o = d.step(in);
  CHECK_EQUAL(static_cast<int>(SmoothPhase::kLineup), static_cast<int>(o.phase));
  CHECK(o.cmd.vx_mps > 0);
  DOUBLES_EQUAL(6 * 0.01 / (0.30 * 0.30), o.cmd.wz_radps / o.cmd.vx_mps, 1e-4);
  // On the axis, turned 0.02 rad left, pads 0.05 m out: heading horizon floored at 0.10 m →
  // y'' = −4·tan 0.02/0.10 along the axis, curvature y''/(1 + tan² 0.02)^1.5 = −0.7996 1/m (turn right, back onto the
  // axis heading).
  d.reset();
  robot.x_m = static_cast<Real>(kPadReach + 0.05);
  robot.y_m = 0;
  robot.yaw_rad = static_cast<Real>(wrapd(kPiD + 0.02));
  in.dock_in_robot = robot.inverse();
  o = d.step(in);
  CHECK_EQUAL(static_cast<int>(SmoothPhase::kLineup), static_cast<int>(o.phase));
  const double t2 = std::tan(0.02);
  DOUBLES_EQUAL(-4 * t2 / 0.10 / std::pow(1 + t2 * t2, 1.5), o.cmd.wz_radps / o.cmd.vx_mps, 1e-4);
  // 10 cm off the axis at the same distance: not lined up, so the graceful law (not LINEUP) steers.
  d.reset();
  robot.x_m = static_cast<Real>(kPadReach + 0.20);
  robot.y_m = static_cast<Real>(0.10);
  robot.yaw_rad = static_cast<Real>(kPiD);
  in.dock_in_robot = robot.inverse();
  o = d.step(in);
  CHECK(o.phase != static_cast<std::uint8_t>(SmoothPhase::kLineup));
  STRCMP_EQUAL("LINEUP", d.phase_name(static_cast<std::uint8_t>(SmoothPhase::kLineup)));
}

TEST(Controllers, LostTargetGivesZeroTwist) {
  Seed000Controller a;
  Seed004Controller b;
  Seed003Controller c;
  SmoothController d;
  DockingController* all[] = {&a, &b, &c, &d};
  ControlInput in;
  in.dt_s = static_cast<Real>(kCtlDt);
  in.dock_valid = false;  // and no camera
  for (DockingController* ctl : all) {
    ctl->reset();
    for (int k = 0; k < 3; ++k) {
      const ControlOutput o = ctl->step(in);
      CHECK(o.status == ControlStatus::kLost);
      DOUBLES_EQUAL(0.0, o.cmd.vx_mps, 0.0);
      DOUBLES_EQUAL(0.0, o.cmd.vy_mps, 0.0);
      DOUBLES_EQUAL(0.0, o.cmd.wz_radps, 0.0);
    }
  }
  // Mid-run loss: smooth moving, then the estimate drops.
  d.reset();
  in.dock_valid = true;
  in.dock_in_robot = start_pose(Start{1.5, 10, 0}, false).inverse();
  CHECK(d.step(in).cmd.vx_mps > 0);
  in.dock_valid = false;
  const ControlOutput o = d.step(in);
  CHECK(o.status == ControlStatus::kLost);
  DOUBLES_EQUAL(0.0, o.cmd.vx_mps, 0.0);
  // seed003: stale camera (older than target_timeout_s) counts as lost.
  c.reset();
  in.dock_valid = true;
  in.now_us = 1000000;
  in.camera.valid = true;
  in.camera.u_px = 300;
  in.camera.stamp_us = 500000;
  const ControlOutput oc = c.step(in);
  CHECK(oc.status == ControlStatus::kLost);
  DOUBLES_EQUAL(0.0, oc.cmd.wz_radps, 0.0);
}

TEST(Controllers, SmoothStallPastTheContactPlaneFailsUntilReset) {
  // Pads 1 cm past the contact plane (stall_press_m 0), no contact: running for the first 1.8 s, failed with a zero
  // twist by 2.2 s (stall_timeout_s 2), and failed even once the pads are back out, until reset().
  SmoothController d;
  ControlInput in;
  in.dt_s = static_cast<Real>(kCtlDt);
  in.dock_valid = true;
  Pose2 robot;
  robot.x_m = static_cast<Real>(kPadReach - 0.01);
  robot.yaw_rad = static_cast<Real>(kPiD);
  in.dock_in_robot = robot.inverse();
  for (int k = 0; k < 90; ++k) CHECK(d.step(in).status == ControlStatus::kRunning);
  ControlOutput o;
  for (int k = 0; k < 20; ++k) o = d.step(in);
  CHECK(o.status == ControlStatus::kFailed);
  DOUBLES_EQUAL(0.0, o.cmd.vx_mps, 0.0);
  DOUBLES_EQUAL(0.0, o.cmd.wz_radps, 0.0);
  robot.x_m = static_cast<Real>(kPadReach + 0.20);
  in.dock_in_robot = robot.inverse();
  CHECK(d.step(in).status == ControlStatus::kFailed);
  d.reset();
  CHECK(d.step(in).status == ControlStatus::kRunning);
}

TEST(Controllers, SmoothSaturatedTurnKeepsTheMinimumTurnSpeed) {
  // Pads 5 cm from the plane, 10 cm off the axis (no LINEUP) and turned 1 rad the wrong way: the curvature is so
  // tight that ω hits w_max_radps and the speed that keeps the curvature falls below min_turn_speed_mps (set above the
  // creep speed here), which is commanded instead.
  SmoothParams p;
  p.min_turn_speed_mps = static_cast<Real>(0.04);
  SmoothController d(p);
  ControlInput in;
  in.dt_s = static_cast<Real>(kCtlDt);
  in.dock_valid = true;
  Pose2 robot;
  robot.x_m = static_cast<Real>(kPadReach + 0.05);
  robot.y_m = static_cast<Real>(0.10);
  robot.yaw_rad = static_cast<Real>(wrapd(kPiD - 1.0));
  in.dock_in_robot = robot.inverse();
  const ControlOutput o = d.step(in);
  CHECK(o.status == ControlStatus::kRunning);
  CHECK(o.phase != static_cast<std::uint8_t>(SmoothPhase::kLineup));
  DOUBLES_EQUAL(p.w_max_radps, std::fabs(o.cmd.wz_radps), 0.0);
  DOUBLES_EQUAL(p.min_turn_speed_mps, o.cmd.vx_mps, 0.0);
}

namespace {
// A running smooth controller's input: the pads `pads_m` from the contact plane, the centre `lateral_m` off the axis
// and turned `turn_rad` from the docked heading.
ControlInput smooth_input_at(double pads_m, double lateral_m, double turn_rad) {
  ControlInput in;
  in.dt_s = static_cast<Real>(kCtlDt);
  in.dock_valid = true;
  Pose2 robot;
  robot.x_m = static_cast<Real>(kPadReach + pads_m);
  robot.y_m = static_cast<Real>(lateral_m);
  robot.yaw_rad = static_cast<Real>(wrapd(kPiD + turn_rad));
  in.dock_in_robot = robot.inverse();
  return in;
}
}  // namespace

TEST(Controllers, SmoothTightCurveTowardsAConfirmedDockKeepsTheMinimumTurnRate) {
  // Pads 0.8 m from the plane, 0.1 m off the axis and turned 0.3 rad: the graceful law's curve is tight (6 1/m),
  // and its speed law alone would crawl round it at the creep speed. Towards a confirmed estimate the speed along
  // the same curve is raised so the turn runs at min_turn_rate_radps; towards one detection, or with the floor
  // off, the law's own speed stands.
  SmoothParams p;
  ControlInput in = smooth_input_at(0.8, 0.1, -0.3);
  SmoothController fast(p);
  const ControlOutput o = fast.step(in);
  CHECK(o.status == ControlStatus::kRunning);
  DOUBLES_EQUAL(p.min_turn_rate_radps, std::fabs(o.cmd.wz_radps), 1e-9);
  CHECK(o.cmd.vx_mps > p.common.creep_speed_mps && o.cmd.vx_mps <= p.v_max_mps);
  in.dock_confirmed = false;
  SmoothController cautious(p);
  const ControlOutput u = cautious.step(in);
  CHECK(std::fabs(u.cmd.wz_radps) < p.min_turn_rate_radps);
  // The same curve: only the speed along it differs.
  DOUBLES_EQUAL(o.cmd.wz_radps / o.cmd.vx_mps, u.cmd.wz_radps / u.cmd.vx_mps, 1e-9);
  in.dock_confirmed = true;
  p.min_turn_rate_radps = 0;
  SmoothController off(p);
  const ControlOutput f = off.step(in);
  DOUBLES_EQUAL(u.cmd.vx_mps, f.cmd.vx_mps, 0.0);
  DOUBLES_EQUAL(u.cmd.wz_radps, f.cmd.wz_radps, 0.0);
}

TEST(Controllers, SmoothTurnRateFloorStaysOutOfTheLineupZone) {
  // Pads 0.3 m from the plane (inside lineup_distance_m + lineup_hysteresis_m), 0.1 m off the axis (the graceful
  // law still steers) and turned 0.3 rad, a curve of 8 1/m: the floor does not apply there, where the heading
  // settles before the contacts judge it.
  SmoothParams p;
  const ControlInput in = smooth_input_at(0.3, 0.1, 0.3);
  SmoothController with(p);
  const ControlOutput a = with.step(in);
  const Real floor_radps = p.min_turn_rate_radps;
  p.min_turn_rate_radps = 0;
  SmoothController without(p);
  const ControlOutput b = without.step(in);
  DOUBLES_EQUAL(b.cmd.vx_mps, a.cmd.vx_mps, 0.0);
  DOUBLES_EQUAL(b.cmd.wz_radps, a.cmd.wz_radps, 0.0);
  CHECK(std::fabs(a.cmd.wz_radps) < floor_radps);  // it would have applied
}

TEST(Controllers, ContactMeansArrivedAndZero) {
  SmoothController d;
  ControlInput in;
  in.dt_s = static_cast<Real>(kCtlDt);
  in.dock_valid = true;
  in.dock_in_robot = start_pose(Start{1.0, 0, 0}, false).inverse();
  in.contact = true;
  ControlOutput o = d.step(in);
  CHECK(o.status == ControlStatus::kArrived);
  DOUBLES_EQUAL(0.0, o.cmd.vx_mps, 0.0);
  in.contact = false;  // contact flicker: stays arrived until reset
  o = d.step(in);
  CHECK(o.status == ControlStatus::kArrived);
  d.reset();
  CHECK(d.step(in).status == ControlStatus::kRunning);
}
