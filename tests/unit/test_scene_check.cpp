// core scene check: the push test's second opinion. A ray-cast room (walls, a dock, a box beside it) scanned before
// and after: a robot that was not moved and took the box for the dock reads "still", a shoved or turned robot
// "moved", and a room too bare to tell reads "unknown".
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/scene_check.hpp"
#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using dockcore_test::pose;

namespace {

Vec2 v(double x_m, double y_m) {
  return Vec2(static_cast<Real>(x_m), static_cast<Real>(y_m));
}

struct Segment {
  Vec2 a, b;
};

/// A 5 x 4 m room whose wall at x = 0 holds a 0.3 m dock (a 6 cm deep box on the wall at y = 0) and, 0.6 m to its
/// left, a 0.4 m box; `with_room` false leaves only the dock's wall, 4 m long; `with_dock` false takes the dock out
/// (hidden from the lidar) of a glass stretch of its wall.
std::vector<Segment> room(bool with_room, bool with_box = true, bool with_dock = true) {
  std::vector<Segment> s;
  auto box = [&](double x0, double y0, double x1, double y1) {
    s.push_back({v(x0, y0), v(x1, y0)});
    s.push_back({v(x1, y0), v(x1, y1)});
    s.push_back({v(x1, y1), v(x0, y1)});
    s.push_back({v(x0, y1), v(x0, y0)});
  };
  if (with_dock) {
    s.push_back({v(0, -2), v(0, 2)});
    box(0, -0.15, 0.06, 0.15);
  } else {  // the wall behind it is glass: the beams that met the dock now leave the room
    s.push_back({v(0, -2), v(0, -0.15)});
    s.push_back({v(0, 0.15), v(0, 2)});
  }
  if (with_box) box(0, 0.75, 0.4, 1.15);
  if (with_room) {
    s.push_back({v(0, 2), v(5, 2)});
    s.push_back({v(5, 2), v(5, -2)});
    s.push_back({v(5, -2), v(0, -2)});
  }
  return s;
}

/// A 720-beam full turn from a lidar at `lidar` (world), max range 8 m; no noise.
LaserScan cast(const std::vector<Segment>& world, const Pose2& lidar) {
  LaserScan scan;
  const std::size_t n = 720;
  scan.reset(n, -kPi, 2 * kPi / static_cast<Real>(n), 0);
  for (std::size_t i = 0; i < n; ++i) {
    const Real a = lidar.yaw_rad + scan.view().angle_rad(i);
    const Vec2 o(lidar.x_m, lidar.y_m), d(std::cos(a), std::sin(a));
    Real best = 0;
    for (const Segment& s : world) {
      const Vec2 e = s.b - s.a;
      const Real den = d.x() * e.y() - d.y() * e.x();
      if (std::fabs(den) < static_cast<Real>(1e-12)) continue;
      const Vec2 w = s.a - o;
      const Real t = (w.x() * e.y() - w.y() * e.x()) / den;
      const Real u = (w.x() * d.y() - w.y() * d.x()) / den;
      if (t > 0 && u >= 0 && u <= 1 && t < static_cast<Real>(8) && (best == 0 || t < best)) best = t;
    }
    scan.ranges_m[i] = best;
  }
  return scan;
}

/// The robot (lidar at its centre) 1.5 m in front of the dock, facing it.
const Pose2 kStart = pose(1.5, 0.1, kPi);

/// Judges the scan the robot takes at `truth` while odometry says `odom`, against a reference from kStart, with the
/// correction a detection at `detected_in_odom` implies (the dock expected at the origin, facing +x).
SceneVerdict judge(const std::vector<Segment>& world, const Pose2& truth, const Pose2& odom, const Pose2& detected,
                   SceneVotes* votes) {
  SceneCheck check;
  const SceneCheckParams params;
  const LaserScan ref = cast(world, kStart);
  check.set_reference(ref.view(), Pose2{}, kStart, params);
  const LaserScan now = cast(world, truth);
  const Pose2 expected{};
  const Pose2 correction = detected.compose(expected.inverse());
  return check.judge(now.view(), Pose2{}, odom, &correction, 1, params, votes);
}

}  // namespace

TEST_GROUP(SceneCheck){};

TEST(SceneCheck, TheBoxTakenForTheDockWhileTheRobotStandsIsStill) {
  // The robot moved 0.3 m towards the dock as odometry says; the box (0.95 m left of the dock) is detected.
  const Pose2 here = pose(1.2, 0.1, kPi);
  SceneVotes v;
  CHECK(judge(room(true), here, here, pose(0, 0.95, 0), &v) == SceneVerdict::kStill);
  CHECK(v.compared > 100);
  CHECK(v.still_explained > v.moved_explained + 50);
  // In the bare world (the dock's wall and the box only) the wall explains both; the box and the wall's ends decide.
  CHECK(judge(room(false), here, here, pose(0, 0.95, 0), &v) == SceneVerdict::kStill);
}

TEST(SceneCheck, AShoveAlongTheWallIsMoved) {
  // Shoved 0.4 m to the left (+y): odometry still says kStart; the dock now shows 0.4 m to the right of where it was
  // expected, in the odometry frame.
  const Pose2 truth = pose(1.5, 0.5, kPi);
  SceneVotes v;
  CHECK(judge(room(true), truth, kStart, pose(0, -0.4, 0), &v) == SceneVerdict::kMoved);
  CHECK(v.moved_explained > v.still_explained);
  CHECK(judge(room(false), truth, kStart, pose(0, -0.4, 0), &v) == SceneVerdict::kMoved);
}

TEST(SceneCheck, ATurnOnTheSpotIsMoved) {
  // Turned 35° on the spot: odometry says kStart; the room turned by -35° about the robot in the odometry frame.
  const Real turn = static_cast<Real>(35.0 * kPi / 180.0);
  const Pose2 truth{kStart.x_m, kStart.y_m, kStart.yaw_rad + turn};
  const Pose2 at_robot{kStart.x_m, kStart.y_m, 0};
  const Pose2 correction = at_robot.compose(Pose2{0, 0, -turn}).compose(at_robot.inverse());
  const Pose2 detected = correction.compose(Pose2{});  // the dock where the turned room puts it
  CHECK(judge(room(true), truth, kStart, detected, nullptr) == SceneVerdict::kMoved);
}

TEST(SceneCheck, ThePushItselfAmongSeveralReadingsIsFound) {
  // A detection whose yaw is off by 8° (a far, noisy fit) blurs a pure shove; offered the shift alone as well, the
  // check still finds the push.
  const Pose2 truth = pose(1.5, 0.5, kPi);
  SceneCheck check;
  const SceneCheckParams params;
  const LaserScan ref = cast(room(false), kStart);
  check.set_reference(ref.view(), Pose2{}, kStart, params);
  const LaserScan now = cast(room(false), truth);
  const Pose2 blurred = pose(0, -0.4, 8.0 * kPi / 180.0);
  const Pose2 shift = pose(0, -0.4, 0);
  const Pose2 both[] = {blurred, shift};
  CHECK(check.judge(now.view(), Pose2{}, kStart, &blurred, 1, params) != SceneVerdict::kMoved);
  CHECK(check.judge(now.view(), Pose2{}, kStart, both, 2, params) == SceneVerdict::kMoved);
}

TEST(SceneCheck, WithoutAReferenceOrWithTooLittleToCompareItIsUnknown) {
  SceneCheck check;
  const SceneCheckParams params;
  const LaserScan now = cast(room(true), kStart);
  const Pose2 shift = pose(0, 0.95, 0);
  CHECK(check.judge(now.view(), Pose2{}, kStart, &shift, 1, params) == SceneVerdict::kUnknown);
  LONGS_EQUAL(0, static_cast<long>(check.reference_points()));
  // A reference of a few returns (everything else beyond max_range_m): too few points to say "still".
  SceneCheckParams near = params;
  near.max_range_m = static_cast<Real>(0.3);
  const std::vector<Segment> pole = {{v(1.3, 0.09), v(1.3, 0.11)}};
  const LaserScan ref = cast(pole, kStart);
  check.set_reference(ref.view(), Pose2{}, kStart, near);
  CHECK(check.reference_points() > 0 && check.reference_points() < near.min_compared);
  CHECK(check.judge(cast(pole, kStart).view(), Pose2{}, kStart, &shift, 1, near) == SceneVerdict::kUnknown);
}

TEST(SceneCheck, ThePersonInFrontOccludesWithoutDeciding) {
  // Someone stands between the robot and the dock: the points behind them read nearer (occluded), not contradicted.
  std::vector<Segment> world = room(true);
  world.push_back({v(0.7, -0.2), v(0.7, 0.4)});
  const Pose2 here = pose(1.2, 0.1, kPi);
  SceneVotes v;
  CHECK(judge(world, here, here, pose(0, 0.95, 0), &v) == SceneVerdict::kStill);
}

TEST(SceneCheck, ReferenceKeepsAnEvenStrideOfTheReturns) {
  SceneCheck check;
  const SceneCheckParams params;
  check.set_reference(cast(room(true), kStart).view(), Pose2{}, kStart, params);
  // A closed room returns every beam: 720 returns, every fourth kept.
  LONGS_EQUAL(SceneCheck::kCapacity, static_cast<long>(check.reference_points()));
  LONGS_EQUAL(static_cast<long>(check.reference_points()),
              static_cast<long>(SceneCheck::points_kept(cast(room(true), kStart).view(), params)));
  SceneCheckParams near = params;  // 0.3 m keeps nothing of this room
  near.max_range_m = static_cast<Real>(0.3);
  LONGS_EQUAL(0, static_cast<long>(SceneCheck::points_kept(cast(room(true), kStart).view(), near)));
  check.clear();
  LONGS_EQUAL(0, static_cast<long>(check.reference_points()));
  CHECK(std::string(to_string(SceneVerdict::kStill)) == "still");
  CHECK(std::string(to_string(SceneVerdict::kMoved)) == "moved");
  CHECK(std::string(to_string(SceneVerdict::kUnknown)) == "unknown");
}

TEST(SceneCheck, StandingStillBeatsEveryProbePushOnlyWhereTheRoomCouldShowOne) {
  // When the implied push rests on one detection, dockcore asks "still" to beat shoves of 0.3 m each way and turns
  // of 10° about the robot. The robot was not moved. Before the bare dock wall a shove along it explains the wall as
  // well as standing still does, and the dock's few returns are no margin: no verdict. The box beside the dock and
  // the room's other walls show every such shove: still.
  const Pose2 here = pose(1.2, 0.1, kPi);
  const Pose2 at_robot{here.x_m, here.y_m, 0};
  const Real a = static_cast<Real>(0.3), q = static_cast<Real>(10.0 * kPi / 180.0);
  const Pose2 probes[] = {Pose2{a, 0, 0},
                          Pose2{-a, 0, 0},
                          Pose2{0, a, 0},
                          Pose2{0, -a, 0},
                          at_robot.compose(Pose2{0, 0, q}).compose(at_robot.inverse()),
                          at_robot.compose(Pose2{0, 0, -q}).compose(at_robot.inverse())};
  const SceneCheckParams params;
  for (const bool furnished : {false, true}) {
    const std::vector<Segment> world = room(furnished, furnished);
    SceneCheck check;
    const LaserScan ref = cast(world, kStart);
    check.set_reference(ref.view(), Pose2{}, kStart, params);
    const LaserScan now = cast(world, here);
    SceneVotes v;
    const SceneVerdict verdict = check.judge(now.view(), Pose2{}, here, probes, 6, params, &v);
    if (furnished) {
      CHECK(verdict == SceneVerdict::kStill);
    } else {
      CHECK(verdict == SceneVerdict::kUnknown);
      CHECK(v.still_explained > v.compared / 2);  // standing still explains the scan; it just cannot win
    }
  }
}

TEST(SceneCheck, AReadingCountsOnlyWhereTheDetectionAllowsIt) {
  const SceneCheckParams params;
  const Pose2 here = pose(1.2, 0.1, kPi);
  Pose2 out[3];
  // The box taken for the dock, 0.95 m along the wall, its yaw 1° off: a shove along the wall (with the turn as
  // noise), never a turn of 1° on the spot, which would leave the box where it was.
  const Pose2 box = pose(0, 0.95, 1.0 * kPi / 180.0);
  LONGS_EQUAL(2, static_cast<long>(push_readings(Pose2{}, box, here, params, out)));
  REAL_EQUAL(0.95, static_cast<double>(out[1].y_m), 1e-6);
  CHECK(out[1].yaw_rad == 0);
  // Turned 35° on the spot, the dock seen 10 cm from where the turn puts it (a far fit's position): the turn alone
  // counts, the shift alone does not (the detection turned by far more than a fit's noise).
  const Real turn = static_cast<Real>(35.0 * kPi / 180.0);
  const Pose2 turned = turn_about(here, -turn).compose(Pose2{}).compose(pose(0, 0.1, 0));
  LONGS_EQUAL(2, static_cast<long>(push_readings(Pose2{}, turned, here, params, out)));
  REAL_EQUAL(-static_cast<double>(turn), static_cast<double>(out[1].yaw_rad), 1e-6);
  // A shove with the yaw blurred by 8°: all three (the turn alone lands 0.17 m off at 1.2 m, within the blur).
  LONGS_EQUAL(3, static_cast<long>(push_readings(Pose2{}, pose(0, -0.4, 8.0 * kPi / 180.0), here, params, out)));
}

TEST(SceneCheck, TheBoxAlongTheWallIsStillOnlyWithoutATurnItDoesNotAllow) {
  // The robot was not moved and took the box for the dock. Judged with the readings the detection allows, the room
  // stands still. A turn of 1° on the spot explains the room about as well as standing still does; offered as a
  // reading, it ties with "still" and the verdict is lost.
  const Pose2 here = pose(1.2, 0.1, kPi);
  const SceneCheckParams params;
  SceneCheck check;
  check.set_reference(cast(room(true), kStart).view(), Pose2{}, kStart, params);
  const LaserScan now = cast(room(true), here);
  const Pose2 box = pose(0, 0.95, 1.0 * kPi / 180.0);
  Pose2 readings[4];
  const std::size_t n = push_readings(Pose2{}, box, here, params, readings);
  CHECK(check.judge(now.view(), Pose2{}, here, readings, n, params) == SceneVerdict::kStill);
  readings[n] = turn_about(here, box.yaw_rad);
  CHECK(check.judge(now.view(), Pose2{}, here, readings, n + 1, params) != SceneVerdict::kStill);
}

TEST(SceneCheck, TheDocksOwnAbsenceDoesNotCountAgainstStandingStill) {
  // The dock is hidden (the beams that met it pass through the glass behind it) and the box taken for it; the robot
  // was not moved. The dock's reference points read beyond under "still": counted against it, they cost its margin
  // (in a room with less beside the dock than this box, the verdict); with the expected dock given they count for
  // neither.
  const Pose2 here = pose(1.2, 0.1, kPi);
  const SceneCheckParams params;
  for (const bool furnished : {false, true}) {
    SceneCheck check;
    check.set_reference(cast(room(furnished), kStart).view(), Pose2{}, kStart, params);
    const LaserScan now = cast(room(furnished, true, false), here);
    const Pose2 box = pose(0, 0.95, 0);
    Pose2 readings[3];
    const std::size_t n = push_readings(Pose2{}, box, here, params, readings);
    // The expectation may be the box itself (the filter restarted on it); the dock's own place is then the second.
    const ExpectedDock docks[2] = {{Vec2(0, static_cast<Real>(0.95)), static_cast<Real>(0.25)},
                                   {Vec2(0, 0), static_cast<Real>(0.25)}};
    SceneVotes with, box_only, without;
    CHECK(check.judge(now.view(), Pose2{}, here, readings, n, params, &with, 0, docks, 2) == SceneVerdict::kStill);
    check.judge(now.view(), Pose2{}, here, readings, n, params, &box_only, 0, docks, 1);
    CHECK(box_only.still_contradicted > with.still_contradicted);
    const SceneVerdict verdict = check.judge(now.view(), Pose2{}, here, readings, n, params, &without);
    CHECK(without.still_contradicted > with.still_contradicted);
    CHECK(verdict == SceneVerdict::kStill);  // this room's box decides either way
    LONGS_EQUAL(0, static_cast<long>(with.still_contradicted));
    CHECK(without.still_contradicted >= 5);  // the dock's points, read through the glass
    LONGS_EQUAL(static_cast<long>(without.still_explained), static_cast<long>(with.still_explained));
  }
}

TEST(SceneCheck, PointsHiddenNearTheLidarDoNotDiluteStandingStill) {
  // After the reference, something stands right behind the robot and hides most of the room: those points read
  // nearer (occluded) and vote for neither. The rest of the room is explained as before: still.
  const Pose2 here = pose(1.2, 0.1, kPi);
  const SceneCheckParams params;
  SceneCheck check;
  check.set_reference(cast(room(true), kStart).view(), Pose2{}, kStart, params);
  std::vector<Segment> world = room(true);
  world.push_back({v(1.3, -1.9), v(1.3, 1.9)});
  const LaserScan now = cast(world, here);
  const Pose2 box = pose(0, 0.95, 0);
  Pose2 readings[3];
  const std::size_t n = push_readings(Pose2{}, box, here, params, readings);
  SceneVotes votes;
  CHECK(check.judge(now.view(), Pose2{}, here, readings, n, params, &votes) == SceneVerdict::kStill);
  // Fewer than half the compared points are explained: the occluded ones are most of them.
  CHECK(2 * votes.still_explained < votes.compared);
}
