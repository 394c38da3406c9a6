#include <cstdio>
#include <cstring>

#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/dock_profile.hpp"

#include "real_tolerance.hpp"

#include <cmath>
#include <limits>

#include <CppUTest/TestHarness.h>

using namespace dockcore;

TEST_GROUP(Geometry){};

TEST(Geometry, WrapAngleStaysInHalfOpenInterval) {
  REAL_EQUAL(kPi, wrap_angle(kPi), 1e-12);
  REAL_EQUAL(kPi, wrap_angle(-kPi), 1e-12);
  // The input angle itself is rounded to Real at its own magnitude (63 rad: 4e-6 in float), so that is the scale.
  DOUBLES_EQUAL(0.5, wrap_angle(0.5 + 10 * kTwoPi), dockcore_test::real_tol(10 * kTwoPi, 1e-9));
  DOUBLES_EQUAL(-0.5, wrap_angle(-0.5 - 3 * kTwoPi), dockcore_test::real_tol(3 * kTwoPi, 1e-9));
}

TEST(Geometry, WrapAngleIsTheRemainderBitForBit) {
  // The subtraction wrap_angle takes within three half-turns must give exactly what std::remainder gives, on both
  // sides of every branch boundary (pi, 3 pi and their negatives, where the remainder's ties round to even).
  auto reference = [](Real a) {
    Real r = std::remainder(a, kTwoPi);
    if (r <= -kPi) r += kTwoPi;
    return r;
  };
  int checked = 0;
  for (const Real edge : {kPi, 3 * kPi, -kPi, -3 * kPi, static_cast<Real>(0), kTwoPi, -kTwoPi}) {
    Real below = edge;
    Real above = edge;
    for (int k = 0; k < 64; ++k) {
      for (const Real a : {below, above}) {
        CHECK_TRUE(wrap_angle(a) == reference(a));
        ++checked;
      }
      below = std::nextafter(below, -std::numeric_limits<Real>::infinity());
      above = std::nextafter(above, std::numeric_limits<Real>::infinity());
    }
  }
  for (int k = -4000; k <= 4000; ++k) {
    const Real a = static_cast<Real>(k) * static_cast<Real>(0.00377);  // about +-15 rad, off any grid of pi
    CHECK_TRUE(wrap_angle(a) == reference(a));
    ++checked;
  }
  CHECK_EQUAL(7 * 64 * 2 + 8001, checked);
}

TEST(Geometry, ComposeWithInverseIsIdentity) {
  const Pose2 a{1.0, -2.0, 2.5};
  const Pose2 b{-0.3, 0.7, -3.0};
  const Pose2 ab = a.compose(b);
  const Pose2 back = a.inverse().compose(ab);
  REAL_EQUAL(b.x_m, back.x_m, 1e-12);
  REAL_EQUAL(b.y_m, back.y_m, 1e-12);
  REAL_EQUAL(b.yaw_rad, back.yaw_rad, 1e-12);
  const Vec2 p(0.4, -0.1);
  const Vec2 q = a.inverse_transform(a.transform(p));
  REAL_EQUAL(p.x(), q.x(), 1e-12);
  REAL_EQUAL(p.y(), q.y(), 1e-12);
}

TEST_GROUP(Scan){};

TEST(Scan, PointsSkipInvalidAndApplyMount) {
  LaserScanN<8> s;
  CHECK_TRUE(s.reset(4, -kPi / 2, kPi / 2, 7));
  s.ranges_m[0] = 1.0;
  s.ranges_m[1] = 0.0;
  s.ranges_m[2] = 2.0;
  s.ranges_m[3] = std::numeric_limits<Real>::infinity();
  ScanPoints pts;
  std::size_t dropped = 99;
  CHECK_EQUAL(2u, scan_to_points(s.view(), Pose2{0.1, 0.0, kPi / 2}, 0.0, 10.0, pts, &dropped));
  CHECK_EQUAL(0u, dropped);
  // Beam at -90° in a lidar turned +90° points along robot +x.
  REAL_EQUAL(1.1, pts[0].p_m.x(), 1e-12);
  REAL_EQUAL(0.0, pts[0].p_m.y(), 1e-12);
  CHECK_EQUAL(2u, pts[1].index);
  // Beam at +90° turned by +90° points along robot -x.
  REAL_EQUAL(-1.9, pts[1].p_m.x(), 1e-12);
  REAL_EQUAL(0.0, pts[1].p_m.y(), 1e-12);
}

TEST(Scan, ResetRefusesOversizedScan) {
  LaserScanN<8> s;
  CHECK_FALSE(s.reset(9, 0, 0.1, 0));
  CHECK_EQUAL(0u, s.count);
}

TEST(Scan, FullTurnWraps) {
  LaserScanN<360> s;
  s.reset(360, -kPi, kTwoPi / 360, 0);
  CHECK_TRUE(s.view().wraps());
  s.reset(180, -kPi / 2, kTwoPi / 360, 0);
  CHECK_FALSE(s.view().wraps());
}

TEST_GROUP(Profile){};

TEST(Profile, BuiltinsExistAndFaceOutwards) {
  for (std::size_t k = 0; kBuiltinProfileNames[k] != nullptr; ++k) {
    DockProfile p;
    CHECK_EQUAL(static_cast<int>(ProfileError::kOk), static_cast<int>(builtin_profile(kBuiltinProfileNames[k], p)));
    STRCMP_EQUAL(kBuiltinProfileNames[k], p.name);
    REAL_EQUAL(0.30, p.width_m(), 0.15);
  }
  DockProfile plate;
  builtin_profile("plate-v", plate);
  CHECK_EQUAL(4u, plate.vertex_count);
  REAL_EQUAL(1.0, plate.normal(1).x(), 1e-12);  // the face looks along +x
  REAL_EQUAL(0.30 + 0.20, plate.length_m(), 1e-9);
}

TEST(Profile, BadProfilesAreRefusedAndLeaveOutputAlone) {
  DockProfile p;
  builtin_profile("plate-v", p);
  const Vec2 one[] = {Vec2(0, 0)};
  CHECK_EQUAL(static_cast<int>(ProfileError::kTooFewVertices), static_cast<int>(make_profile(one, 1, 0, "x", p)));
  const Vec2 dup[] = {Vec2(0, 0), Vec2(0, 0.0005)};
  CHECK_EQUAL(static_cast<int>(ProfileError::kDegenerateSegment), static_cast<int>(make_profile(dup, 2, 0, "x", p)));
  const Vec2 nan[] = {Vec2(0, 0), Vec2(std::nan(""), 1)};
  CHECK_EQUAL(static_cast<int>(ProfileError::kNotFinite), static_cast<int>(make_profile(nan, 2, 0, "x", p)));
  CHECK_EQUAL(static_cast<int>(ProfileError::kUnknownName), static_cast<int>(builtin_profile("nope", p)));
  STRCMP_EQUAL("plate-v", p.name);
}

TEST(Profile, ContactOffsetShiftsOrigin) {
  const Vec2 v[] = {Vec2(0.05, -0.1), Vec2(0.05, 0.1)};
  DockProfile p;
  CHECK_EQUAL(static_cast<int>(ProfileError::kOk), static_cast<int>(make_profile(v, 2, 0.05, "flat", p)));
  REAL_EQUAL(0.0, p.vertices_m[0].x(), 1e-12);
}

TEST(Profile, TooManyVerticesAreRefused) {
  Vec2 v[kMaxProfileVertices + 1];
  for (std::size_t i = 0; i <= kMaxProfileVertices; ++i) v[i] = Vec2(0, 0.01 * static_cast<double>(i));
  DockProfile p;
  CHECK_EQUAL(static_cast<int>(ProfileError::kOk),
              static_cast<int>(make_profile(v, kMaxProfileVertices, 0, "most", p)));
  CHECK_EQUAL(kMaxProfileVertices, p.vertex_count);
  CHECK_EQUAL(static_cast<int>(ProfileError::kTooManyVertices),
              static_cast<int>(make_profile(v, kMaxProfileVertices + 1, 0, "too-many", p)));
  STRCMP_EQUAL("most", p.name);
}

TEST(Profile, EveryErrorHasItsOwnMessage) {
  const ProfileError errors[] = {ProfileError::kOk,
                                 ProfileError::kTooFewVertices,
                                 ProfileError::kTooManyVertices,
                                 ProfileError::kDegenerateSegment,
                                 ProfileError::kNotFinite,
                                 ProfileError::kUnknownName,
                                 ProfileError::kReflectorNoSegment,
                                 ProfileError::kReflectorOffSegment,
                                 ProfileError::kReflectorTooShort,
                                 ProfileError::kReflectorOverlap,
                                 ProfileError::kTooManyReflectors};
  const std::size_t n = sizeof(errors) / sizeof(errors[0]);
  for (std::size_t a = 0; a < n; ++a) {
    const char* msg = to_string(errors[a]);
    CHECK(msg != nullptr);
    STRCMP_NOCASE_CONTAINS(a == 0 ? "ok" : (a < 6 ? "profile" : "reflector"), msg);
    for (std::size_t b = 0; b < a; ++b) CHECK(std::strcmp(msg, to_string(errors[b])) != 0);
  }
  // The capacity the message names is the real one.
  char cap[8];
  std::snprintf(cap, sizeof cap, "%zu", kMaxProfileVertices);
  STRCMP_CONTAINS(cap, to_string(ProfileError::kTooManyVertices));
  STRCMP_EQUAL("unknown profile error", to_string(static_cast<ProfileError>(200)));
}

TEST(Profile, EachBadReflectorSaysWhichRuleItBrokeAndLeavesTheProfileAlone) {
  DockProfile p;
  CHECK(builtin_profile("plate-v", p) == ProfileError::kOk);  // face: segment 1, 0.30 m
  const auto add = [&p](std::uint8_t seg, double from_m, double to_m) {
    return static_cast<int>(add_reflector(p, ReflectorStripe{seg, static_cast<Real>(from_m), static_cast<Real>(to_m)}));
  };
  CHECK_EQUAL(static_cast<int>(ProfileError::kOk), add(1, 0.10, 0.20));
  CHECK_EQUAL(static_cast<int>(ProfileError::kReflectorNoSegment), add(3, 0.0, 0.05));
  CHECK_EQUAL(static_cast<int>(ProfileError::kReflectorOffSegment), add(1, 0.25, 0.35));
  CHECK_EQUAL(static_cast<int>(ProfileError::kReflectorOffSegment), add(1, -0.01, 0.05));
  CHECK_EQUAL(static_cast<int>(ProfileError::kReflectorOffSegment), add(1, 0.0, std::nan("")));
  CHECK_EQUAL(static_cast<int>(ProfileError::kReflectorTooShort), add(1, 0.0, 0.005));
  CHECK_EQUAL(static_cast<int>(ProfileError::kReflectorOverlap), add(1, 0.15, 0.25));
  CHECK_EQUAL(1u, p.reflector_count);
  // A file's millimetre rounding past the end is cut at the end, more is refused.
  CHECK_EQUAL(static_cast<int>(ProfileError::kOk), add(1, 0.25, 0.3004));
  REAL_EQUAL(0.30, p.reflectors[1].to_m, 1e-6);
  for (int k = 0; k < 6; ++k) CHECK_EQUAL(static_cast<int>(ProfileError::kOk), add(0, 0.015 * k, 0.015 * k + 0.011));
  CHECK_EQUAL(static_cast<int>(ProfileError::kTooManyReflectors), add(2, 0.0, 0.05));
  CHECK_EQUAL(8u, p.reflector_count);
}

TEST(Profile, MountKindNamesRoundTripAndOthersAreRefused) {
  const DockMountKind kinds[] = {DockMountKind::kUnknown, DockMountKind::kWall, DockMountKind::kFreeStanding};
  for (const DockMountKind k : kinds) {
    DockMountKind out = k == DockMountKind::kWall ? DockMountKind::kUnknown : DockMountKind::kWall;
    CHECK(parse_mount_kind(to_string(k), &out));
    CHECK(out == k);
  }
  STRCMP_EQUAL("free_standing", to_string(DockMountKind::kFreeStanding));
  // Whole names only, and a refusal leaves the output alone.
  DockMountKind out = DockMountKind::kWall;
  for (const char* bad : {"floor", "wal", "walls", "Wall", "", "free standing"}) {
    CHECK_FALSE(parse_mount_kind(bad, &out));
    CHECK(out == DockMountKind::kWall);
  }
  CHECK_FALSE(parse_mount_kind(nullptr, &out));
  CHECK_FALSE(parse_mount_kind("wall", nullptr));
  STRCMP_EQUAL("unknown", to_string(static_cast<DockMountKind>(7)));
}

TEST(Profile, MountingBoundsAreChecked) {
  const DockMounting def;
  CHECK(mounting_valid(def));
  for (const DockMountKind k : {DockMountKind::kUnknown, DockMountKind::kWall, DockMountKind::kFreeStanding}) {
    DockMounting m;
    m.kind = k;
    CHECK(mounting_valid(m));
  }
  DockMounting m;
  m.kind = static_cast<DockMountKind>(7);
  CHECK_FALSE(mounting_valid(m));
  // The gap range: ordered, within [0, kMaxWallGapM], finite; equal ends and the largest gap are allowed.
  const Real inf = std::numeric_limits<Real>::infinity();
  const Real nan = std::numeric_limits<Real>::quiet_NaN();
  const Real ok[][2] = {{0, 0}, {static_cast<Real>(0.05), static_cast<Real>(0.05)}, {0, kMaxWallGapM}};
  for (const auto& r : ok) {
    m = DockMounting{};
    m.kind = DockMountKind::kWall;
    m.wall_gap_min_m = r[0];
    m.wall_gap_max_m = r[1];
    CHECK(mounting_valid(m));
  }
  const Real bad[][2] = {{static_cast<Real>(-0.01), static_cast<Real>(0.05)},
                         {static_cast<Real>(0.06), static_cast<Real>(0.05)},
                         {0, kMaxWallGapM + static_cast<Real>(0.01)},
                         {nan, static_cast<Real>(0.05)},
                         {0, nan},
                         {0, inf},
                         {-inf, 0}};
  for (const auto& r : bad) {
    m = DockMounting{};
    m.kind = DockMountKind::kWall;
    m.wall_gap_min_m = r[0];
    m.wall_gap_max_m = r[1];
    CHECK_FALSE(mounting_valid(m));
  }
}
