// BreakpointDetector against scans raycast here from the built-in "breakpoint" profile standing against a wall. The
// detector on the simulator's cluttered scenes is test_breakpoint_detector_scenes.
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>

#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/breakpoint_detector.hpp"
#include "dockcore/perception/dock_profile.hpp"

#include "breakpoint_scene.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using namespace breakpoint_scene;

namespace {

const Real kDeg = kPi / 180;
const Real kInf = std::numeric_limits<Real>::infinity();
// Tolerance for values that are exact up to rounding: looser when core is built with float.
const double kTight = sizeof(Real) == 4 ? 2e-5 : 1e-9;

/// Dock at distance d_m and bearing bearing_rad from the lidar, its face turned towards the lidar.
Pose2 facing_dock(Real d_m, Real bearing_rad) {
  return Pose2{d_m * std::cos(bearing_rad), d_m * std::sin(bearing_rad), wrap_angle(bearing_rad + kPi)};
}

/// Range along `angle` to the infinite line x = x_dock_m of the dock frame (the face is x = 0, the slots' bottom
/// x = -0.06): the geometric truth the detector's ranges approximate.
Real range_to_dock_line(const Pose2& dock, Real x_dock_m, Real angle) {
  const Vec2 p0 = dock.transform(Vec2(x_dock_m, 0));
  const Vec2 t = dock.transform(Vec2(x_dock_m, 1)) - p0;  // direction of the line
  const Vec2 d(std::cos(angle), std::sin(angle));
  return cross2(p0, t) / cross2(d, t);
}

// 1° lidar over a full turn, index 0 at -180° (the robot's front is index 180).
const std::size_t kBeams = 360;
const Real kInc = kTwoPi / 360;

LaserScanN<kBeams> g_scan;
BreakpointDetector g_det;  // static: the detector holds ~37 KB of working buffers

/// Scan angle of beam i of g_scan's usual geometry (index 0 at -180°).
Real beam_angle(std::size_t i) { return -kPi + static_cast<Real>(i) * kInc; }

/// Renders the dock facing the lidar at (d_m, bearing) against a wall into g_scan (index 0 at -180°).
Pose2 render_dock(Real d_m, Real bearing_rad) {
  Scene s;
  const Pose2 dock = facing_dock(d_m, bearing_rad);
  add_dock_against_wall(s, dock);
  render(s, g_scan, kBeams, -kPi, kInc);
  return dock;
}

/// Flat synthetic scan: every beam of g_scan reads range_m.
void flat_scan(Real range_m) {
  g_scan.reset(kBeams, -kPi, kInc, 0);
  for (std::size_t i = 0; i < kBeams; ++i) g_scan.ranges_m[i] = range_m;
}

/// Working position of scan index i in the last detect() (the window is contiguous, so search it).
std::size_t pos_of(std::size_t scan_index) {
  for (std::size_t j = 0; j < g_det.working_count(); ++j)
    if (g_det.scan_index_of(j) == scan_index) return j;
  FAIL("scan index not in the window");
  return 0;
}

}  // namespace

TEST_GROUP(Breakpoint) {
  void setup() override {
    g_det.set_params(BreakpointParams{});
    g_det.reset_counters();
  }
};

// Head-on at 1.0 m: at this distance one beam spans 17 mm, the slots (30 mm) get one or two beams and the end blocks'
// inner walls (visible over 0.4°) none, so every output is close to the ideal geometry.
TEST(Breakpoint, HeadOnOneMetre) {
  const Pose2 dock = render_dock(1.0, 0);
  const BreakpointDetection det = g_det.detect(g_scan.view());
  CHECK_TRUE(det.found);
  CHECK_EQUAL(static_cast<int>(BreakpointStatus::kFound), static_cast<int>(det.status));
  // The wall <-> end block jumps (0.10 m) lie outside the band, but the wall itself, seen obliquely, has beam-to-beam
  // steps r tan(a) * 1° inside it (0.025 m at 1.1 m / cos 45°): marks the sliding search has to step over.
  CHECK_TRUE(det.mutation_count > 4);
  DOUBLES_EQUAL(0.0, det.centre_angle_rad, kInc);
  // Right beam m0: last on the end block at dock y = +0.13..0.15 (lidar's right); left m3: last in the left slot.
  // Face-edge angles: atan(0.13 / 1.0) = 7.41°, slot bottom outer edge at atan(0.13 / 1.06) = 6.99°.
  CHECK_TRUE(det.right_angle_rad <= -std::atan(0.13 / 1.0) && det.right_angle_rad > -std::atan(0.15 / 1.0));
  CHECK_TRUE(det.left_angle_rad <= std::atan(0.13 / 1.0) && det.left_angle_rad > std::atan(0.10 / 1.0));
  // Both side ranges refer to the slots' bottom line (right: face + 0.06 compensation).
  DOUBLES_EQUAL(range_to_dock_line(dock, -0.06, det.left_angle_rad), det.left_range_m, 0.01);
  DOUBLES_EQUAL(range_to_dock_line(dock, -0.06, det.right_angle_rad), det.right_range_m, 0.01);
  DOUBLES_EQUAL(1.0 / std::cos(det.right_angle_rad) + 0.06, det.right_range_m, kTight);  // on the face, exactly
  DOUBLES_EQUAL(range_to_dock_line(dock, 0, det.centre_angle_rad), det.centre_range_m, 0.01);
  CHECK_EQUAL(180u, det.centre_index);
  CHECK_TRUE(det.mutation_index[0] < det.mutation_index[1] && det.mutation_index[1] < det.mutation_index[2] &&
             det.mutation_index[2] < det.mutation_index[3]);
  CHECK_EQUAL(det.right_index, det.mutation_index[0]);
  CHECK_EQUAL(det.left_index, det.mutation_index[3]);
  Vec2 p;
  CHECK_TRUE(det.dock_position_lidar(p));
  DOUBLES_EQUAL(1.0, p.x(), 0.01);
  DOUBLES_EQUAL(0.0, p.y(), 1.0 * kInc);
  // Within ±30° the wall's steps stay below 0.025 m (1.27 m * tan 30° * 1° = 0.013 m): only the dock's four jumps.
  BreakpointParams narrow;
  narrow.window_min_rad = -30 * kDeg;
  narrow.window_max_rad = 30 * kDeg;
  g_det.set_params(narrow);
  const BreakpointDetection n30 = g_det.detect(g_scan.view());
  CHECK_EQUAL(4, n30.mutation_count);
  CHECK_EQUAL(det.centre_index, n30.centre_index);
}

// Head-on at 0.5 m the inner wall of the right end block is visible over 1.5° and beam -14° lands on it
// (range 0.13 / sin 14° = 0.537 m, between face 0.515 and slot 0.577). The jump block -> wall (0.019 m) is below
// the band, wall -> slot (0.038 m) inside it, so the seed's m0 is the wall beam and right = 0.537 + 0.06: 2 cm
// beyond the slot line. The left side has no such beam and is exact.
TEST(Breakpoint, HeadOnHalfMetreRightBeamOnEndBlockWall) {
  const Pose2 dock = render_dock(0.5, 0);
  const BreakpointDetection det = g_det.detect(g_scan.view());
  CHECK_TRUE(det.found);
  DOUBLES_EQUAL(0.0, det.centre_angle_rad, kInc);
  DOUBLES_EQUAL(-14.0 * kDeg, det.right_angle_rad, kTight);
  DOUBLES_EQUAL(0.13 / std::sin(14.0 * kDeg) + 0.06, det.right_range_m, kTight);
  DOUBLES_EQUAL(range_to_dock_line(dock, -0.06, det.right_angle_rad), det.right_range_m, 0.035);
  DOUBLES_EQUAL(range_to_dock_line(dock, -0.06, det.left_angle_rad), det.left_range_m, 0.01);
  DOUBLES_EQUAL(range_to_dock_line(dock, 0, det.centre_angle_rad), det.centre_range_m, 0.01);
  DOUBLES_EQUAL(0.5, det.centre_range_m, 0.01);
}

TEST(Breakpoint, SmallBearingsFindCentreWithinOneBeam) {
  for (Real d : {0.5, 1.0}) {
    for (Real b_deg : {-8.4, -3.0, -1.3, 2.6, 4.5, 9.7}) {
      const Pose2 dock = render_dock(d, b_deg * kDeg);
      const BreakpointDetection det = g_det.detect(g_scan.view());
      CHECK_TRUE(det.found);
      DOUBLES_EQUAL(b_deg * kDeg, det.centre_angle_rad, kInc);
      DOUBLES_EQUAL(range_to_dock_line(dock, 0, det.centre_angle_rad), det.centre_range_m, 0.01);
      DOUBLES_EQUAL(range_to_dock_line(dock, -0.06, det.left_angle_rad), det.left_range_m, 0.035);
      DOUBLES_EQUAL(range_to_dock_line(dock, -0.06, det.right_angle_rad), det.right_range_m, 0.035);
      Vec2 p;
      CHECK_TRUE(det.dock_position_lidar(p));
      CHECK_TRUE((p - Vec2(dock.x_m, dock.y_m)).norm() < d * kInc + 0.01);
    }
  }
}

// Sweep of placements, 0.4..1.3 m, bearings -30°..30° in 0.11° steps. The dock faces the lidar and the wall lies
// along its back, so only the beams' phase against the dock changes with the bearing: the sweep covers it finely.
// Where an end block's inner wall is visible over more than a beam (0.4 m: 1.8°), its ramp can split the
// block <-> slot jump into two steps both below 0.025 m and the dock is missed: a limit of the seed's rules
// (measured here: 10% of beam phases at 0.4 m, none from 0.5 m). When found, the centre is within a beam, the centre
// range within 1 cm; a side beam on that ramp reads up to 3.3 cm off the slot line (half to 92% of the sides are
// within 1 cm, from 0.5 m to 1.3 m).
TEST(Breakpoint, SweepOfPlacements) {
  for (Real d : {0.4, 0.5, 0.7, 1.0, 1.3}) {
    int found = 0;
    int total = 0;
    int side_within_1cm = 0;
    for (int k = -272; k <= 272; ++k) {
      const Real b = static_cast<Real>(k) * 0.11 * kDeg;
      const Pose2 dock = render_dock(d, b);
      const BreakpointDetection det = g_det.detect(g_scan.view());
      ++total;
      if (!det.found) continue;
      ++found;
      DOUBLES_EQUAL(b, det.centre_angle_rad, kInc);
      DOUBLES_EQUAL(range_to_dock_line(dock, 0, det.centre_angle_rad), det.centre_range_m, 0.01);
      const Real el = std::fabs(range_to_dock_line(dock, -0.06, det.left_angle_rad) - det.left_range_m);
      const Real er = std::fabs(range_to_dock_line(dock, -0.06, det.right_angle_rad) - det.right_range_m);
      CHECK_TRUE(el < 0.035 && er < 0.035);
      side_within_1cm += (el < 0.01 ? 1 : 0) + (er < 0.01 ? 1 : 0);
    }
    if (d < 0.45) {
      CHECK_TRUE(found >= total * 85 / 100);
    } else {
      CHECK_EQUAL(total, found);
      CHECK_TRUE(side_within_1cm >= found);  // at least half of the side ranges within 1 cm
    }
  }
}

// The seed's rule r[m0] < r[m0 - 5] needs something nearer than the 2.1 m filter beside the dock.
TEST(Breakpoint, NeedsBackgroundInsideFilterRange) {
  {
    Scene s;  // dock alone: beside it the beams read inf -> 0
    DockProfile p;
    builtin_profile("breakpoint", p);
    const Pose2 dock = facing_dock(1.0, 0);
    for (std::size_t i = 0; i + 1 < p.vertex_count; ++i)
      s.add(dock.transform(p.vertices_m[i]), dock.transform(p.vertices_m[i + 1]));
    render(s, g_scan, kBeams, -kPi, kInc);
    const BreakpointDetection det = g_det.detect(g_scan.view());
    CHECK_FALSE(det.found);
    CHECK_EQUAL(static_cast<int>(BreakpointStatus::kNoPattern), static_cast<int>(det.status));
    // A wall at 2.3 m (beyond 2.1 m) is filtered out as well; at 1.5 m it counts.
    s.add(Vec2(2.3, -3), Vec2(2.3, 3));
    render(s, g_scan, kBeams, -kPi, kInc);
    CHECK_FALSE(g_det.detect(g_scan.view()).found);
    s.a[s.n - 1] = Vec2(1.5, -3);
    s.b[s.n - 1] = Vec2(1.5, 3);
    render(s, g_scan, kBeams, -kPi, kInc);
    CHECK_TRUE(g_det.detect(g_scan.view()).found);
  }
}

TEST(Breakpoint, GapCompletionOfOneAndTwoPoints) {
  flat_scan(1.0);
  // One gap, neighbours 0.006 apart: the mean (not the seed text's half-difference) fills it.
  g_scan.ranges_m[149] = 0.997;
  g_scan.ranges_m[150] = kInf;
  g_scan.ranges_m[151] = 1.003;
  // Two gaps, neighbours 0.015 apart (inside the code's 0.02 m, outside the text's 0.01 m).
  g_scan.ranges_m[159] = 0.99;
  g_scan.ranges_m[160] = 0;
  g_scan.ranges_m[161] = std::numeric_limits<Real>::quiet_NaN();
  g_scan.ranges_m[162] = 1.005;
  // Three gaps: never completed.
  g_scan.ranges_m[170] = g_scan.ranges_m[171] = g_scan.ranges_m[172] = 0;
  // One gap whose neighbours disagree by 0.03 m: left alone.
  g_scan.ranges_m[199] = 0.99;
  g_scan.ranges_m[200] = 0;
  g_scan.ranges_m[201] = 1.02;
  // Beyond 2.1 m counts as a gap too.
  g_scan.ranges_m[220] = 2.5;
  g_det.detect(g_scan.view());
  const Real* w = g_det.working_ranges_m();
  DOUBLES_EQUAL(1.0, w[pos_of(150)], kTight);
  DOUBLES_EQUAL(0.9975, w[pos_of(160)], kTight);
  DOUBLES_EQUAL(0.9975, w[pos_of(161)], kTight);
  DOUBLES_EQUAL(0.0, w[pos_of(170)], 0);
  DOUBLES_EQUAL(0.0, w[pos_of(171)], 0);
  DOUBLES_EQUAL(0.0, w[pos_of(172)], 0);
  DOUBLES_EQUAL(0.0, w[pos_of(200)], 0);
  DOUBLES_EQUAL(1.0, w[pos_of(220)], kTight);
  CHECK_EQUAL(4u, g_det.counters().gap_filled_points);

  // The text's 0.01 m threshold completes the single gap but not the pair.
  BreakpointParams text;
  text.gap_fill_max_diff_m = 0.01;
  g_det.set_params(text);
  g_det.detect(g_scan.view());
  DOUBLES_EQUAL(1.0, g_det.working_ranges_m()[pos_of(150)], kTight);
  DOUBLES_EQUAL(0.0, g_det.working_ranges_m()[pos_of(160)], 0);
}

// A dropout at the neighbour beam m0 - 5 (on the wall) would fail rule 2; completion restores it.
TEST(Breakpoint, GapCompletionRescuesNeighbourRule) {
  render_dock(1.0, 0);
  const BreakpointDetection ref = g_det.detect(g_scan.view());
  CHECK_TRUE(ref.found);
  g_scan.ranges_m[ref.right_index - 5] = 0;
  g_scan.ranges_m[ref.left_index + 5] = kInf;
  g_scan.ranges_m[ref.left_index + 6] = kInf;
  const BreakpointDetection det = g_det.detect(g_scan.view());
  CHECK_TRUE(det.found);
  CHECK_EQUAL(ref.right_index, det.right_index);
  CHECK_EQUAL(ref.left_index, det.left_index);
  BreakpointParams off;
  off.gap_fill_max_diff_m = 0;
  g_det.set_params(off);
  CHECK_FALSE(g_det.detect(g_scan.view()).found);
}

TEST(Breakpoint, JumpBandEdges) {
  struct Case {
    Real step_m;
    int marks;
  };
  // A 10-beam plateau gives two jumps of step_m (up and down).
  const Case cases[] = {{0.0245, 0}, {0.0255, 2}, {0.0600, 2}, {0.0645, 2}, {0.0655, 0}, {0.10, 0}};
  for (const Case& c : cases) {
    flat_scan(1.0);
    for (std::size_t i = 120; i < 130; ++i) g_scan.ranges_m[i] = 1.0 + c.step_m;
    CHECK_EQUAL(c.marks, g_det.detect(g_scan.view()).mutation_count);
  }
  // Both band ends are strict: a step of exactly min_jump_m (2^-5, exact in binary) is not marked.
  flat_scan(1.0);
  for (std::size_t i = 120; i < 130; ++i) g_scan.ranges_m[i] = 1.0 + 0.03125;
  BreakpointParams p;
  p.min_jump_m = 0.03125;
  g_det.set_params(p);
  CHECK_EQUAL(0, g_det.detect(g_scan.view()).mutation_count);
  p.min_jump_m = 0.0312;
  p.max_jump_m = 0.03125;
  g_det.set_params(p);
  CHECK_EQUAL(0, g_det.detect(g_scan.view()).mutation_count);
  p.max_jump_m = 0.0313;
  g_det.set_params(p);
  CHECK_EQUAL(2, g_det.detect(g_scan.view()).mutation_count);
}

TEST(Breakpoint, AllInvalidScanIsNotFound) {
  for (Real bad : {kInf, static_cast<Real>(0), std::numeric_limits<Real>::quiet_NaN(), static_cast<Real>(-1),
                   static_cast<Real>(3.0)}) {
    flat_scan(bad);
    const BreakpointDetection det = g_det.detect(g_scan.view());
    CHECK_FALSE(det.found);
    CHECK_EQUAL(static_cast<int>(BreakpointStatus::kTooFewMutations), static_cast<int>(det.status));
    CHECK_EQUAL(0, det.mutation_count);
    Vec2 p(7, 7);
    CHECK_FALSE(det.dock_position_lidar(p));
    DOUBLES_EQUAL(7.0, p.x(), 0);
  }
}

// Window [min, 90°]: the candidate needs m0 - 5 inside the window, and symmetrically m3 + 5 for the upper bound.
TEST(Breakpoint, DockAtWindowEdge) {
  render_dock(1.0, 0);
  const BreakpointDetection ref = g_det.detect(g_scan.view());
  CHECK_TRUE(ref.found);
  const Real half = static_cast<Real>(0.5) * kInc;
  BreakpointParams p;
  p.window_min_rad = beam_angle(ref.right_index - 5) - half;  // m0 - 5 is the first beam: just inside
  g_det.set_params(p);
  BreakpointDetection det = g_det.detect(g_scan.view());
  CHECK_TRUE(det.found);
  CHECK_EQUAL(ref.centre_index, det.centre_index);
  p.window_min_rad = beam_angle(ref.right_index - 4) - half;  // m0 - 5 just outside
  g_det.set_params(p);
  CHECK_FALSE(g_det.detect(g_scan.view()).found);
  p.window_min_rad = beam_angle(ref.right_index + 3);  // window cuts through the dock
  g_det.set_params(p);
  CHECK_FALSE(g_det.detect(g_scan.view()).found);

  p.window_min_rad = -kPi / 2;
  p.window_max_rad = beam_angle(ref.left_index + 5) + half;
  g_det.set_params(p);
  det = g_det.detect(g_scan.view());
  CHECK_TRUE(det.found);
  CHECK_EQUAL(ref.left_index, det.left_index);
  p.window_max_rad = beam_angle(ref.left_index + 4) + half;
  g_det.set_params(p);
  CHECK_FALSE(g_det.detect(g_scan.view()).found);
}

// A lidar whose index 0 is its front (as the seed's rplidar, angles [0, 360°)): the ±90° window wraps across
// index 359 -> 0 and the dock straddles index 0.
TEST(Breakpoint, WrapAroundWindowWithDockAcrossIndexZero) {
  const Pose2 dock = render_dock(0.5, 0);
  const BreakpointDetection ref = g_det.detect(g_scan.view());
  CHECK_TRUE(ref.found);

  Scene s;
  add_dock_against_wall(s, dock);
  static LaserScanN<kBeams> front0;
  render(s, front0, kBeams, 0, kInc);
  CHECK_TRUE(front0.view().wraps());
  const BreakpointDetection det = g_det.detect(front0.view());
  CHECK_TRUE(det.found);
  CHECK_EQUAL(181u, g_det.working_count());
  CHECK_EQUAL(270u, g_det.scan_index_of(0));
  CHECK_TRUE(det.right_index > 300);  // right edge at about -14° -> index 346
  CHECK_TRUE(det.left_index < 20);    // left edge at about +13° -> index 13
  CHECK_EQUAL(0u, det.centre_index);
  DOUBLES_EQUAL(ref.right_angle_rad, det.right_angle_rad, kTight);
  DOUBLES_EQUAL(ref.left_angle_rad, det.left_angle_rad, kTight);
  DOUBLES_EQUAL(ref.centre_angle_rad, det.centre_angle_rad, kTight);
  DOUBLES_EQUAL(ref.left_range_m, det.left_range_m, kTight);
  DOUBLES_EQUAL(ref.right_range_m, det.right_range_m, kTight);
  DOUBLES_EQUAL(ref.centre_range_m, det.centre_range_m, kTight);
}

// Index 0 at -180° and a window behind the robot, [150°, 210°]: the window runs across the scan's last index.
// Also with a 361-beam scan that repeats -180° at its end (beams per turn 360, not the count).
TEST(Breakpoint, WrapAroundWindowBehindTheRobot) {
  const BreakpointDetection ref = [] {
    render_dock(0.5, 0);
    return g_det.detect(g_scan.view());
  }();
  Scene s;
  add_dock_against_wall(s, facing_dock(0.5, kPi));
  BreakpointParams p;
  p.window_min_rad = 150 * kDeg;
  p.window_max_rad = 210 * kDeg;
  g_det.set_params(p);
  static LaserScanN<361> scan;
  for (std::size_t count : {std::size_t{360}, std::size_t{361}}) {
    render(s, scan, count, -kPi, kInc);
    CHECK_TRUE(scan.view().wraps());
    const BreakpointDetection det = g_det.detect(scan.view());
    CHECK_TRUE(det.found);
    CHECK_EQUAL(61u, g_det.working_count());
    CHECK_EQUAL(0u, det.centre_index);
    CHECK_EQUAL((ref.right_index + 180) % 360, det.right_index);
    CHECK_EQUAL((ref.left_index + 180) % 360, det.left_index);
    DOUBLES_EQUAL(0.0, wrap_angle(det.right_angle_rad - ref.right_angle_rad - kPi), kTight);
    DOUBLES_EQUAL(0.0, wrap_angle(det.left_angle_rad - ref.left_angle_rad - kPi), kTight);
    DOUBLES_EQUAL(kPi, det.centre_angle_rad, kTight);
    DOUBLES_EQUAL(ref.left_range_m, det.left_range_m, kTight);
    DOUBLES_EQUAL(ref.right_range_m, det.right_range_m, kTight);
  }
}

/// The paper's marker (eq. 5-6..5-9): a plate at 1.0 m with steps of 0.012 m (the paper's height difference),
/// 3 beams each, giving five signed marks -,+,-,+,-; beyond it nothing within range.
static void paper_pattern(Real outer_step_m, bool sixth_step) {
  flat_scan(kInf);
  Real levels[6];
  levels[0] = 1.0;
  levels[1] = levels[0] - outer_step_m;
  levels[2] = levels[1] + 0.012;
  levels[3] = levels[2] - 0.012;
  levels[4] = levels[3] + 0.012;
  levels[5] = levels[4] - outer_step_m;
  for (std::size_t k = 0; k < 6; ++k)
    for (std::size_t i = 0; i < 3; ++i) g_scan.ranges_m[170 + 3 * k + i] = levels[k];
  // Blocks start at 170, 173 (rd = -1), 176 (+1), 179 (-1), 182 (+1), 185 (-1); 188.. nothing.
  if (sixth_step)
    for (std::size_t i = 188; i < 191; ++i) g_scan.ranges_m[i] = 1.0;  // +1 at 188
}

TEST(Breakpoint, PaperSignedVariantFindsFiveStepMarker) {
  BreakpointParams p;
  p.variant = BreakpointVariant::kPaperSigned;
  g_det.set_params(p);
  paper_pattern(0.012, false);
  BreakpointDetection det = g_det.detect(g_scan.view());
  CHECK_TRUE(det.found);
  CHECK_EQUAL(5, det.mutation_count);
  CHECK_EQUAL(173u, det.right_index);  // m
  CHECK_EQUAL(185u, det.left_index);   // n
  DOUBLES_EQUAL(beam_angle(179), det.centre_angle_rad, kTight);  // (m + n) / 2 = 179 -> -1°
  DOUBLES_EQUAL(0.988, det.right_range_m, kTight);
  DOUBLES_EQUAL(0.988, det.left_range_m, kTight);
  DOUBLES_EQUAL(1.0 - 0.012, det.centre_range_m, kTight);  // beam 179 is on a 0.988 step

  // Outer steps too small to mark (0.008 m): the middle three still make an interval, [176, 182].
  paper_pattern(0.008, false);
  det = g_det.detect(g_scan.view());
  CHECK_TRUE(det.found);
  CHECK_EQUAL(3, det.mutation_count);
  CHECK_EQUAL(176u, det.right_index);
  CHECK_EQUAL(182u, det.left_index);
  DOUBLES_EQUAL(beam_angle(179), det.centre_angle_rad, kTight);

  // Six marks in one cluster exceed the count of 5: not the marker.
  paper_pattern(0.012, true);
  det = g_det.detect(g_scan.view());
  CHECK_FALSE(det.found);
  CHECK_EQUAL(6, det.mutation_count);
  CHECK_EQUAL(static_cast<int>(BreakpointStatus::kNoPattern), static_cast<int>(det.status));

  // The seed-code variant sees no mark at all in 0.012 m steps (its band starts at 0.025 m).
  g_det.set_params(BreakpointParams{});
  paper_pattern(0.012, false);
  det = g_det.detect(g_scan.view());
  CHECK_FALSE(det.found);
  CHECK_EQUAL(0, det.mutation_count);
}

TEST(Breakpoint, PaperSignedUnevenCentreIsUnrounded) {
  BreakpointParams p;
  p.variant = BreakpointVariant::kPaperSigned;
  g_det.set_params(p);
  flat_scan(kInf);
  // Plate 1.0 at [170, 190); 0.988 at [173, 176) and [178, 182): marks at 173 (-), 176 (+), 178 (-), 182 (+).
  for (std::size_t i = 170; i < 190; ++i) g_scan.ranges_m[i] = 1.0;
  for (std::size_t i : {173, 174, 175, 178, 179, 180, 181}) g_scan.ranges_m[i] = 0.988;
  const BreakpointDetection det = g_det.detect(g_scan.view());
  CHECK_TRUE(det.found);
  CHECK_EQUAL(173u, det.right_index);
  CHECK_EQUAL(182u, det.left_index);
  DOUBLES_EQUAL(beam_angle(173) + 4.5 * kInc, det.centre_angle_rad, kTight);
  CHECK_EQUAL(178u, det.centre_index);  // round(177.5) for the range lookup
}

TEST(Breakpoint, DeterministicAcrossCallsAndInstances) {
  render_dock(0.7, 3.3 * kDeg);
  static LaserScanN<kBeams> a;
  a = g_scan;
  const BreakpointDetection first = g_det.detect(a.view());
  render_dock(1.0, -6 * kDeg);
  g_det.detect(g_scan.view());
  const BreakpointDetection again = g_det.detect(a.view());
  static BreakpointDetector other;
  const BreakpointDetection fresh = other.detect(a.view());
  for (const BreakpointDetection* d : {&again, &fresh}) {
    CHECK_TRUE(d->found && first.found);
    CHECK_TRUE(first.left_angle_rad == d->left_angle_rad && first.right_angle_rad == d->right_angle_rad &&
               first.centre_angle_rad == d->centre_angle_rad);
    CHECK_TRUE(first.left_range_m == d->left_range_m && first.right_range_m == d->right_range_m &&
               first.centre_range_m == d->centre_range_m);
    CHECK_EQUAL(first.centre_index, d->centre_index);
    CHECK_EQUAL(first.mutation_count, d->mutation_count);
    for (std::size_t k = 0; k < 4; ++k) CHECK_EQUAL(first.mutation_index[k], d->mutation_index[k]);
  }
}

TEST(Breakpoint, CountersAccumulate) {
  render_dock(1.0, 0);
  g_scan.ranges_m[165] = 0;  // on the wall at -15°; neighbours 1.1 / cos 14°, 1.1 / cos 16°: 0.010 m apart
  const BreakpointDetection a = g_det.detect(g_scan.view());
  flat_scan(kInf);
  const BreakpointDetection b = g_det.detect(g_scan.view());
  CHECK_TRUE(a.found);
  CHECK_FALSE(b.found);
  CHECK_EQUAL(2u, g_det.counters().scans_processed);
  CHECK_EQUAL(1u, g_det.counters().detections);
  CHECK_EQUAL(1u, g_det.counters().gap_filled_points);
  CHECK_EQUAL(static_cast<std::uint32_t>(a.mutation_count + b.mutation_count), g_det.counters().mutations_found);
  CHECK_TRUE(a.mutation_count > 4);
  g_det.reset_counters();
  CHECK_EQUAL(0u, g_det.counters().scans_processed);
}

TEST(Breakpoint, BadInputsReportStatus) {
  flat_scan(1.0);
  ScanView v = g_scan.view();
  v.count = 0;
  CHECK_EQUAL(static_cast<int>(BreakpointStatus::kBadScan), static_cast<int>(g_det.detect(v).status));
  v = g_scan.view();
  v.angle_increment_rad = -kInc;
  CHECK_EQUAL(static_cast<int>(BreakpointStatus::kBadScan), static_cast<int>(g_det.detect(v).status));
  BreakpointParams p;
  p.window_min_rad = 0.5;
  p.window_max_rad = 0.4;
  g_det.set_params(p);
  CHECK_EQUAL(static_cast<int>(BreakpointStatus::kBadWindow), static_cast<int>(g_det.detect(g_scan.view()).status));
  p.window_min_rad = std::numeric_limits<Real>::quiet_NaN();
  g_det.set_params(p);
  CHECK_EQUAL(static_cast<int>(BreakpointStatus::kBadWindow), static_cast<int>(g_det.detect(g_scan.view()).status));
  p.window_min_rad = 0.1 * kDeg;
  p.window_max_rad = 0.2 * kDeg;
  g_det.set_params(p);
  CHECK_EQUAL(static_cast<int>(BreakpointStatus::kEmptyWindow), static_cast<int>(g_det.detect(g_scan.view()).status));
  CHECK_EQUAL(0u, g_det.counters().scans_processed);
  CHECK_TRUE(std::strlen(to_string(BreakpointStatus::kEmptyWindow)) > 0);
}
