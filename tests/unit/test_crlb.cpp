#include "dockcore/perception/dock_profile.hpp"
#include "docksim/crlb.hpp"

#include <cstdio>

#include <CppUTest/TestHarness.h>

using namespace dockcore;

TEST_GROUP(Crlb){};

// Reference figures of the specification for plate-v, LD06 (0.8°), σ 10 mm, head-on:
// ~4 mm / 0.95° at 0.5 m, ~6 mm / 1.4° at 1 m.
TEST(Crlb, PlateVMatchesReferenceFigures) {
  DockProfile p;
  builtin_profile("plate-v", p);
  const double inc = 0.8 * kPi / 180.0;
  const docksim::Crlb at05 = docksim::dock_pose_crlb(p, Pose2{0.5, 0.0, kPi}, -kPi, inc, 450, 0.01, 0.0);
  const docksim::Crlb at10 = docksim::dock_pose_crlb(p, Pose2{1.0, 0.0, kPi}, -kPi, inc, 450, 0.01, 0.0);
  CHECK_TRUE(at05.ok);
  CHECK_TRUE(at10.ok);
  DOUBLES_EQUAL(0.004, at05.sigma_lateral_m, 0.0012);
  DOUBLES_EQUAL(0.95, rad_to_deg(at05.sigma_yaw_rad), 0.3);
  DOUBLES_EQUAL(0.006, at10.sigma_lateral_m, 0.0018);
  DOUBLES_EQUAL(1.4, rad_to_deg(at10.sigma_yaw_rad), 0.45);
  CHECK(at10.beams < at05.beams);
}

TEST(Crlb, FlatPlateHasNoLateralInformation) {
  const Vec2 v[] = {Vec2(0, -0.15), Vec2(0, 0.15)};
  DockProfile flat;
  make_profile(v, 2, 0, "flat", flat);
  const docksim::Crlb b = docksim::dock_pose_crlb(flat, Pose2{0.5, 0.0, kPi}, -kPi, 0.8 * kPi / 180.0, 450, 0.01, 0.0);
  // Sliding a flat plate along itself changes no range: the bound is singular (or astronomically large).
  if (b.ok) {
    char msg[64];
    std::snprintf(msg, sizeof msg, "lateral bound %g m", b.sigma_lateral_m);
    CHECK_TEXT(b.sigma_lateral_m > 1.0, msg);
  }
}
