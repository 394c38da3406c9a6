#include "dockcore/perception/profile_check.hpp"

#include <cmath>
#include <cstdio>

#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;

namespace {

Real r(double v) {
  return static_cast<Real>(v);
}

DockProfile make(const Vec2* v, std::size_t n, const char* name) {
  DockProfile p;
  CHECK_EQUAL(static_cast<int>(ProfileError::kOk), static_cast<int>(make_profile(v, n, 0, name, p)));
  return p;
}

ProfileCheck check_ld06(const DockProfile& p) {
  const ProfileCheck c = check_profile(p, kProfileCheckDefaultBeamSpacingRad, kProfileCheckDefaultRangeM);
  std::printf(
      "\n  %-12s %-18s component %-4s ratio %.3g weak (%.2f %.2f %.2f) lever %.3f m beams %zu width %.3f/%.3f m",
      p.name, to_string(c.reason), to_string(c.component), static_cast<double>(c.eigen_ratio),
      static_cast<double>(c.weak_direction.x()), static_cast<double>(c.weak_direction.y()),
      static_cast<double>(c.weak_direction.z()), static_cast<double>(c.lever_m), c.beams,
      static_cast<double>(c.width_m), static_cast<double>(c.min_width_m));
  return c;
}

/// An arc of radius radius_m through `n` points from -half_angle to +half_angle, seen from +x (the outward side).
/// centre_x_m places the circle's centre on the x axis.
DockProfile arc(Real radius_m, Real half_angle_rad, Real centre_x_m, std::size_t n) {
  Vec2 v[kMaxProfileVertices];
  for (std::size_t i = 0; i < n; ++i) {
    const Real a = -half_angle_rad + 2 * half_angle_rad * static_cast<Real>(i) / static_cast<Real>(n - 1);
    v[i] = Vec2(centre_x_m + radius_m * std::cos(a), radius_m * std::sin(a));
  }
  return make(v, n, "arc");
}

}  // namespace

TEST_GROUP(ProfileCheck){};

TEST(ProfileCheck, BuiltinsPassWithLd06At2500mm) {
  for (std::size_t i = 0; kBuiltinProfileNames[i] != nullptr; ++i) {
    DockProfile p;
    CHECK_EQUAL(static_cast<int>(ProfileError::kOk), static_cast<int>(builtin_profile(kBuiltinProfileNames[i], p)));
    const ProfileCheck c = check_ld06(p);
    STRCMP_EQUAL("ok", to_string(c.reason));
    CHECK(c.eigen_ratio >= kProfileCheckMinEigenRatio);
    CHECK(c.beams > 20);
  }
}

TEST(ProfileCheck, FlatPlateCannotFixY) {
  const Vec2 v[] = {Vec2(0, r(-0.2)), Vec2(0, r(0.2))};
  const ProfileCheck c = check_ld06(make(v, 2, "plate"));
  STRCMP_EQUAL("ambiguous", to_string(c.reason));
  STRCMP_EQUAL("y", to_string(c.component));
  CHECK(c.eigen_ratio < kProfileCheckMinEigenRatio);
}

TEST(ProfileCheck, PlateDrawnAsSeveralCollinearSegmentsIsStillOnePlate) {
  const Vec2 v[] = {Vec2(0, r(-0.2)), Vec2(0, r(-0.05)), Vec2(0, r(0.05)), Vec2(0, r(0.2))};
  const ProfileCheck c = check_ld06(make(v, 4, "plate3"));
  STRCMP_EQUAL("ambiguous", to_string(c.reason));
  STRCMP_EQUAL("y", to_string(c.component));
}

TEST(ProfileCheck, ArcAboutTheContactsCannotFixYaw) {
  // Every normal passes through the dock origin: turning about it changes no residual.
  const ProfileCheck c = check_ld06(arc(r(0.25), r(0.6), 0, kMaxProfileVertices));
  STRCMP_EQUAL("ambiguous", to_string(c.reason));
  STRCMP_EQUAL("yaw", to_string(c.component));
}

TEST(ProfileCheck, ConvexArcInFrontOfItsCentreFixesEverythingButOneMotion) {
  // The same arc with its centre 0.25 m behind the contacts: the unobservable motion is the turn about that centre,
  // a mix of y and yaw; it is still refused.
  const ProfileCheck c = check_ld06(arc(r(0.25), r(0.6), r(-0.25), kMaxProfileVertices));
  STRCMP_EQUAL("ambiguous", to_string(c.reason));
  CHECK(c.component == PoseComponent::kY || c.component == PoseComponent::kYaw);
}

TEST(ProfileCheck, WingedPlateFixesEverything) {
  // plate-v without its 45° wings is a plate; a 90° return on each side is enough too.
  const Vec2 v[] = {Vec2(r(-0.1), r(-0.2)), Vec2(0, r(-0.2)), Vec2(0, r(0.2)), Vec2(r(-0.1), r(0.2))};
  const ProfileCheck c = check_ld06(make(v, 4, "boxed"));
  STRCMP_EQUAL("ok", to_string(c.reason));
}

TEST(ProfileCheck, SelfIntersectingIsRefused) {
  // A Z whose last segment crosses the first.
  const Vec2 v[] = {Vec2(0, r(-0.15)), Vec2(0, r(0.15)), Vec2(r(-0.1), r(0.15)), Vec2(r(0.05), 0)};
  const ProfileCheck c = check_ld06(make(v, 4, "crossing"));
  STRCMP_EQUAL("self-intersecting", to_string(c.reason));
  CHECK_EQUAL(0u, c.segment_a);
  CHECK_EQUAL(2u, c.segment_b);
}

TEST(ProfileCheck, TouchingAndFoldingBackAreSelfIntersecting) {
  // The last vertex lands on the first segment.
  const Vec2 touch[] = {Vec2(0, r(-0.15)), Vec2(0, r(0.15)), Vec2(r(-0.1), r(0.15)), Vec2(r(-0.1), 0), Vec2(0, 0)};
  const ProfileCheck t = check_ld06(make(touch, 5, "touching"));
  STRCMP_EQUAL("self-intersecting", to_string(t.reason));
  CHECK_EQUAL(0u, t.segment_a);
  CHECK_EQUAL(3u, t.segment_b);
  // A spike: the second segment runs back along the first.
  const Vec2 fold[] = {Vec2(0, r(-0.15)), Vec2(0, r(0.15)), Vec2(0, r(0.05)), Vec2(r(-0.1), r(0.2))};
  const ProfileCheck f = check_ld06(make(fold, 4, "fold"));
  STRCMP_EQUAL("self-intersecting", to_string(f.reason));
  CHECK_EQUAL(0u, f.segment_a);
  CHECK_EQUAL(1u, f.segment_b);
}

TEST(ProfileCheck, FiveCentimetreDockAt2500mmWithLd06IsTooSmall) {
  // 0.8° at 2.5 m is 34.9 mm between beams: 3 beams need 69.8 mm.
  DockProfile p;
  CHECK_EQUAL(static_cast<int>(ProfileError::kOk), static_cast<int>(builtin_profile("v-marker", p)));
  for (std::size_t i = 0; i < p.vertex_count; ++i) p.vertices_m[i] *= r(0.05 / 0.30);
  const ProfileCheck c = check_ld06(p);
  STRCMP_EQUAL("too small", to_string(c.reason));
  STRCMP_EQUAL("none", to_string(c.component));
  REAL_EQUAL(0.05, c.width_m, 1e-9);
  DOUBLES_EQUAL(2 * 2.5 * 0.8 * 3.14159265358979 / 180, static_cast<double>(c.min_width_m), 1e-6);
  // The same dock passes at 1 m, where 3 beams need 27.9 mm.
  const ProfileCheck near = check_profile(p, kProfileCheckDefaultBeamSpacingRad, 1);
  STRCMP_EQUAL("ok", to_string(near.reason));
}

TEST(ProfileCheck, WideDockWhoseOnlyYFeaturesAreTinyIsTooSmallInY) {
  // A 0.4 m plate with 40 mm wings at 45°: seen from 1 m the wings fix y, but at 2.5 m each holds at most 2 beams.
  const Real w = r(0.04 * 0.70710678118654752);
  const Vec2 v[] = {Vec2(-w, r(-0.2) - w), Vec2(0, r(-0.2)), Vec2(0, r(0.2)), Vec2(-w, r(0.2) + w)};
  const DockProfile p = make(v, 4, "small-wings");
  const ProfileCheck c = check_ld06(p);
  STRCMP_EQUAL("too small", to_string(c.reason));
  STRCMP_EQUAL("y", to_string(c.component));
  REAL_EQUAL(0.04, c.width_m, 1e-6);
  // At 1.2 m the wings hold 3 beams (33.5 mm needed).
  STRCMP_EQUAL("ok", to_string(check_profile(p, kProfileCheckDefaultBeamSpacingRad, r(1.2)).reason));
}

TEST(ProfileCheck, FacingAwayIsNotVisible) {
  // A plate drawn from +y to -y: its outward normal points at -x, away from the viewpoints.
  const Vec2 v[] = {Vec2(0, r(0.2)), Vec2(0, r(-0.2))};
  STRCMP_EQUAL("not visible from the front", to_string(check_ld06(make(v, 2, "backwards")).reason));
}

TEST(ProfileCheck, BadArgumentsAreRefused) {
  DockProfile p;
  CHECK_EQUAL(static_cast<int>(ProfileError::kOk), static_cast<int>(builtin_profile("plate-v", p)));
  STRCMP_EQUAL("bad arguments", to_string(check_profile(p, 0, 2).reason));
  STRCMP_EQUAL("bad arguments", to_string(check_profile(p, r(0.01), std::nan("")).reason));
  STRCMP_EQUAL("bad arguments", to_string(check_profile(DockProfile{}, r(0.01), 2).reason));
}

TEST(ProfileCheck, FinerLidarSameVerdictAndRatio) {
  // The ratio depends on where beams land, not how many: 0.8° and 0.1° (capped spreading) agree within 10 %.
  DockProfile p;
  CHECK_EQUAL(static_cast<int>(ProfileError::kOk), static_cast<int>(builtin_profile("plate-v", p)));
  const ProfileCheck coarse = check_profile(p, kProfileCheckDefaultBeamSpacingRad, 2);
  const ProfileCheck fine = check_profile(p, deg_to_rad(r(0.01)), 2);
  STRCMP_EQUAL("ok", to_string(fine.reason));
  CHECK(fine.beams > coarse.beams);
  DOUBLES_EQUAL(static_cast<double>(coarse.eigen_ratio), static_cast<double>(fine.eigen_ratio),
                0.1 * static_cast<double>(coarse.eigen_ratio));
}
