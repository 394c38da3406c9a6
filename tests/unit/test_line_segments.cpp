#include <cmath>
#include <cstdio>
#include <cstring>

#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/line_segments.hpp"
#include "docksim/rng.hpp"

#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;

namespace {

constexpr Real kLd06Inc = static_cast<Real>(0.8 * 3.14159265358979323846 / 180.0);
constexpr std::size_t kLd06Beams = 450;  // 450 x 0.8° = 360°

struct Wall {
  Vec2 a;
  Vec2 b;
};

/// Nearest hit of the ray from the origin along `dir` with any wall; false if none.
bool ray_hit(const Wall* walls, std::size_t count, const Vec2& dir, Real* range_out) {
  bool hit = false;
  Real best = 0;
  for (std::size_t w = 0; w < count; ++w) {
    const Vec2 ab = walls[w].b - walls[w].a;
    // origin + t·dir = a + s·ab  ->  t·dir - s·ab = a
    const Real det = -dir.x() * ab.y() + dir.y() * ab.x();
    if (std::fabs(det) < 1e-12) continue;
    const Vec2 a = walls[w].a;
    const Real t = (-a.x() * ab.y() + a.y() * ab.x()) / det;
    const Real s = (dir.x() * a.y() - dir.y() * a.x()) / det;
    if (t <= 0 || s < 0 || s > 1) continue;
    if (!hit || t < best) {
      best = t;
      hit = true;
    }
  }
  *range_out = best;
  return hit;
}

/// Ray-casts the walls from the origin (lidar frame) into `scan`, with Gaussian range noise sigma_m.
void cast_scan(const Wall* walls, std::size_t count, Real angle_min, Real inc, std::size_t beams, Real sigma_m,
               docksim::Rng* rng, LaserScan& scan) {
  scan.reset(beams, angle_min, inc, 0);
  for (std::size_t i = 0; i < beams; ++i) {
    const Real a = scan.view().angle_rad(i);
    Real r = 0;
    if (ray_hit(walls, count, Vec2(std::cos(a), std::sin(a)), &r)) {
      if (rng != nullptr && sigma_m > 0) r += static_cast<Real>(rng->normal(0.0, static_cast<double>(sigma_m)));
      scan.ranges_m[i] = r;
    }
  }
}

/// Hand-built point set: range and beam angle from the point itself (sensor at the origin).
void push_point(ScanPoints& pts, const Vec2& p) {
  ScanPoint sp;
  sp.p_m = p;
  sp.range_m = p.norm();
  sp.angle_rad = std::atan2(p.y(), p.x());
  sp.index = static_cast<std::uint32_t>(pts.size());
  pts.push_back(sp);
}

/// Expected line: unit normal facing the origin and n·p = offset. Checks both, sign included.
void check_line(const LineSegment& s, const Vec2& normal, Real offset, Real tol_n, Real tol_off) {
  REAL_EQUAL(normal.x(), s.normal.x(), tol_n);
  REAL_EQUAL(normal.y(), s.normal.y(), tol_n);
  REAL_EQUAL(offset, s.offset_m, tol_off);
}

LaserScan g_scan;
ScanPoints g_points;
LineSegments g_segs;

}  // namespace

TEST_GROUP(LineSegments){};

TEST(LineSegments, FitTlsRecoversSteepLine) {
  // x = 1 + 0.01·y is nearly vertical: ordinary least squares in y(x) would fail, TLS must not.
  Vec2 p[5];
  for (int i = 0; i < 5; ++i) {
    const Real y = static_cast<Real>(i) * 0.1 - 0.2;
    p[i] = Vec2(1 + 0.01 * y, y);
  }
  LineFit f;
  CHECK_TRUE(fit_line_tls(p, 5, f));
  const Vec2 expected = Vec2(0.01, 1).normalized();
  REAL_EQUAL(1.0, std::fabs(f.direction.dot(expected)), 1e-12);
  REAL_EQUAL(0.0, f.rms_m, 1e-9);
  REAL_EQUAL(1.0, f.centroid_m.x(), 1e-12);
  CHECK_FALSE(fit_line_tls(p, 1, f));
  const Vec2 same[3] = {Vec2(1, 1), Vec2(1, 1), Vec2(1, 1)};
  CHECK_FALSE(fit_line_tls(same, 3, f));
}

TEST(LineSegments, StraightWallGivesOneSegmentWithItsLine) {
  const Wall walls[] = {{Vec2(2, -1), Vec2(2, 1)}};
  cast_scan(walls, 1, -kPi, kLd06Inc, kLd06Beams, 0, nullptr, g_scan);
  scan_to_points(g_scan.view(), Pose2{}, 0.05, 12.0, g_points);
  // Beams hitting x = 2 for |y| <= 1: |tan a| <= 0.5.
  std::size_t expected_hits = 0;
  for (std::size_t i = 0; i < kLd06Beams; ++i) {
    const Real a = g_scan.view().angle_rad(i);
    if (std::cos(a) > 0 && std::fabs(std::tan(a)) <= 0.5) ++expected_hits;
  }
  CHECK_EQUAL(expected_hits, g_points.size());
  const SegmentStats st = extract_line_segments(g_points, g_scan.view(), SegmentParams{}, g_segs);
  CHECK_FALSE(st.truncated());
  LONGS_EQUAL(1, g_segs.size());
  const LineSegment& s = g_segs[0];
  // Normal faces the sensor: (-1, 0); line -x = -2.
  check_line(s, Vec2(-1, 0), -2, 1e-9, 1e-9);
  REAL_EQUAL(0.0, s.rms_m, 1e-9);
  LONGS_EQUAL(expected_hits, s.point_count);
  LONGS_EQUAL(0, s.first);
  LONGS_EQUAL(expected_hits - 1, s.last);
  // Ends: the first and last hits, which lie within one beam step (2·0.014/cos² ~ 0.035 m) of the wall's ends.
  REAL_EQUAL(2.0, s.start_m.x(), 1e-9);
  // Range 2/cos(a), then r·sin(a), each rounded to Real: a few roundings at magnitude 2.
  DOUBLES_EQUAL(2.0 * std::tan(g_points[0].angle_rad), s.start_m.y(), dockcore_test::real_tol(2.0, 1e-9, 16));
  CHECK(s.start_m.y() < -0.96 && s.end_m.y() > 0.96);
  // The beams are symmetric about 0 (in float only to the rounding of angle_min + i·increment).
  DOUBLES_EQUAL(-s.start_m.y(), s.end_m.y(), dockcore_test::real_tol(2.0, 1e-9, 16));
  REAL_EQUAL(s.signed_distance_m(Vec2(0, 0)), 2.0, 1e-9);
}

TEST(LineSegments, ConcaveLCornerGivesTwoSegments) {
  // Walls x = 2 (y in [-1, 1]) and y = 1 (x in [0.5, 2]), meeting at (2, 1).
  const Wall walls[] = {{Vec2(2, -1), Vec2(2, 1)}, {Vec2(2, 1), Vec2(0.5, 1)}};
  cast_scan(walls, 2, -kPi, kLd06Inc, kLd06Beams, 0, nullptr, g_scan);
  scan_to_points(g_scan.view(), Pose2{}, 0.05, 12.0, g_points);
  extract_line_segments(g_points, g_scan.view(), SegmentParams{}, g_segs);
  LONGS_EQUAL(2, g_segs.size());
  check_line(g_segs[0], Vec2(-1, 0), -2, 1e-6, 1e-6);
  check_line(g_segs[1], Vec2(0, -1), -1, 1e-6, 1e-6);
  CHECK_EQUAL(g_segs[0].cluster, g_segs[1].cluster);
  // The corner: wall 1 ends at the last beam below atan2(1, 2), wall 2 starts at the first beam above it — each
  // corner sample goes to its own wall (wall 2's first point is ~7 cm from the corner: 63° incidence).
  const Real corner_a = std::atan2(1.0, 2.0);
  Real a_below = -kPi;
  Real a_above = kPi;
  for (const ScanPoint& p : g_points) {
    if (p.angle_rad <= corner_a && p.angle_rad > a_below) a_below = p.angle_rad;
    if (p.angle_rad > corner_a && p.angle_rad < a_above) a_above = p.angle_rad;
  }
  REAL_EQUAL(2.0 * std::tan(a_below), g_segs[0].end_m.y(), 1e-6);
  REAL_EQUAL(1.0 / std::tan(a_above), g_segs[1].start_m.x(), 1e-6);
  CHECK(g_segs[0].last + 1 == g_segs[1].first);  // disjoint, nothing skipped
  // Second wall ends at the last hit at or before x = 0.5 (beam angle atan2(1, 0.5)).
  CHECK(std::fabs(g_segs[1].end_m.x() - 0.5) < 0.02);
  REAL_EQUAL(0.0, g_segs[0].rms_m, 1e-9);
  REAL_EQUAL(0.0, g_segs[1].rms_m, 1e-9);
}

TEST(LineSegments, NoisyLineRmsMatchesSigma) {
  // 200 points 1 cm apart along a tilted line 2 m away, Gaussian noise of 10 mm perpendicular to it: one segment
  // (noise spikes may split it, merging must rejoin it), RMS ≈ σ, line parameters within a few σ/sqrt(n).
  docksim::Rng rng(42);
  const Real sigma = 0.010;
  const Vec2 n_true = Vec2(-std::cos(0.3), -std::sin(0.3));  // faces the origin
  const Real offset_true = -2.0;
  const Vec2 t = Vec2(n_true.y(), -n_true.x());  // scan order: counter-clockwise about the origin
  g_points.clear();
  const std::size_t count = 200;
  for (std::size_t i = 0; i < count; ++i) {
    const Real along = -1.0 + 0.01 * static_cast<Real>(i);
    const Vec2 p = n_true * offset_true + t * along + n_true * static_cast<Real>(rng.normal(0.0, sigma));
    push_point(g_points, p);
  }
  const SegmentStats st = extract_line_segments(g_points, 0, false, SegmentParams{}, g_segs);
  LONGS_EQUAL(1, g_segs.size());
  CHECK_FALSE(st.truncated());
  const LineSegment& s = g_segs[0];
  LONGS_EQUAL(count, s.point_count);
  // sqrt(mean square) of 200 samples: relative spread 1/sqrt(2n) = 5%; the fit removes 2 dof.
  REAL_EQUAL(sigma, s.rms_m, 0.15 * sigma);
  // 1σ direction error σ·sqrt(12/n)/L = 1.2 mrad for L = 2 m; offset error σ/sqrt(n) = 0.7 mm. Allow 4σ.
  check_line(s, n_true, offset_true, 0.005, 0.003);
}

TEST(LineSegments, NoisyScanWallIsOneSegment) {
  // A ray-cast scan with LD06 noise (σ = 10 mm in range) on a 4 m wall 1.5 m away: one segment, RMS close to
  // σ·cos(incidence) averaged over the wall (range noise only partly lies across the wall).
  const Wall walls[] = {{Vec2(1.5, -2), Vec2(1.5, 2)}};
  docksim::Rng rng(7);
  cast_scan(walls, 1, -kPi, kLd06Inc, kLd06Beams, 0.010, &rng, g_scan);
  scan_to_points(g_scan.view(), Pose2{}, 0.05, 12.0, g_points);
  extract_line_segments(g_points, g_scan.view(), SegmentParams{}, g_segs);
  LONGS_EQUAL(1, g_segs.size());
  Real mean_sq_cos = 0;
  for (const ScanPoint& p : g_points) mean_sq_cos += std::cos(p.angle_rad) * std::cos(p.angle_rad);
  const Real expected_rms = 0.010 * std::sqrt(mean_sq_cos / static_cast<Real>(g_points.size()));
  REAL_EQUAL(expected_rms, g_segs[0].rms_m, 0.2 * expected_rms);
  check_line(g_segs[0], Vec2(-1, 0), -1.5, 0.01, 0.004);
}

TEST(LineSegments, RangeGapsSplitClusters) {
  // Collinear wall pieces with a 0.3 m doorway (11 beams missing), and a 0.25 m depth step (above 5·r·Δθ = 0.15 m at
  // 2.1 m): three clusters, three segments.
  const Wall walls[] = {{Vec2(2, -1.5), Vec2(2, -0.15)}, {Vec2(2, 0.15), Vec2(2, 0.8)}, {Vec2(2.25, 0.8), Vec2(2.25, 1.6)}};
  cast_scan(walls, 3, -kPi, kLd06Inc, kLd06Beams, 0, nullptr, g_scan);
  scan_to_points(g_scan.view(), Pose2{}, 0.05, 12.0, g_points);
  const SegmentStats st = extract_line_segments(g_points, g_scan.view(), SegmentParams{}, g_segs);
  LONGS_EQUAL(3, g_segs.size());
  LONGS_EQUAL(3, st.clusters);
  CHECK(g_segs[0].cluster != g_segs[1].cluster);
  CHECK(g_segs[1].cluster != g_segs[2].cluster);
  check_line(g_segs[0], Vec2(-1, 0), -2, 1e-6, 1e-6);
  check_line(g_segs[1], Vec2(-1, 0), -2, 1e-6, 1e-6);
  check_line(g_segs[2], Vec2(-1, 0), -2.25, 1e-6, 1e-6);
}

TEST(LineSegments, MissingBeamsBreakOnlyBeyondTolerance) {
  // One wall; knock out 2 consecutive returns in the middle (tolerated) -> 1 segment; 3 in a row elsewhere -> 2
  // clusters. The points either side are only ~6 cm apart, within 5·r·Δθ, so only the missing-beam rule splits.
  const Wall walls[] = {{Vec2(1, -1), Vec2(1, 1)}};
  cast_scan(walls, 1, -kPi, kLd06Inc, kLd06Beams, 0, nullptr, g_scan);
  g_scan.ranges_m[225] = 0;
  g_scan.ranges_m[226] = 0;
  scan_to_points(g_scan.view(), Pose2{}, 0.05, 12.0, g_points);
  extract_line_segments(g_points, g_scan.view(), SegmentParams{}, g_segs);
  LONGS_EQUAL(1, g_segs.size());
  g_scan.ranges_m[240] = 0;
  g_scan.ranges_m[241] = 0;
  g_scan.ranges_m[242] = 0;
  scan_to_points(g_scan.view(), Pose2{}, 0.05, 12.0, g_points);
  const SegmentStats st = extract_line_segments(g_points, g_scan.view(), SegmentParams{}, g_segs);
  LONGS_EQUAL(2, g_segs.size());
  LONGS_EQUAL(2, st.clusters);
}

TEST(LineSegments, WrapAcrossIndexZeroKeepsOneCluster) {
  // Wall behind the lidar at x = -2: with angle_min = -pi its returns sit at both ends of the scan.
  const Wall walls[] = {{Vec2(-2, 1), Vec2(-2, -1)}, {Vec2(2, -0.5), Vec2(2, 0.5)}};
  cast_scan(walls, 2, -kPi, kLd06Inc, kLd06Beams, 0, nullptr, g_scan);
  CHECK_TRUE(g_scan.view().wraps());
  scan_to_points(g_scan.view(), Pose2{}, 0.05, 12.0, g_points);
  const std::size_t n = g_points.size();
  SegmentStats st = extract_line_segments(g_points, g_scan.view(), SegmentParams{}, g_segs);
  CHECK_TRUE(st.wrapped);
  LONGS_EQUAL(2, g_segs.size());
  // Output starts after the gap: the front wall first, then the rear wall straddling index 0.
  check_line(g_segs[0], Vec2(-1, 0), -2, 1e-9, 1e-9);
  const LineSegment& rear = g_segs[1];
  check_line(rear, Vec2(1, 0), -2, 1e-9, 1e-9);
  CHECK(rear.first > rear.last);
  // Every rear-wall point is used: those with cos(a) < 0.
  std::size_t rear_hits = 0;
  for (const ScanPoint& p : g_points) rear_hits += std::cos(p.angle_rad) < 0 ? 1 : 0;
  LONGS_EQUAL(rear_hits, rear.point_count);
  LONGS_EQUAL(rear_hits, (n - rear.first) + rear.last + 1);
  REAL_EQUAL(2.0, rear.length_m(), 0.07);  // the 2 m wall less at most one beam spacing (2·0.014/cos²45°) at each end

  // Without the wrap flag the rear wall is cut at index 0 into two pieces.
  st = extract_line_segments(g_points, kLd06Inc, false, SegmentParams{}, g_segs);
  CHECK_FALSE(st.wrapped);
  LONGS_EQUAL(3, g_segs.size());
}

TEST(LineSegments, ClosedRoomGivesOneSegmentPerWall) {
  // Inside a 4 m x 3 m room, off-centre: no gap anywhere, the contour closes on itself. Every wall must come out
  // as exactly one segment whichever beam the cut falls on.
  const Vec2 c[4] = {Vec2(-1.5, -1.0), Vec2(2.5, -1.0), Vec2(2.5, 2.0), Vec2(-1.5, 2.0)};
  const Wall walls[] = {{c[0], c[1]}, {c[1], c[2]}, {c[2], c[3]}, {c[3], c[0]}};
  const Real starts[] = {-kPi, 0, 1.0, -2.0};
  for (Real a0 : starts) {
    cast_scan(walls, 4, a0, kLd06Inc, kLd06Beams, 0, nullptr, g_scan);
    scan_to_points(g_scan.view(), Pose2{}, 0.05, 12.0, g_points);
    const SegmentStats st = extract_line_segments(g_points, g_scan.view(), SegmentParams{}, g_segs);
    CHECK_TRUE(st.wrapped);
    LONGS_EQUAL(4, g_segs.size());
    int seen[4] = {0, 0, 0, 0};
    // Which wall a segment is: 1e-9 in double. In float the fit of the 4 m wall y = 2 seen from a0 = 1.0 comes out
    // 2.8e-5 rad / 2.6e-5 m off (its moments over ~170 points lose ~200 ulps; measured, see docs/performance.md),
    // so 1000 float ulps at 3 m (3.6e-4) — still far below the 0.5 m between walls this identifies.
    const double tol = dockcore_test::real_tol(3.0, 1e-9, 1000);
    for (const LineSegment& s : g_segs) {
      DOUBLES_EQUAL(0.0, s.rms_m, dockcore_test::real_tol(3.0, 1e-9, 16));
      if (std::fabs(s.normal.y() - 1) < tol && std::fabs(s.offset_m + 1.0) < tol) ++seen[0];   // y = -1
      if (std::fabs(s.normal.x() + 1) < tol && std::fabs(s.offset_m + 2.5) < tol) ++seen[1];   // x = 2.5
      if (std::fabs(s.normal.y() + 1) < tol && std::fabs(s.offset_m + 2.0) < tol) ++seen[2];   // y = 2
      if (std::fabs(s.normal.x() - 1) < tol && std::fabs(s.offset_m + 1.5) < tol) ++seen[3];   // x = -1.5
    }
    for (int w = 0; w < 4; ++w) LONGS_EQUAL(1, seen[w]);
  }
}

TEST(LineSegments, ClockwiseScanNormalsStillFaceTheSensor) {
  const Wall walls[] = {{Vec2(2, -1), Vec2(2, 1)}, {Vec2(2, 1), Vec2(0.5, 1)}};
  cast_scan(walls, 2, kPi, -kLd06Inc, kLd06Beams, 0, nullptr, g_scan);
  scan_to_points(g_scan.view(), Pose2{}, 0.05, 12.0, g_points);
  extract_line_segments(g_points, g_scan.view(), SegmentParams{}, g_segs);
  LONGS_EQUAL(2, g_segs.size());
  // Clockwise order: y = 1 wall first, then x = 2.
  check_line(g_segs[0], Vec2(0, -1), -1, 1e-6, 1e-6);
  check_line(g_segs[1], Vec2(-1, 0), -2, 1e-6, 1e-6);
}

TEST(LineSegments, MountPoseMovesLinesButKeepsNormalsFacingTheSensor) {
  // Points in the robot frame with the lidar 0.2 m ahead and yawed 90°: the wall at lidar x = 2 is robot y = 2.
  const Wall walls[] = {{Vec2(2, -1), Vec2(2, 1)}};
  cast_scan(walls, 1, -kPi, kLd06Inc, kLd06Beams, 0, nullptr, g_scan);
  scan_to_points(g_scan.view(), Pose2{0.2, 0, kPi / 2}, 0.05, 12.0, g_points);
  extract_line_segments(g_points, g_scan.view(), SegmentParams{}, g_segs);
  LONGS_EQUAL(1, g_segs.size());
  check_line(g_segs[0], Vec2(0, -1), -2, 1e-9, 1e-9);
}

TEST(LineSegments, AllInvalidAndTinyInputsGiveNothing) {
  g_scan.reset(kLd06Beams, -kPi, kLd06Inc, 0);
  scan_to_points(g_scan.view(), Pose2{}, 0.05, 12.0, g_points);
  SegmentStats st = extract_line_segments(g_points, g_scan.view(), SegmentParams{}, g_segs);
  LONGS_EQUAL(0, g_segs.size());
  LONGS_EQUAL(0, st.clusters);
  g_points.clear();
  push_point(g_points, Vec2(1, 0));
  push_point(g_points, Vec2(1, 0.01));
  st = extract_line_segments(g_points, 0, false, SegmentParams{}, g_segs);
  LONGS_EQUAL(0, g_segs.size());
}

TEST(LineSegments, SplitIterationCapIsReported) {
  const Wall walls[] = {{Vec2(2, -1), Vec2(2, 1)}, {Vec2(2, 1), Vec2(0.5, 1)}};
  cast_scan(walls, 2, -kPi, kLd06Inc, kLd06Beams, 0, nullptr, g_scan);
  scan_to_points(g_scan.view(), Pose2{}, 0.05, 12.0, g_points);
  SegmentParams p;
  p.max_split_iterations = 0;
  const SegmentStats st = extract_line_segments(g_points, g_scan.view(), p, g_segs);
  CHECK_TRUE(st.truncated());
  LONGS_EQUAL(1, st.unsplit_ranges);
  LONGS_EQUAL(1, g_segs.size());  // the corner is left in: one poor segment
  CHECK(g_segs[0].rms_m > 0.05);
}

TEST(LineSegments, ClusterCapIsReported) {
  const Wall walls[] = {{Vec2(2, -1.5), Vec2(2, -0.15)}, {Vec2(2, 0.15), Vec2(2, 0.8)}, {Vec2(2.25, 0.8), Vec2(2.25, 1.6)}};
  cast_scan(walls, 3, -kPi, kLd06Inc, kLd06Beams, 0, nullptr, g_scan);
  scan_to_points(g_scan.view(), Pose2{}, 0.05, 12.0, g_points);
  SegmentParams p;
  p.max_clusters = 1;
  const SegmentStats st = extract_line_segments(g_points, g_scan.view(), p, g_segs);
  CHECK_TRUE(st.truncated());
  LONGS_EQUAL(2, st.clusters_dropped);
  LONGS_EQUAL(1, g_segs.size());
}

TEST(LineSegments, OutputCapacityIsReported) {
  // 300 separate 6 cm pieces (4 points 2 cm apart, 20 cm between piece starts) on a circle of radius 10 m around
  // the sensor, sampled at 2 mrad: the 14 cm gaps are 7 missing beams. 300 segments wanted, kMaxLineSegments kept.
  g_points.clear();
  const Real step = 0.002;
  for (int c = 0; c < 300; ++c) {
    for (int k = 0; k < 4; ++k) {
      const Real a = -3.0 + step * (10 * c + k);
      push_point(g_points, Vec2(10 * std::cos(a), 10 * std::sin(a)));
    }
  }
  const SegmentStats st = extract_line_segments(g_points, step, false, SegmentParams{}, g_segs);
  LONGS_EQUAL(300, st.clusters);
  LONGS_EQUAL(kMaxLineSegments, g_segs.size());
  LONGS_EQUAL(300 - kMaxLineSegments, st.segments_dropped);
  CHECK_TRUE(st.truncated());
  REAL_EQUAL(0.06, g_segs[0].length_m(), 1e-4);  // chord of a 6 cm arc
}

TEST(LineSegments, SingleSpikeDoesNotSplitAWall) {
  // A 4 cm outlier (beyond the 3 cm split threshold, inside the 5 cm cluster gap) in the middle of a straight run:
  // split, then merged back across the spike.
  g_points.clear();
  for (int i = 0; i < 60; ++i) {
    const Real y = -0.6 + 0.02 * i;
    push_point(g_points, Vec2(i == 30 ? 1.96 : 2.0, y));
  }
  extract_line_segments(g_points, 0, false, SegmentParams{}, g_segs);
  LONGS_EQUAL(1, g_segs.size());
  LONGS_EQUAL(59, g_segs[0].point_count);  // the spike is left out of the fit
  REAL_EQUAL(0.0, g_segs[0].rms_m, 1e-9);
  check_line(g_segs[0], Vec2(-1, 0), -2, 1e-9, 1e-9);
}

TEST(LineSegments, Deterministic) {
  const Wall walls[] = {{Vec2(2, -1), Vec2(2, 1)}, {Vec2(2, 1), Vec2(0.5, 1)}, {Vec2(-1, -2), Vec2(-1, 2)}};
  docksim::Rng rng(3);
  cast_scan(walls, 3, -kPi, kLd06Inc, kLd06Beams, 0.01, &rng, g_scan);
  scan_to_points(g_scan.view(), Pose2{}, 0.05, 12.0, g_points);
  static LineSegments again;
  extract_line_segments(g_points, g_scan.view(), SegmentParams{}, g_segs);
  extract_line_segments(g_points, g_scan.view(), SegmentParams{}, again);
  LONGS_EQUAL(g_segs.size(), again.size());
  CHECK(g_segs.size() >= 3);
  for (std::size_t i = 0; i < g_segs.size(); ++i) {
    CHECK_EQUAL(0, std::memcmp(&g_segs[i], &again[i], sizeof(LineSegment)));
  }
}
