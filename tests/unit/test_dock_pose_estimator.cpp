// DockPoseEstimator on its own: refusals of scans without returns or with a bad beam geometry, and the placed-profile
// queries (ray cast, nearest segment, angular span) against the plain formulas at seeded random poses. The estimator
// on the simulator's scenes is test_dock_pose_estimator_scenes.
#include <cmath>

#include "dockcore/perception/dock_pose_estimator.hpp"
#include "docksim/rng.hpp"

#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;

namespace {

// Large objects live outside the test functions (the estimator holds ~100 kB of buffers).
DockPoseEstimator g_est;
LaserScan g_scan;

DockProfile profile(const char* name) {
  DockProfile p;
  CHECK_EQUAL(static_cast<int>(ProfileError::kOk), static_cast<int>(builtin_profile(name, p)));
  return p;
}

}  // namespace

TEST_GROUP(DockPoseEstimator){};

TEST(DockPoseEstimator, AllInvalidScanIsNoPoints) {
  g_est.configure(profile("plate-v"), EstimatorParams{});
  g_scan.reset(450, -kPi, deg_to_rad(0.8), 0);
  const DockEstimate e = g_est.estimate(g_scan.view(), Pose2{});
  CHECK_FALSE(e.found);
  CHECK_EQUAL(static_cast<int>(EstimateStatus::kNoPoints), static_cast<int>(e.status));
}

TEST(DockPoseEstimator, BadScanGeometryIsRefusedAndCounted) {
  g_est.configure(profile("plate-v"), EstimatorParams{});
  g_scan.reset(450, -kPi, 0.0, 0);
  const DockEstimate e = g_est.estimate(g_scan.view(), Pose2{});
  CHECK_EQUAL(static_cast<int>(EstimateStatus::kBadScan), static_cast<int>(e.status));
  CHECK_EQUAL(1u, g_est.counters().bad_scans);
}

TEST(DockPoseEstimator, HintOnEmptyScanIsStillNoPoints) {
  // The hint is refined before the returns are counted; a scan without returns must still say so and count no
  // candidate.
  const DockProfile prof = profile("plate-v");
  g_est.configure(prof, EstimatorParams{});
  g_scan.reset(450, -kPi, deg_to_rad(0.8), 0);
  const Pose2 hint = dockcore_test::pose(1.0, 0.0, kPi);
  const DockEstimate e = g_est.estimate(g_scan.view(), Pose2{}, &hint);
  CHECK_EQUAL(static_cast<int>(EstimateStatus::kNoPoints), static_cast<int>(e.status));
  CHECK_EQUAL(0u, g_est.counters().candidates);
}

TEST(DockPoseEstimator, ScatteredReturnsAreNoCandidates) {
  // Isolated returns, one every 10th beam at ranges that jump about: points, but no line a profile could match.
  g_est.configure(profile("plate-v"), EstimatorParams{});
  g_scan.reset(450, -kPi, deg_to_rad(0.8), 0);
  for (std::size_t i = 0; i < 450; i += 10) {
    g_scan.ranges_m[i] = static_cast<Real>(1.0 + 0.7 * static_cast<double>(i % 3));
  }
  const DockEstimate e = g_est.estimate(g_scan.view(), Pose2{});
  CHECK_FALSE(e.found);
  CHECK_EQUAL(static_cast<int>(EstimateStatus::kNoCandidates), static_cast<int>(e.status));
}

namespace {

// Fills g_scan (count beams from angle_min_rad, 0.8° apart) with the noise-free returns of `prof` placed at `dock`.
void cast_dock(const DockProfile& prof, const Pose2& dock, std::size_t count, Real angle_min_rad) {
  static PlacedProfile pp;
  pp.place(prof, dock);
  g_scan.reset(count, angle_min_rad, deg_to_rad(0.8), 0);
  for (std::size_t i = 0; i < count; ++i) {
    const Real a = g_scan.view().angle_rad(i);
    Real r = 0;
    std::size_t seg = 0;
    if (pp.raycast(Vec2(std::cos(a), std::sin(a)), &r, &seg)) g_scan.ranges_m[i] = r;
  }
}

void check_found_at(const DockEstimate& e, const Pose2& truth) {
  CHECK_TRUE(e.found);
  DOUBLES_EQUAL(truth.x_m, e.pose.x_m, 0.005);
  DOUBLES_EQUAL(truth.y_m, e.pose.y_m, 0.005);
  DOUBLES_EQUAL(0.0, wrap_angle(e.pose.yaw_rad - truth.yaw_rad), 0.01);
}

}  // namespace

TEST(DockPoseEstimator, CovarianceAboveTheLimitIsRefusedAsUncertain) {
  // A plate-v 1 m ahead, its returns cast on core's own placed profile (no noise, no wall): found with the default
  // limit on the position 1-σ, refused as uncertain (and counted) when the limit is far below the range noise.
  const DockProfile prof = profile("plate-v");
  cast_dock(prof, dockcore_test::pose(1.0, 0.05, kPi - 0.1), 450, -kPi);
  // A round room behind the lidar, 2.5 m out: returns enough for the scan to pass the floor, none of them the dock.
  for (std::size_t i = 0; i < 100; ++i) g_scan.ranges_m[i] = static_cast<Real>(2.5);
  g_est.configure(prof, EstimatorParams{});
  const DockEstimate ok = g_est.estimate(g_scan.view(), Pose2{});
  CHECK_TRUE(ok.found);
  EstimatorParams tight;
  tight.max_sigma_m = static_cast<Real>(1e-6);
  g_est.configure(prof, tight);
  const DockEstimate e = g_est.estimate(g_scan.view(), Pose2{});
  CHECK_FALSE(e.found);
  CHECK_EQUAL(static_cast<int>(EstimateStatus::kNotVerified), static_cast<int>(e.status));
  CHECK_EQUAL(static_cast<int>(RejectReason::kUncertain), static_cast<int>(e.reject));
  CHECK_EQUAL(1u, g_est.counters().rejected_by[static_cast<std::size_t>(RejectReason::kUncertain)]);
}

TEST(DockPoseEstimator, ADocksOwnFloorOnInliersReplacesTheParameters) {
  // The same plate-v scan (noise-free, 1 m ahead): found with the parameters' floor; a profile stating a floor one
  // above the inliers it gets is refused for too few inliers, whatever the parameters say. The built-ins bring 6.
  DockProfile prof = profile("plate-v");
  CHECK_EQUAL(6, prof.min_inliers);
  CHECK_EQUAL(6, profile("v-marker").min_inliers);
  CHECK_EQUAL(6, profile("breakpoint").min_inliers);
  cast_dock(prof, dockcore_test::pose(1.0, 0.05, kPi - 0.1), 450, -kPi);
  // A round room behind the lidar, 2.5 m out: returns enough for the scan to pass the floor, none of them the dock.
  for (std::size_t i = 0; i < 100; ++i) g_scan.ranges_m[i] = static_cast<Real>(2.5);
  g_est.configure(prof, EstimatorParams{});
  const DockEstimate ok = g_est.estimate(g_scan.view(), Pose2{});
  CHECK_TRUE(ok.found);
  prof.min_inliers = static_cast<std::uint16_t>(ok.inliers + 1);
  g_est.configure(prof, EstimatorParams{});
  const DockEstimate e = g_est.estimate(g_scan.view(), Pose2{});
  CHECK_FALSE(e.found);
  CHECK_EQUAL(static_cast<int>(RejectReason::kTooFewInliers), static_cast<int>(e.reject));
  // With reflector stripes the profile's floor is not used (its code needs the parameters' floor of beams); read by
  // geometry alone here, the same scan is found again.
  ReflectorStripe stripe;
  stripe.segment = 1;
  stripe.from_m = static_cast<Real>(0.10);
  stripe.to_m = static_cast<Real>(0.20);
  CHECK_EQUAL(static_cast<int>(ProfileError::kOk), static_cast<int>(add_reflector(prof, stripe)));
  g_est.configure(prof, EstimatorParams{});
  g_est.set_intensity_usable(false);
  CHECK_TRUE(g_est.estimate(g_scan.view(), Pose2{}).found);
}

namespace {

// Puts a return at the dock-frame point (x_m, y_m) of `dock` on the beam of g_scan nearest its bearing (0.8° beams
// from -π, as cast_dock lays them). Returns the beam's index.
std::size_t put_return(const Pose2& dock, Real x_m, Real y_m) {
  const Vec2 p = dock.transform(Vec2(x_m, y_m));
  const Real a = std::atan2(p.y(), p.x());
  const auto i = static_cast<std::size_t>(std::lround((a + kPi) / deg_to_rad(0.8)));
  g_scan.ranges_m[i] = p.norm();
  return i;
}

}  // namespace

TEST(DockPoseEstimator, AReturnRightBesideTheDocksEndCountsAgainstIt) {
  // A noise-free plate-v 1 m ahead, tracked from its own pose: nothing past its ends, no edges cue. Something right
  // beside the end of its face (5 cm in front of the face's line, 7-9 cm past its end) counts against the dock
  // (`stops`, the edges cue); the same thing 30 cm in front of the line is the room, and counts for nothing.
  const DockProfile prof = profile("plate-v");
  const Pose2 dock = dockcore_test::pose(1.0, 0.0, kPi);
  g_est.configure(prof, EstimatorParams{});
  cast_dock(prof, dock, 450, -kPi);
  const DockEstimate clean = g_est.estimate(g_scan.view(), Pose2{}, &dock);
  check_found_at(clean, dock);
  DOUBLES_EQUAL(0.0, clean.evidence.features.stops, 1e-9);
  const std::size_t edges = static_cast<std::size_t>(EvidenceCue::kEdges);
  DOUBLES_EQUAL(0.0, clean.evidence.cue_nats[edges], 1e-9);

  // Two beams' worth: at 1 m a beam covers 1.4 cm, so it stands for under a third of the 5 cm correlation length.
  CHECK_TRUE(put_return(dock, static_cast<Real>(0.05), static_cast<Real>(0.215)) !=
             put_return(dock, static_cast<Real>(0.05), static_cast<Real>(0.235)));
  const DockEstimate beside = g_est.estimate(g_scan.view(), Pose2{}, &dock);
  CHECK_TRUE(beside.evidence.features.stops > 0);
  CHECK_TRUE(beside.evidence.cue_nats[edges] < -1);
  CHECK_TRUE(beside.evidence.total_nats < clean.evidence.total_nats - 1);

  cast_dock(prof, dock, 450, -kPi);
  put_return(dock, static_cast<Real>(0.30), static_cast<Real>(0.215));
  put_return(dock, static_cast<Real>(0.30), static_cast<Real>(0.235));
  const DockEstimate room = g_est.estimate(g_scan.view(), Pose2{}, &dock);
  check_found_at(room, dock);
  DOUBLES_EQUAL(0.0, room.evidence.features.stops, 1e-9);
  DOUBLES_EQUAL(clean.evidence.total_nats, room.evidence.total_nats, 1e-9);
}

TEST(DockPoseEstimator, GlobalSearchFindsADockAcrossTheWrapOfAFullTurn) {
  // Behind the lidar: the dock's beams are the scan's last and first, and registration's span runs across the wrap.
  const DockProfile prof = profile("plate-v");
  const Pose2 dock = dockcore_test::pose(-1.0, 0.02, 0.1);
  cast_dock(prof, dock, 450, -kPi);
  CHECK_TRUE(g_scan.view().wraps());
  g_est.configure(prof, EstimatorParams{});
  check_found_at(g_est.estimate(g_scan.view(), Pose2{}), dock);
}

TEST(DockPoseEstimator, GlobalSearchFindsADockNearEitherEndOfAPartialScan) {
  // A 180° scan with the dock just inside either end: the spans registration and verification look at (the dock
  // plus a margin) reach past the scan's ends, where there are no beams.
  const DockProfile prof = profile("plate-v");
  for (const Real bearing_deg : {-75.0, 75.0}) {
    const Real b = deg_to_rad(bearing_deg);
    const Pose2 dock = dockcore_test::pose(std::cos(b), std::sin(b), b + kPi);
    cast_dock(prof, dock, 225, -kPi / 2);
    CHECK_FALSE(g_scan.view().wraps());
    g_est.configure(prof, EstimatorParams{});
    check_found_at(g_est.estimate(g_scan.view(), Pose2{}), dock);
  }
}

namespace {

// The plain formulas the fast PlacedProfile queries must agree with: a division per segment, no precomputation.
bool reference_raycast(const PlacedProfile& pp, const Vec2& dir, Real* range_m, std::size_t* segment) {
  bool hit = false;
  for (std::size_t i = 0; i < pp.segments; ++i) {
    if (!pp.visible[i]) continue;
    const Real denom = pp.n[i].dot(dir);
    if (denom >= 0) continue;
    const Real t = pp.c_m[i] / denom;
    const Vec2 d = pp.v_m[i + 1] - pp.v_m[i];
    const Real u = (t * dir - pp.v_m[i]).dot(d) / d.squaredNorm();
    if (t <= 0 || u < 0 || u > 1) continue;
    if (!hit || t < *range_m) {
      hit = true;
      *range_m = t;
      *segment = i;
    }
  }
  return hit;
}

Real reference_distance(const PlacedProfile& pp, const Vec2& p, std::size_t i) {
  const Vec2 d = pp.v_m[i + 1] - pp.v_m[i];
  Real u = (p - pp.v_m[i]).dot(d) / d.squaredNorm();
  u = u < 0 ? 0 : (u > 1 ? 1 : u);
  return (p - pp.v_m[i] - u * d).norm();
}

// The angular span as every vertex's bearing relative to the first gives it (one arctangent each).
void check_angular_span(const PlacedProfile& pp, double tol) {
  const Vec2& a = pp.v_m[0];
  Real lo_ref = 0;
  Real hi_ref = 0;
  for (std::size_t i = 1; i <= pp.segments; ++i) {
    const Vec2& b = pp.v_m[i];
    const Real rel = std::atan2(a.x() * b.y() - a.y() * b.x(), a.x() * b.x() + a.y() * b.y());
    lo_ref = std::fmin(lo_ref, rel);
    hi_ref = std::fmax(hi_ref, rel);
  }
  const Real ref = std::atan2(a.y(), a.x());
  Real lo = 0;
  Real hi = 0;
  pp.angular_span(&lo, &hi);
  DOUBLES_EQUAL(ref + lo_ref, lo, tol);
  DOUBLES_EQUAL(ref + hi_ref, hi, tol);
}

}  // namespace

TEST(DockPoseEstimator, AngularSpanAgreesWithEveryVertexBearing) {
  // Far poses take the two-arctangent path; poses with the sensor at or inside the dock's outline (vertices more
  // than 90 degrees apart as seen from it) take the per-vertex one. Both must give the plain answer.
  docksim::Rng rng(12);
  auto uniform = [&rng](double lo, double hi) { return static_cast<Real>(rng.uniform(lo, hi)); };
  const double tol = dockcore_test::real_tol(1.0, 1e-12, 16);
  static PlacedProfile pp;
  for (const char* name : {"plate-v", "v-marker", "breakpoint"}) {
    const DockProfile prof = profile(name);
    for (int trial = 0; trial < 500; ++trial) {
      const Real d = trial % 2 == 0 ? uniform(0.3, 3.0) : uniform(0.0, 0.15);
      const Real bearing = uniform(-kPi, kPi);
      pp.place(prof, Pose2{d * std::cos(bearing), d * std::sin(bearing), uniform(-kPi, kPi)});
      check_angular_span(pp, tol);
    }
  }
}

TEST(DockPoseEstimator, PlacedProfileQueriesAgreeWithThePlainFormulas) {
  // Every built-in profile at many poses: the side-test ray cast, the division-free nearest segment, and the
  // "projects well inside" shortcut the registration takes (the shortcut's segment is a nearest one), against the
  // plain formulas. Rays within 1e-4 rad of a
  // vertex are left out: there hit or miss is a matter of rounding in either formula.
  docksim::Rng rng(11);
  auto uniform = [&rng](double lo, double hi) { return static_cast<Real>(rng.uniform(lo, hi)); };
  const double tol = dockcore_test::real_tol(1.0, 1e-9, 64);  // a few roundings on metre-sized values
  static PlacedProfile pp;
  int rays = 0;
  int shortcuts = 0;
  for (const char* name : {"plate-v", "v-marker", "breakpoint"}) {
    const DockProfile prof = profile(name);
    for (int trial = 0; trial < 200; ++trial) {
      const Pose2 pose{uniform(0.3, 2.0), uniform(-1.0, 1.0), uniform(-kPi, kPi)};
      pp.place(prof, pose);
      // The shortcut's bound per segment, found independently: 0.45 of the least distance from sampled points of the
      // segments it does not join (every built-in profile turns by 90° or less at its joints).
      Real max_line[kMaxProfileVertices];
      for (std::size_t i = 0; i < pp.segments; ++i) {
        Real clearance = 1e9;
        for (std::size_t j = 0; j < pp.segments; ++j) {
          if (j + 1 >= i && j <= i + 1) continue;
          for (int q = 0; q <= 200; ++q) {
            const Vec2 sample = pp.v_m[j] + static_cast<Real>(q / 200.0) * (pp.v_m[j + 1] - pp.v_m[j]);
            clearance = std::fmin(clearance, reference_distance(pp, sample, i));
          }
        }
        max_line[i] = static_cast<Real>(0.45) * clearance;
      }
      check_angular_span(pp, tol);
      const Real bearing = std::atan2(pose.y_m, pose.x_m);
      for (int k = 0; k < 40; ++k) {
        const Real a = bearing + uniform(-0.4, 0.4);
        const Vec2 dir(std::cos(a), std::sin(a));
        bool near_vertex = false;
        for (std::size_t v = 0; v <= pp.segments; ++v) {
          const Vec2& q = pp.v_m[v];
          near_vertex = near_vertex || std::fabs(dir.x() * q.y() - dir.y() * q.x()) < 1e-4 * q.norm();
        }
        Real r_fast = 0;
        Real r_ref = 0;
        std::size_t s_fast = 0;
        std::size_t s_ref = 0;
        const bool h_fast = pp.raycast(dir, &r_fast, &s_fast);
        const bool h_ref = reference_raycast(pp, dir, &r_ref, &s_ref);
        if (!near_vertex) {
          CHECK_EQUAL(h_ref, h_fast);
          if (h_ref) {
            ++rays;
            DOUBLES_EQUAL(r_ref, r_fast, tol);
          }
        }
        // A point near the dock (up to 5 cm off its surfaces).
        const Real r = h_ref ? r_ref : std::sqrt(pose.x_m * pose.x_m + pose.y_m * pose.y_m);
        const Vec2 p = r * dir + Vec2(uniform(-0.05, 0.05), uniform(-0.05, 0.05));
        std::size_t seg = 0;
        Real dist = 0;
        Real line = 0;
        Real over = 0;
        if (!pp.nearest(p, &seg, &dist, &line, &over)) continue;
        Real best = 1e9;
        for (std::size_t i = 0; i < pp.segments; ++i) {
          if (pp.visible[i]) best = std::fmin(best, reference_distance(pp, p, i));
        }
        DOUBLES_EQUAL(best, dist, tol);
        for (std::size_t i = 0; i < pp.segments; ++i) {
          Real e = 0;
          if (!pp.visible[i] || !pp.projects_well_inside(p, i, max_line[i], &e)) continue;
          ++shortcuts;
          // The shortcut's segment is a nearest one and its line distance is the distance.
          DOUBLES_EQUAL(best, std::fabs(e), tol);
        }
      }
    }
  }
  CHECK_TRUE(rays > 1000);
  CHECK_TRUE(shortcuts > 1000);
}
