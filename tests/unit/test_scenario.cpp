// Scenario TOML parsing: a complete good file, defaults, positioned errors for unknown keys, bad types and bad values,
// and the shipped scenario files.
#include <algorithm>
#include <cmath>
#include <string>

#include "docksim/angles.hpp"
#include "docksim/scenario.hpp"
#include "docksim/sim_run.hpp"

#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

namespace {

// The controller-name list is a function-local static: create it before CppUTest starts counting allocations.
const bool kNamesReady = !docksim::controller_names().empty();

constexpr double kDeg = docksim::kDegD;

std::string scenario_dir() {
  std::string f = __FILE__;  // .../tests/unit/test_scenario.cpp
  for (int i = 0; i < 3; ++i) f = f.substr(0, f.find_last_of('/'));
  return f + "/tools/scenarios/";
}

/// Parses `text`, expecting an error; returns it.
docksim::ScenarioError expect_error(const std::string& text) {
  try {
    docksim::parse_scenario_toml(text, "s.toml");
  } catch (const docksim::ScenarioError& e) {
    return e;
  }
  FAIL("no error");
  return docksim::ScenarioError("");
}

}  // namespace

TEST_GROUP(Scenario){};

TEST(Scenario, ControllerNames) {
  CHECK(kNamesReady);
  CHECK(docksim::is_controller_name("smooth"));
  CHECK(!docksim::is_controller_name("pid"));
}

TEST(Scenario, GoodFile) {
  const std::string text =
      "name = \"t\"\n"
      "seed = 42\n"
      "[robot]\n"
      "kinematics = \"mecanum\"\n"
      "wheel_radius_m = 0.06\n"
      "[robot.footprint]\n"
      "shape = \"circle\"\n"
      "radius_m = 0.25\n"
      "[robot.lidar]\n"
      "x_m = 0.1\n"
      "yaw_deg = 90\n"
      "[robot.camera]\n"
      "enabled = true\n"
      "fx_px = 600\n"
      "[lidar]\n"
      "model = \"ld06\"\n"
      "sigma_range_m = 0.02\n"
      "dropout = 0.05\n"
      "[dock]\n"
      "profile = \"v-marker\"\n"
      "x_m = 1\n"
      "yaw_deg = 180\n"
      "[[world.boxes]]\n"
      "x_m = 2\n"
      "y_m = 1\n"
      "[[world.circles]]\n"
      "x_m = -1\n"
      "r_m = 0.05\n"
      "[start]\n"
      "distance_m = [1, 2]\n"
      "bearing_deg = [-10, 20]\n"
      "heading_deg = [0, 0]\n"
      "[[events]]\n"
      "t_s = 5\n"
      "type = \"occlude_dock\"\n"
      "duration_s = 1\n"
      "[[events]]\n"
      "t_s = 2\n"
      "type = \"push\"\n"
      "dx_m = 0.3\n"
      "dyaw_deg = 10\n"
      "[controller]\n"
      "name = \"seed003\"\n"
      "[controller.seed003]\n"
      "x_kp = 2.5\n";
  const docksim::Scenario sc = docksim::parse_scenario_toml(text, "t.toml");
  STRCMP_EQUAL("t", sc.name.c_str());
  CHECK_EQUAL(42u, sc.seed);
  CHECK(sc.chassis.geometry.kind == docksim::DriveKind::kMecanum);
  REAL_EQUAL(0.06, sc.chassis.geometry.wheel_radius_m, 1e-12);
  CHECK(sc.chassis.footprint.shape == docksim::FootprintShape::kCircle);
  REAL_EQUAL(0.1, static_cast<double>(sc.lidar_mount.x_m), 1e-9);
  REAL_EQUAL(90 * kDeg, static_cast<double>(sc.lidar_mount.yaw_rad), 1e-9);
  CHECK(sc.camera.enabled);
  REAL_EQUAL(600, static_cast<double>(sc.camera.model.fx_px), 1e-9);
  // seed003 gets the scenario's camera and, on mecanum, the holonomic law.
  REAL_EQUAL(600, static_cast<double>(sc.seed003.camera.fx_px), 1e-9);
  CHECK(sc.seed003.holonomic);
  REAL_EQUAL(2.5, static_cast<double>(sc.seed003.x_kp), 1e-9);
  // Lidar overrides on top of the LD06 model.
  STRCMP_EQUAL("ld06", sc.lidar.name.c_str());
  CHECK_EQUAL(450u, sc.lidar.beams);
  REAL_EQUAL(0.02, sc.lidar.sigma_const_m, 1e-12);
  REAL_EQUAL(0.05, sc.lidar.dropout_prob, 1e-12);
  STRCMP_EQUAL("v-marker", sc.profile.name);
  REAL_EQUAL(1.0, static_cast<double>(sc.dock_pose.x_m), 1e-9);
  CHECK_EQUAL(1u, sc.boxes.size());
  CHECK_EQUAL(1u, sc.circles.size());
  REAL_EQUAL(-10 * kDeg, sc.start.bearing_min_rad, 1e-12);
  REAL_EQUAL(20 * kDeg, sc.start.bearing_max_rad, 1e-12);
  // Events sorted by time.
  CHECK_EQUAL(2u, sc.events.size());
  CHECK(sc.events[0].kind == docksim::EventKind::kPush);
  REAL_EQUAL(0.3, sc.events[0].dx_m, 1e-12);
  REAL_EQUAL(10 * kDeg, sc.events[0].dyaw_rad, 1e-12);
  CHECK(sc.events[1].kind == docksim::EventKind::kOccludeDock);
  REAL_EQUAL(1.0, sc.events[1].duration_s, 1e-12);
  STRCMP_EQUAL("seed003", sc.controller.c_str());
  // Pads on a 0.25 m circle: every controller's pad reach follows the footprint.
  REAL_EQUAL(0.25, static_cast<double>(sc.smooth.common.pad_reach_m), 1e-9);
  REAL_EQUAL(0.25, static_cast<double>(sc.seed004.common.pad_reach_m), 1e-9);
}

TEST(Scenario, EmptyFileGivesDefaults) {
  const docksim::Scenario sc = docksim::parse_scenario_toml("", "empty.toml");
  STRCMP_EQUAL("empty", sc.name.c_str());
  STRCMP_EQUAL("smooth", sc.controller.c_str());
  STRCMP_EQUAL("plate-v", sc.profile.name);
  CHECK(sc.chassis.geometry.kind == docksim::DriveKind::kDifferential);
  REAL_EQUAL(0.5, sc.start.distance_min_m, 1e-12);
  REAL_EQUAL(2.5, sc.start.distance_max_m, 1e-12);
  // Default 0.45 m rectangle, front pads: 0.225 m from the centre.
  REAL_EQUAL(0.225, static_cast<double>(sc.smooth.common.pad_reach_m), 1e-9);
  CHECK(!sc.camera.enabled);
}

TEST(Scenario, UnknownKeyHasLineAndColumn) {
  const docksim::ScenarioError e = expect_error("[robot]\nwheel_radius_m = 0.05\n  wheel_radios_m = 0.05\n");
  CHECK_EQUAL(3, e.line());
  CHECK_EQUAL(3, e.column());
  const std::string m = e.what();
  CHECK(m.rfind("s.toml:3:3: ", 0) == 0);
  CHECK(m.find("robot.wheel_radios_m") != std::string::npos);
}

TEST(Scenario, HostStallEventAndMotorCommandTimeout) {
  const docksim::Scenario sc = docksim::parse_scenario_toml(
      "[robot.motor]\ncommand_timeout_s = 0.5\n[[events]]\nt_s = 2\ntype = \"host_stall\"\nduration_s = 0.4\n",
      "s.toml");
  REAL_EQUAL(0.5, sc.chassis.motor.command_timeout_s, 1e-12);
  CHECK_EQUAL(1u, sc.events.size());
  CHECK(sc.events[0].kind == docksim::EventKind::kHostStall);
  STRCMP_EQUAL("host_stall", docksim::to_string(sc.events[0].kind));
  REAL_EQUAL(0.4, sc.events[0].duration_s, 1e-12);
  // A host stall has no motion of its own: "motion" belongs to chassis_silent.
  const docksim::ScenarioError e =
      expect_error("[[events]]\nt_s = 1\ntype = \"host_stall\"\nduration_s = 1\nmotion = \"hold\"\n");
  CHECK_EQUAL(5, e.line());
  CHECK_EQUAL(2, expect_error("[robot.motor]\ncommand_timeout_s = -1\n").line());
}

TEST(Scenario, UnknownTopLevelTableAndEventKey) {
  const docksim::ScenarioError a = expect_error("seed = 1\n[robots]\n");
  CHECK_EQUAL(2, a.line());
  // duration_s does not belong to a push.
  const docksim::ScenarioError b = expect_error("[[events]]\nt_s = 1\ntype = \"push\"\nduration_s = 2\n");
  CHECK_EQUAL(4, b.line());
  CHECK_EQUAL(1, b.column());
}

TEST(Scenario, BadValueHasLineAndColumn) {
  // Out of range: dropout is a probability.
  const docksim::ScenarioError a = expect_error("[lidar]\ndropout = 1.5\n");
  CHECK_EQUAL(2, a.line());
  CHECK_EQUAL(11, a.column());
  // Wrong type.
  const docksim::ScenarioError b = expect_error("[robot]\nkinematics = 3\n");
  CHECK_EQUAL(2, b.line());
  CHECK_EQUAL(14, b.column());
  // Not one of the choices.
  const docksim::ScenarioError c = expect_error("[robot]\nkinematics = \"tricycle\"\n");
  CHECK_EQUAL(2, c.line());
  CHECK(std::string(c.what()).find("diff, mecanum") != std::string::npos);
  // A range with min > max.
  const docksim::ScenarioError d = expect_error("[start]\ndistance_m = [2, 1]\n");
  CHECK_EQUAL(2, d.line());
  // Unknown lidar model and controller.
  const docksim::ScenarioError e = expect_error("[lidar]\nmodel = \"sick\"\n");
  CHECK_EQUAL(2, e.line());
  const docksim::ScenarioError f = expect_error("[controller]\nname = \"pid\"\n");
  CHECK_EQUAL(2, f.line());
  // Unknown profile.
  const docksim::ScenarioError g = expect_error("[dock]\n\nprofile = \"round\"\n");
  CHECK_EQUAL(3, g.line());
  // TOML syntax error.
  const docksim::ScenarioError h = expect_error("[robot\n");
  CHECK_EQUAL(1, h.line());
}

TEST(Scenario, ShippedFilesLoad) {
  const docksim::Scenario d = docksim::load_scenario_file(scenario_dir() + "default.toml");
  STRCMP_EQUAL("default", d.name.c_str());
  CHECK(d.chassis.geometry.kind == docksim::DriveKind::kDifferential);
  STRCMP_EQUAL("ld06", d.lidar.name.c_str());
  REAL_EQUAL(0.010, d.lidar.sigma_const_m, 1e-12);
  REAL_EQUAL(0.03, d.lidar.dropout_prob, 1e-12);
  REAL_EQUAL(0.5, d.start.distance_min_m, 1e-12);
  REAL_EQUAL(2.5, d.start.distance_max_m, 1e-12);
  REAL_EQUAL(45 * kDeg, d.start.bearing_max_rad, 1e-12);
  REAL_EQUAL(-30 * kDeg, d.start.heading_min_rad, 1e-12);
  const docksim::Scenario s = docksim::load_scenario_file(scenario_dir() + "seed003.toml");
  CHECK(s.chassis.geometry.kind == docksim::DriveKind::kMecanum);
  CHECK(s.camera.enabled);
  CHECK(s.seed003.holonomic);
  try {
    docksim::load_scenario_file(scenario_dir() + "no-such-file.toml");
    FAIL("no error");
  } catch (const docksim::ScenarioError& e) {
    CHECK_EQUAL(0, e.line());
  }
}

// [dock] dead and stop_short_m reach the chassis's dock; the final push's bounds are [task] keys.
TEST(Scenario, ADeadChargerAndAnUnseenStopShortOfTheContacts) {
  const docksim::Scenario none = docksim::parse_scenario_toml("", "none.toml");
  CHECK(!none.dock_dead);
  REAL_EQUAL(0.0, none.dock_stop_short_m, 0);
  const docksim::Scenario sc = docksim::parse_scenario_toml(
      "[dock]\ndead = true\nstop_short_m = 0.02\n[task]\npush_zone_m = 0.12\nmax_push_m = 0.2\nmax_push_s = 8\n",
      "s.toml");
  const docksim::DockPlacement dp = docksim::dock_placement(sc);
  CHECK(dp.dead);
  REAL_EQUAL(0.02, dp.stop_short_m, 1e-12);
  REAL_EQUAL(0.12, static_cast<double>(sc.task.push_zone_m), 1e-9);
  REAL_EQUAL(0.2, static_cast<double>(sc.task.max_push_m), 1e-9);
  REAL_EQUAL(8.0, static_cast<double>(sc.task.max_push_s), 1e-9);
  CHECK_EQUAL(2, expect_error("[dock]\nstop_short_m = 0.6\n").line());
  CHECK_EQUAL(2, expect_error("[task]\nmax_push_s = 0\n").line());
}

TEST(Scenario, SmoothLineupParametersAreSettable) {
  const docksim::Scenario sc = docksim::parse_scenario_toml(
      "[controller]\nname = \"smooth\"\n[controller.smooth]\nlineup_distance_m = 0.35\nlineup_max_curvature_inv_m = 2.5\n",
      "lineup.toml");
  REAL_EQUAL(0.35, sc.smooth.lineup_distance_m, 1e-12);
  REAL_EQUAL(2.5, sc.smooth.lineup_max_curvature_inv_m, 1e-12);
}

namespace {

/// Range of the first world hit from `from` along `dir` (unit), or -1 when nothing is hit within 10 m.
double first_hit(const docksim::World& w, const dockcore::Vec2& from, const dockcore::Vec2& dir) {
  double r = 0;
  return w.raycast(from, dir, 10.0, &r) ? r : -1;
}

/// Checks that `text` is refused at line:column with `needle` in the message.
void refused_at(const std::string& text, int line, int column, const char* needle) {
  const docksim::ScenarioError e = expect_error(text);
  const std::string msg = e.what();
  CHECK_EQUAL_TEXT(line, e.line(), msg.c_str());
  CHECK_EQUAL_TEXT(column, e.column(), msg.c_str());
  const std::string prefix = "s.toml:" + std::to_string(line) + ":" + std::to_string(column) + ": ";
  CHECK_TEXT(msg.rfind(prefix, 0) == 0, msg.c_str());
  CHECK_TEXT(msg.find(needle) != std::string::npos, msg.c_str());
}

constexpr double kPlateVBackM = -0.1 * 0.70710678118654752;  // plate-v's smallest x (its wing tips)
constexpr double kPlateVHalfWidthM = 0.15 - kPlateVBackM;      // its largest |y|
/// World geometry is in core's Real (float in the float build): ranges of ~1 m hold a few float ulps.
const double kHitTol = dockcore_test::real_tol(1.0, 1e-9, 16);

}  // namespace

TEST(Scenario, WallGapGlassAndFreeStandingShapeTheLidarsWorld) {
  // A beam from 1 m out, 0.4 m to the dock's left (clear of the dock), straight back at the wall.
  const dockcore::Vec2 from(1.0, 0.4), back(-1.0, 0.0);
  const docksim::Scenario flush = docksim::parse_scenario_toml("[dock]\nwall = true\n", "s.toml");
  DOUBLES_EQUAL(1.0 - kPlateVBackM, first_hit(docksim::scenario_world(flush), from, back), kHitTol);
  const docksim::Scenario gap = docksim::parse_scenario_toml("[dock]\nwall_gap_m = 0.05\n", "s.toml");
  REAL_EQUAL(0.05, gap.wall_gap_m, 1e-12);
  DOUBLES_EQUAL(1.0 - kPlateVBackM + 0.05, first_hit(docksim::scenario_world(gap), from, back), kHitTol);
  // Glass: the wall is there (dock_wall) but the lidar sees through it.
  const docksim::Scenario glass = docksim::parse_scenario_toml("[dock]\nwall_glass = true\n", "s.toml");
  CHECK(glass.wall && glass.wall_glass);
  DOUBLES_EQUAL(-1, first_hit(docksim::scenario_world(glass), from, back), 0);
  dockcore::Vec2 a, b;
  CHECK(docksim::dock_wall(glass, &a, &b));
  REAL_EQUAL(kPlateVBackM, a.x(), 1e-9);
  // Free-standing: no wall at all; the dock itself is still hit.
  const docksim::Scenario free = docksim::parse_scenario_toml("[dock]\nwall = false\n", "s.toml");
  CHECK_FALSE(docksim::dock_wall(free, &a, &b));
  DOUBLES_EQUAL(-1, first_hit(docksim::scenario_world(free), from, back), 0);
  DOUBLES_EQUAL(1.0, first_hit(docksim::scenario_world(free), dockcore::Vec2(1.0, 0.0), back), kHitTol);
  // The gap follows the dock's pose: a dock at (2, 1) turned 90° has its wall along y = 1 + back - gap.
  const docksim::Scenario turned =
      docksim::parse_scenario_toml("[dock]\nx_m = 2\ny_m = 1\nyaw_deg = 90\nwall_gap_m = 0.1\n", "s.toml");
  CHECK(docksim::dock_wall(turned, &a, &b));
  REAL_EQUAL(1.0 + kPlateVBackM - 0.1, a.y(), 1e-6);
  REAL_EQUAL(1.0 + kPlateVBackM - 0.1, b.y(), 1e-6);
}

TEST(Scenario, WhatTheDetectorIsToldIsIndependentOfTheWorld) {
  // Default: the profile's own mounting (built-ins: unknown).
  CHECK(docksim::parse_scenario_toml("", "s.toml").profile.mounting.kind == dockcore::DockMountKind::kUnknown);
  // Told unknown, the world has a wall 5 cm behind the dock.
  const docksim::Scenario a =
      docksim::parse_scenario_toml("[dock]\nwall_gap_m = 0.05\n[dock.mounting]\nkind = \"unknown\"\n", "s.toml");
  CHECK(a.profile.mounting.kind == dockcore::DockMountKind::kUnknown);
  REAL_EQUAL(0.05, a.wall_gap_m, 1e-12);
  // Told "wall 0-50 mm", the world has none.
  const docksim::Scenario b = docksim::parse_scenario_toml(
      "[dock]\nwall = false\n[dock.mounting]\nkind = \"wall\"\nwall_gap_m = [0, 0.05]\n", "s.toml");
  CHECK_FALSE(b.wall);
  CHECK(b.profile.mounting.kind == dockcore::DockMountKind::kWall);
  REAL_EQUAL(0.05, b.profile.mounting.wall_gap_max_m, 1e-12);
}

TEST(Scenario, FurnitureStandsBesideTheDock) {
  const docksim::Scenario sc = docksim::parse_scenario_toml(
      "[dock]\nwall_gap_m = 0.02\n"
      "[[dock.furniture]]\nkind = \"box\"\nside = \"left\"\ngap_m = 0.3\ndepth_m = 0.4\nwidth_m = 0.2\n"
      "[[dock.furniture]]\nkind = \"bin\"\nside = \"right\"\ngap_m = 0.25\nradius_m = 0.1\nx_m = 0.5\n"
      "[[dock.furniture]]\nkind = \"chair\"\nside = \"right\"\ngap_m = 0.8\nseat_m = 0.4\nleg_radius_m = 0.02\n",
      "s.toml");
  CHECK_EQUAL(3u, sc.furniture.size());
  CHECK_EQUAL(1u, sc.boxes.size());
  CHECK_EQUAL(5u, sc.circles.size());  // the bin and four chair legs
  // Box: near edge 0.3 m beyond the dock's outermost +y, back 1 cm in front of the wall (2 cm behind the dock).
  const double back = kPlateVBackM - 0.02 + docksim::kFurnitureWallClearanceM;
  REAL_EQUAL(back + 0.2, sc.boxes[0].centre.x(), 1e-9);
  REAL_EQUAL(kPlateVHalfWidthM + 0.3 + 0.1, sc.boxes[0].centre.y(), 1e-9);
  // Bin at the given x, on the right.
  REAL_EQUAL(0.5, sc.circles[0].centre.x(), 1e-9);
  REAL_EQUAL(-(kPlateVHalfWidthM + 0.25 + 0.1), sc.circles[0].centre.y(), 1e-9);
  // Chair legs: outer edges on the 0.4 m seat square, whose near side is 0.8 m beyond the dock's -y edge.
  double nearest = -1e9;
  for (std::size_t i = 1; i < 5; ++i) {
    REAL_EQUAL(0.02, sc.circles[i].r_m, 1e-12);
    nearest = std::max(nearest, static_cast<double>(sc.circles[i].centre.y()) + 0.02);
  }
  REAL_EQUAL(-(kPlateVHalfWidthM + 0.8), nearest, 1e-9);
  // The lidar sees the box: a beam parallel to the dock's x at the box's centre line hits its front face.
  const docksim::World w = docksim::scenario_world(sc);
  DOUBLES_EQUAL(1.0 - (back + 0.4), first_hit(w, dockcore::Vec2(1.0, sc.boxes[0].centre.y()), dockcore::Vec2(-1, 0)),
                std::max(1e-6, kHitTol));
  // Furniture follows a turned dock: a dock facing +y has its left at -x.
  const docksim::Scenario t =
      docksim::parse_scenario_toml("[dock]\nyaw_deg = 90\nwall = false\n[[dock.furniture]]\nkind = \"bin\"\n", "s.toml");
  REAL_EQUAL(-(kPlateVHalfWidthM + 0.3 + 0.15), t.circles[0].centre.x(), 1e-6);
  REAL_EQUAL(kPlateVBackM + 0.15, t.circles[0].centre.y(), 1e-6);
}

TEST(Scenario, BadWallMountingAndFurnitureValuesArePositioned) {
  //                   col: 1234567890123
  refused_at("[dock]\nwall_gap_m = 0.6\n", 2, 14, "dock.wall_gap_m = 0.6 is out of range [0, 0.5]");
  refused_at("[dock]\nwall_glass = \"yes\"\n", 2, 14, "dock.wall_glass must be true or false");
  refused_at("[dock]\nwall = false\nwall_gap_m = 0.05\n", 3, 14,
             "dock.wall_gap_m is only meaningful with dock.wall = true");
  refused_at("[dock]\nwall_glass = true\nwall = false\n", 2, 14, "dock.wall_glass is only meaningful with");
  refused_at("[dock.mounting]\nkind = \"wall\"\nwall_gap_m = [0.1, 0.05]\n", 3, 14, "minimum is larger than the maximum");
  refused_at("[dock.mounting]\nkind = \"glass\"\n", 2, 8, "dock.mounting.kind = \"glass\" is not one of");
  refused_at("[[dock.furniture]]\nkind = \"sofa\"\n", 2, 8, "dock.furniture.kind = \"sofa\" is not one of box, bin, chair");
  refused_at("[[dock.furniture]]\nside = \"left\"\n", 1, 1, "without 'kind'");
  refused_at("[[dock.furniture]]\nkind = \"box\"\nradius_m = 0.2\n", 3, 1, "unknown key 'dock.furniture.box.radius_m'");
  refused_at("[[dock.furniture]]\nkind = \"bin\"\nside = \"behind\"\n", 3, 8, "is not one of left, right");
  refused_at("[[dock.furniture]]\nkind = \"bin\"\ngap_m = 4\n", 3, 9, "dock.furniture.bin.gap_m = 4 is out of range [0, 3]");
  refused_at("[[dock.furniture]]\nkind = \"chair\"\nleg_radius_m = 0.1\n", 3, 16, "out of range [0.005, 0.05]");
  refused_at("[[dock.furniture]]\nkind = \"box\"\nwidth_m = 0.01\n", 3, 11, "out of range [0.05, 2]");
  refused_at("[dock]\nfurniture = 3\n", 2, 13, "dock.furniture must be an array of tables");
}

TEST(Scenario, ShippedWallScenariosHaveTheirWorlds) {
  const docksim::Scenario f = docksim::load_scenario_file(scenario_dir() + "free-standing.toml");
  CHECK_FALSE(f.wall);
  CHECK(f.profile.mounting.kind == dockcore::DockMountKind::kFreeStanding);
  const docksim::Scenario g = docksim::load_scenario_file(scenario_dir() + "wall-gap-5cm.toml");
  CHECK(g.wall && !g.wall_glass);
  REAL_EQUAL(0.05, g.wall_gap_m, 1e-12);
  CHECK(g.profile.mounting.kind == dockcore::DockMountKind::kUnknown);
  const docksim::Scenario s = docksim::load_scenario_file(scenario_dir() + "glass.toml");
  CHECK(s.wall && s.wall_glass);
  CHECK(s.profile.mounting.kind == dockcore::DockMountKind::kUnknown);
  const docksim::Scenario u = docksim::load_scenario_file(scenario_dir() + "furniture.toml");
  CHECK_EQUAL(3u, u.furniture.size());
  // Apart from the dock's surroundings they are the default scenario.
  const docksim::Scenario d = docksim::load_scenario_file(scenario_dir() + "default.toml");
  for (const docksim::Scenario* x : {&f, &g, &s, &u}) {
    REAL_EQUAL(d.start.distance_max_m, x->start.distance_max_m, 0);
    REAL_EQUAL(d.estimator.max_range_m, x->estimator.max_range_m, 0);
    STRCMP_EQUAL(d.controller.c_str(), x->controller.c_str());
  }
}

TEST(Scenario, EstimatorTuningKeys) {
  // The same text as dockd's EstimatorTuningKeys test: both parsers share one key list.
  const docksim::Scenario sc = docksim::parse_scenario_toml(
      "[estimator]\ninlier_gate_m = 0.02\nmax_view_angle_deg = 60\nselect = \"hint\"\nmin_inliers = 14\n"
      "[estimator.segments]\nmin_points = 4\n",
      "s.toml");
  REAL_EQUAL(0.02, sc.estimator.inlier_gate_m, 1e-12);
  REAL_EQUAL(60 * kDeg, sc.estimator.max_view_angle_rad, 1e-9);
  CHECK(sc.estimator.select == dockcore::DockSelect::kHint);
  CHECK_EQUAL(14u, sc.estimator.min_inliers);
  CHECK_EQUAL(4u, sc.estimator.segments.min_points);
  const dockcore::EstimatorParams d{};
  REAL_EQUAL(d.min_evidence_nats, sc.estimator.min_evidence_nats, 0);
  refused_at("[estimator]\ninlier_gate_m = 0.6\n", 2, 17, "estimator.inlier_gate_m = 0.6 is out of range [0.001, 0.5]");
  refused_at("[estimator]\nmax_view_angle_deg = 95\n", 2, 22, "estimator.max_view_angle_deg = 95 is out of range [1, 90]");
  refused_at("[estimator]\nselect = \"first\"\n", 2, 10, "estimator.select = \"first\" is not one of nearest, hint");
  refused_at("[estimator]\nwall_tolerance_m = 0.3\n", 2, 20, "estimator.wall_tolerance_m = 0.3 is out of range [0, 0.2]");
  refused_at("[estimator]\nrequire_wall_behind = false\n", 2, 1, "unknown key 'estimator.require_wall_behind'");
}

TEST(Scenario, TheDockTakesItsDetector) {
  const docksim::Scenario sc = docksim::load_scenario_file(scenario_dir() + "seed000.toml");
  CHECK(sc.detector == dockcore::DockDetector::kBreakpoint);
  STRCMP_EQUAL("seed000", sc.controller.c_str());
  CHECK(docksim::parse_scenario_toml("", "s.toml").detector == dockcore::DockDetector::kEstimator);
  // A bad value, and a detector that cannot find the dock's profile, at the key.
  const docksim::ScenarioError bad = expect_error("[dock]\ndetector = \"vmarker\"\n");
  STRCMP_CONTAINS("s.toml:2:12: dock.detector = \"vmarker\" is not one of estimator, breakpoint", bad.what());
  const docksim::ScenarioError mismatch = expect_error("[dock]\nprofile = \"plate-v\"\ndetector = \"breakpoint\"\n");
  STRCMP_CONTAINS("s.toml:3:12: dock.detector = \"breakpoint\": detector breakpoint finds only the breakpoint dock",
                  mismatch.what());
}

TEST(Scenario, AnotherDockStandsBesideTheDockWithItsOwnTape) {
  const docksim::Scenario sc = docksim::load_scenario_file(scenario_dir() + "two-docks.toml");
  CHECK_EQUAL(2u, sc.profile.reflector_count);
  CHECK_EQUAL(1u, sc.other_docks.size());
  const docksim::Scenario::OtherDock& d = sc.other_docks[0];
  CHECK_EQUAL(1u, d.profile.reflector_count);
  REAL_EQUAL(0.0, d.pose.x_m, 1e-9);  // the same outline: back planes aligned, origins level
  REAL_EQUAL(1.0, d.pose.y_m, 1e-3);  // centres 1 m apart, on the dock's left
  REAL_EQUAL(0.0, d.pose.yaw_rad, 1e-12);
  // The world holds both docks' tape: one retro piece per stripe.
  const docksim::World w = docksim::scenario_world(sc);
  int retro = 0;
  for (const auto& s : w.segments) retro += s.retro ? 1 : 0;
  CHECK_EQUAL(3, retro);
  // Reported at the entry, not at the file's start.
  refused_at("[[dock.furniture]]\nkind = \"box\"\n\n[[dock.furniture]]\nkind = \"dock\"\nside = \"left\"\n", 4, 1,
             "kind dock without 'profile'");
  refused_at("[[dock.furniture]]\nkind = \"dock\"\nprofile = \"round\"\n", 3, 11, "dock.furniture.profile");
}
