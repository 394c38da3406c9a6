// Scenario TOML parsing: a complete good file, defaults, positioned errors for unknown keys, bad types and bad values,
// and the shipped scenario files.
#include <cmath>
#include <string>

#include "docksim/scenario.hpp"

#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

namespace {

// The controller-name list is a function-local static: create it before CppUTest starts counting allocations.
const bool kNamesReady = !docksim::controller_names().empty();

constexpr double kDeg = 3.14159265358979323846 / 180.0;

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

TEST(Scenario, SmoothLineupParametersAreSettable) {
  const docksim::Scenario sc = docksim::parse_scenario_toml(
      "[controller]\nname = \"smooth\"\n[controller.smooth]\nlineup_distance_m = 0.35\nlineup_max_curvature_inv_m = 2.5\n",
      "lineup.toml");
  REAL_EQUAL(0.35, sc.smooth.lineup_distance_m, 1e-12);
  REAL_EQUAL(2.5, sc.smooth.lineup_max_curvature_inv_m, 1e-12);
}
