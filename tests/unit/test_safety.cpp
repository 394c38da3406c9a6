// Obstacle check (seed 004 Table 3 footprints) and the pose-deviation test, on hand-built scans.
#include <cmath>
#include <memory>

#include "dockcore/control/safety.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;

namespace {

/// Full-turn scan, 0.5° beams, no returns; add() puts a return at a robot-frame point (identity mount unless given).
struct Scan {
  static constexpr std::size_t kBeams = 720;
  LaserScanN<kBeams> s;
  Pose2 mount{};
  Scan() { s.reset(kBeams, -kPi, kTwoPi / kBeams, 0); }
  /// Puts returns on the two beams nearest the bearing of p (the check wants 2 points), at p's range.
  void add(const Vec2& p_robot) {
    const Vec2 p = mount.inverse_transform(p_robot);
    const double a = std::atan2(p.y(), p.x());
    const long i = std::lround((a + kPi) / (kTwoPi / kBeams));
    for (long k = i; k <= i + 1; ++k) s.ranges_m[static_cast<std::size_t>((k + kBeams) % kBeams)] = p.norm();
  }
  ScanView view() const { return s.view(); }
};

}  // namespace

TEST_GROUP(Safety){};

TEST(Safety, EmptyScanIsValidAndClear) {
  ObstacleChecker c;
  c.configure(square_footprint(), nullptr);
  Scan sc;
  const ObstacleFlags f = c.check(sc.view(), sc.mount, nullptr);
  CHECK(f.valid);
  CHECK(!f.forward && !f.backward && !f.rotation);
  ScanView bad = sc.view();
  bad.angle_increment_rad = 0;
  CHECK(!c.check(bad, sc.mount, nullptr).valid);
}

TEST(Safety, SquareForwardAreaStartsAtTheBodyFront) {
  ObstacleChecker c;
  c.configure(square_footprint(), nullptr);
  {
    Scan sc;  // 0.2 m ahead of the 0.37 m front, on the axis: blocked forward, not behind; 0.57 m > 0.45 m: turning ok
    sc.add(Vec2(0.57, 0.0));
    const ObstacleFlags f = c.check(sc.view(), sc.mount, nullptr);
    CHECK(f.forward && !f.backward && !f.rotation);
    DOUBLES_EQUAL(0.2, f.nearest_forward_m, 1e-4);  // the second beam is 0.5° off the bearing
  }
  {
    Scan sc;  // 0.32 m ahead of the front: beyond the 0.3 m area
    sc.add(Vec2(0.69, 0.0));
    CHECK(!c.check(sc.view(), sc.mount, nullptr).forward);
  }
  {
    Scan sc;  // within the depth but |y| = 0.27 > 0.25
    sc.add(Vec2(0.5, 0.27));
    CHECK(!c.check(sc.view(), sc.mount, nullptr).forward);
  }
  {
    Scan sc;  // inside the body, on no configured self sector: an obstacle the robot overlaps, not the robot
    sc.add(Vec2(0.3, 0.0));
    const ObstacleFlags f = c.check(sc.view(), sc.mount, nullptr);
    CHECK(f.forward && f.rotation && !f.backward);
    LONGS_EQUAL(0, f.self_points);
    LONGS_EQUAL(2, f.body_points);
    CHECK(f.nearest_forward_m < 0);
  }
}

// A disc 1.5 cm beyond the front edge, inside the 2 cm self margin, is an obstacle (HIL row motion_obstacle,
// docs/reliability.md): only configured self sectors are the robot.
TEST(Safety, ObstacleWithinTheSelfMarginOfTheBumperBlocks) {
  ObstacleChecker c;
  c.configure(square_footprint(), nullptr);
  Scan sc;
  sc.add(Vec2(0.385, 0.0));  // 1.5 cm beyond the 0.37 m front edge
  ObstacleFlags f = c.check(sc.view(), sc.mount, nullptr);
  CHECK(f.forward);
  LONGS_EQUAL(0, f.self_points);
  DOUBLES_EQUAL(0.015, f.nearest_forward_m, 1e-3);
  // Driven on into the body: still blocked (forward and turning), never invisible.
  Scan deeper;
  deeper.add(Vec2(0.2, 0.05));
  f = c.check(deeper.view(), deeper.mount, nullptr);
  CHECK(f.forward && f.rotation && !f.backward);
  Scan behind;  // inside the rear half of the body: blocks backing off, not forward
  behind.add(Vec2(-0.3, 0.0));
  f = c.check(behind.view(), behind.mount, nullptr);
  CHECK(f.backward && !f.forward && f.rotation);
}

TEST(Safety, ConfiguredSelfSectorsAreTheRobot) {
  FootprintParams fp = square_footprint();
  // A lidar post at bearing 135° (lidar frame), 0.3 m from the centre, and a bumper strip across the front seen
  // through a sector that wraps through ±180° (a lidar mounted backwards).
  fp.self_sectors[0] = AngleSector{deg_to_rad(static_cast<Real>(130)), deg_to_rad(static_cast<Real>(140))};
  fp.self_sectors[1] = AngleSector{deg_to_rad(static_cast<Real>(170)), deg_to_rad(static_cast<Real>(-170))};
  fp.self_sector_count = 2;
  ObstacleChecker c;
  c.configure(fp, nullptr);
  const Vec2 post(0.3 * std::cos(deg_to_rad(135.0)), 0.3 * std::sin(deg_to_rad(135.0)));
  CHECK(c.is_self_point(post, deg_to_rad(static_cast<Real>(135))));
  CHECK(!c.is_self_point(post, deg_to_rad(static_cast<Real>(100))));  // same place, another bearing: not the robot
  Scan sc;
  sc.add(post);
  ObstacleFlags f = c.check(sc.view(), sc.mount, nullptr);
  CHECK(!f.forward && !f.backward && !f.rotation);
  LONGS_EQUAL(2, f.self_points);
  // Within the margin beyond the body on a self bearing: range noise on the robot's own structure.
  Scan edge;
  Pose2 backwards{0, 0, kPi};
  edge.mount = backwards;
  edge.add(Vec2(0.385, 0.0));  // lidar bearing 180°
  f = c.check(edge.view(), edge.mount, nullptr);
  CHECK(!f.forward);
  LONGS_EQUAL(2, f.self_points);
  // Beyond the margin on the same bearing: an obstacle (the structure cannot return from there).
  Scan beyond;
  beyond.mount = backwards;
  beyond.add(Vec2(0.45, 0.0));
  CHECK(c.check(beyond.view(), beyond.mount, nullptr).forward);
}

TEST(Safety, SquareRotationAndBackward) {
  ObstacleChecker c;
  c.configure(square_footprint(), nullptr);
  Scan side;  // beside the body (|y| 0.40 > 0.25) within the 0.45 m circumscribed radius: a turning corner hits it
  side.add(Vec2(0.0, 0.40));
  ObstacleFlags f = c.check(side.view(), side.mount, nullptr);
  CHECK(f.rotation && !f.forward && !f.backward);
  Scan behind;
  behind.add(Vec2(-0.5, 0.1));
  f = c.check(behind.view(), behind.mount, nullptr);
  CHECK(f.backward && !f.forward && !f.rotation);
}

TEST(Safety, CircularFootprint) {
  ObstacleChecker c;
  c.configure(circular_footprint(), nullptr);
  Scan sc;  // 0.2 m ahead of the 0.275 m radius, inside |y| < 0.25
  sc.add(Vec2(0.475, 0.1));
  ObstacleFlags f = c.check(sc.view(), sc.mount, nullptr);
  CHECK(f.forward && !f.rotation);
  Scan beside;  // 0.32 m to the side: a round robot turning in place sweeps nothing new
  beside.add(Vec2(0.0, 0.32));
  f = c.check(beside.view(), beside.mount, nullptr);
  CHECK(!f.rotation && !f.forward);
}

TEST(Safety, LidarMountIsApplied) {
  ObstacleChecker c;
  c.configure(square_footprint(), nullptr);
  Scan sc;
  sc.mount = Pose2{0.2, 0, 0};
  sc.add(Vec2(0.5, 0.0));  // 0.3 m from the lidar, 0.5 m from the centre: 0.13 m ahead of the front
  const ObstacleFlags f = c.check(sc.view(), sc.mount, nullptr);
  CHECK(f.forward);
  DOUBLES_EQUAL(0.13, f.nearest_forward_m, 1e-4);
}

TEST(Safety, TheDockAndTheWallBehindItAreExcluded) {
  DockProfile prof;
  CHECK(builtin_profile("breakpoint", prof) == ProfileError::kOk);
  ObstacleChecker c;
  c.configure(square_footprint(), &prof);
  // Dock face 0.15 m ahead of the front edge, facing the robot.
  const Pose2 dock{0.52, 0.0, kPi};
  Scan sc;
  sc.add(dock.transform(Vec2(0.0, 0.05)));    // on the face
  sc.add(dock.transform(Vec2(-0.06, 0.115))); // in a slot
  sc.add(dock.transform(Vec2(-0.10, 0.2)));   // the wall beside the dock, inside the forward area
  ObstacleFlags f = c.check(sc.view(), sc.mount, &dock);
  CHECK(!f.forward && !f.rotation);
  LONGS_EQUAL(6, f.dock_points);
  // Without the dock estimate the same points block.
  CHECK(c.check(sc.view(), sc.mount, nullptr).forward);
  // Something between the robot and the dock face (0.08 m in front of it, beyond the 0.05 m margin) blocks.
  Scan in_front;
  in_front.add(dock.transform(Vec2(0.08, 0.0)));
  CHECK(c.check(in_front.view(), in_front.mount, &dock).forward);
  CHECK(!c.is_dock_point(dock.transform(Vec2(0.08, 0.0)), dock));
  CHECK(c.is_dock_point(dock.transform(Vec2(0.04, 0.0)), dock));
  // Far to the side of the dock zone, at the wall line: not the dock.
  CHECK(!c.is_dock_point(dock.transform(Vec2(-0.10, 0.7)), dock));
}

TEST(Safety, WingedDockBodyIsExcludedByThePolyline) {
  DockProfile prof;
  CHECK(builtin_profile("plate-v", prof) == ProfileError::kOk);
  ObstacleChecker c;
  c.configure(square_footprint(), &prof);
  const Pose2 dock{0.6, 0.0, kPi};
  // A wing point lies behind the face plane, so it is in the zone anyway; a point 0.03 m off the face's end, in
  // front of the plane, is caught by the polyline margin.
  const Vec2 off_face = dock.transform(Vec2(0.03, 0.15));
  CHECK(c.is_dock_point(off_face, dock));
}

TEST(Safety, MotionGate) {
  const MotionGateParams g;
  ObstacleFlags f;
  f.valid = true;
  f.forward = true;
  CHECK(motion_blocked(Twist2{0.1, 0, 0}, f, g));
  CHECK(!motion_blocked(Twist2{-0.1, 0, 0}, f, g));
  CHECK(!motion_blocked(Twist2{0, 0, 0.5}, f, g));
  f.forward = false;
  f.rotation = true;
  CHECK(motion_blocked(Twist2{0, 0, 0.5}, f, g));
  CHECK(!motion_blocked(Twist2{0.2, 0, 0.5}, f, g));  // curving forward: the forward area decides
  CHECK(motion_blocked(Twist2{0, 0.1, 0}, f, g));     // holonomic sideways into the swept circle
  f.rotation = false;
  f.backward = true;
  CHECK(motion_blocked(Twist2{-0.1, 0, 0}, f, g));
  ObstacleFlags none;  // no scan: fail safe
  CHECK(motion_blocked(Twist2{0.1, 0, 0}, none, g));
  CHECK(!motion_blocked(Twist2{}, none, g));
}

// Blocked ahead with the way to turn free, a command keeps its turn alone; every other blocked case stops.
TEST(Safety, ABlockedCommandKeepsOnlyAFreeTurn) {
  MotionGateParams g;
  ObstacleFlags f;
  f.valid = true;
  f.forward = true;
  const Twist2 curve{0.2, 0.05, 0.4};
  const Twist2 kept = permitted_motion(curve, f, g, true);
  REAL_EQUAL(0.0, kept.vx_mps, 0);
  REAL_EQUAL(0.0, kept.vy_mps, 0);
  REAL_EQUAL(0.4, kept.wz_radps, 1e-6);
  const Twist2 stopped = permitted_motion(curve, f, g, false);  // turn_when_blocked off
  CHECK(stopped.vx_mps == 0 && stopped.vy_mps == 0 && stopped.wz_radps == 0);
  // A turn below the rotation threshold is no rotation the gate checks: stopped with the rest.
  CHECK(permitted_motion(Twist2{0.2, 0, 0.04}, f, g, true).wz_radps == 0);
  f.rotation = true;  // a corner would hit something when turning
  CHECK(permitted_motion(curve, f, g, true).wz_radps == 0);
  f.forward = false;
  f.rotation = false;
  f.backward = true;
  REAL_EQUAL(-0.3, permitted_motion(Twist2{-0.1, 0, -0.3}, f, g, true).wz_radps, 1e-6);
  // Not blocked: passed unchanged.
  const Twist2 free = permitted_motion(curve, f, g, true);
  REAL_EQUAL(0.2, free.vx_mps, 1e-6);
  REAL_EQUAL(0.4, free.wz_radps, 1e-6);
  ObstacleFlags none;  // no scan: nothing moves
  CHECK(permitted_motion(Twist2{0, 0, 0.5}, none, g, true).wz_radps == 0);
}

TEST(Safety, PoseDeviation) {
  const DeviationParams p;
  const Pose2 expected{0, 0, 0};
  LONGS_EQUAL(0, static_cast<int>(check_pose_deviation(Pose2{0.1, 0.1, 0.2}, expected, 1.0, 1.0, p)));
  LONGS_EQUAL(178, static_cast<int>(check_pose_deviation(Pose2{0.25, 0.25, 0}, expected, 1.0, 1.0, p)));  // 0.354 m jump
  LONGS_EQUAL(178, static_cast<int>(check_pose_deviation(expected, expected, 2.01, 1.0, p)));
  LONGS_EQUAL(0, static_cast<int>(check_pose_deviation(expected, expected, 2.4, 2.3, p)));  // started far
  LONGS_EQUAL(178, static_cast<int>(check_pose_deviation(expected, expected, 2.61, 2.3, p)));
  LONGS_EQUAL(179, static_cast<int>(check_pose_deviation(Pose2{0, 0, deg_to_rad(31)}, expected, 1.0, 1.0, p)));
  LONGS_EQUAL(0, static_cast<int>(check_pose_deviation(Pose2{0, 0, deg_to_rad(29)}, expected, 1.0, 1.0, p)));
  // Wrap-around: 359° is 1°.
  LONGS_EQUAL(0, static_cast<int>(check_pose_deviation(Pose2{0, 0, kPi - 0.01}, Pose2{0, 0, -kPi + 0.01}, 1.0, 1.0, p)));
  LONGS_EQUAL(178, static_cast<int>(check_pose_deviation(Pose2{NAN, 0, 0}, expected, 1.0, 1.0, p)));
}

TEST(Safety, FaultNames) {
  STRCMP_EQUAL("detection_failed", to_string(FaultCode::kDetectionFailed));
  STRCMP_EQUAL("task_timeout", to_string(FaultCode::kTaskTimeout));
  STRCMP_EQUAL("unknown", to_string(static_cast<FaultCode>(999)));
}

TEST(Safety, EveryFaultCodeHasItsStableName) {
  // Wire codes and names as docs/faults.md lists them; hosts log both, so neither may change.
  const char* const names[] = {"detection_failed", "distance_deviation",   "angle_deviation", "obstacle_timeout",
                               "target_lost",      "charge_not_confirmed", "contacts_lost",   "chassis_stale",
                               "lidar_stale",      "undock_failed",        "bad_command",     "align_failed",
                               "task_timeout",     "contacts_not_reached"};
  LONGS_EQUAL(177, kFirstFaultCode);
  LONGS_EQUAL(190, kLastFaultCode);
  for (std::uint16_t code = kFirstFaultCode; code <= kLastFaultCode; ++code) {
    STRCMP_EQUAL(names[code - 177], to_string(static_cast<FaultCode>(code)));
  }
  STRCMP_EQUAL("none", to_string(FaultCode::kNone));
  STRCMP_EQUAL("unknown", to_string(static_cast<FaultCode>(176)));
  STRCMP_EQUAL("unknown", to_string(static_cast<FaultCode>(191)));
}
