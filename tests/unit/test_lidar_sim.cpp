// Lidar simulator and scene generator: geometry against hand-computed values, error statistics, determinism, and
// that generated clutter never hides the dock.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "dockcore/perception/intensity_check.hpp"
#include "docksim/angles.hpp"
#include "docksim/lidar_sim.hpp"
#include "docksim/rng.hpp"
#include "docksim/scenes.hpp"

#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

using namespace docksim;
using dockcore::kPi;

namespace {

constexpr double kDeg = docksim::kDegD;

Vec2 V(double x, double y) { return Vec2(static_cast<Real>(x), static_cast<Real>(y)); }
Vec2 dir_of(double a) { return V(std::cos(a), std::sin(a)); }

// A model with every error switched off: ranges must equal the geometry.
LidarModel ideal_model(const char* base = "ld06") {
  LidarModel m;
  CHECK_TRUE(lidar_model(base, &m));
  m.sigma_const_m = 0;
  m.sigma_prop = 0;
  m.dropout_prob = 0;
  m.angular_jitter_rad = 0;
  m.mixed_pixels = false;
  return m;
}

double beam_angle(const LidarModel& m, std::size_t i) { return m.angle_min_rad + static_cast<double>(i) * m.angle_increment_rad; }

// Closed square room of half size h around the origin.
World room(double h) {
  World w;
  w.add_polyline({V(-h, -h), V(-h, h), V(h, h), V(h, -h)}, true);
  return w;
}

struct Stats {
  double n = 0, sum = 0, sum2 = 0;
  void add(double x) {
    n += 1;
    sum += x;
    sum2 += x * x;
  }
  double mean() const { return sum / n; }
  double sd() const { return std::sqrt(std::max(0.0, sum2 / n - mean() * mean())); }
};

}  // namespace

TEST_GROUP(Raycast){};

TEST(Raycast, WallAtOneMetreHeadOnAndAtThirtyDegrees) {
  World w;
  w.add_polyline({V(1, -5), V(1, 5)});
  double r = 0, refl = 0;
  CHECK_TRUE(w.raycast(V(0, 0), dir_of(0), 10, &r, &refl));
  REAL_EQUAL(1.0, r, 1e-12);
  REAL_EQUAL(0.5, refl, 1e-12);
  CHECK_TRUE(w.raycast(V(0, 0), dir_of(30 * kDeg), 10, &r));
  REAL_EQUAL(1.0 / std::cos(30 * kDeg), r, 1e-12);
  CHECK_TRUE(w.raycast(V(0, 0), dir_of(-60 * kDeg), 10, &r));
  REAL_EQUAL(2.0, r, 1e-12);
  // Offset origin: from (0.25, 0.5) straight at the wall.
  CHECK_TRUE(w.raycast(V(0.25, 0.5), dir_of(0), 10, &r));
  REAL_EQUAL(0.75, r, 1e-12);
}

TEST(Raycast, MissesAwayFromWallBeyondEndsAndPastMaxRange) {
  World w;
  w.add_polyline({V(1, -1), V(1, 1)});
  double r = -1;
  CHECK_FALSE(w.raycast(V(0, 0), dir_of(kPi), 10, &r));
  CHECK_FALSE(w.raycast(V(0, 0), dir_of(50 * kDeg), 10, &r));  // tan 50° > 1: passes beyond the end.
  CHECK_TRUE(w.raycast(V(0, 0), dir_of(44 * kDeg), 10, &r));
  CHECK_FALSE(w.raycast(V(0, 0), dir_of(0), 0.99, &r));
  CHECK_TRUE(w.raycast(V(0, 0), dir_of(0), 1.0, &r));
}

TEST(Raycast, OneSidedSegmentsOnlyHitFromTheirNormalSide) {
  // a=(1,-5) -> b=(1,5): normal (dy, -dx) = (10, 0) points away from the origin, so the origin sees its back.
  World back;
  back.segments.push_back(Segment{V(1, -5), V(1, 5), 0.5, true});
  double r = 0;
  CHECK_FALSE(back.raycast(V(0, 0), dir_of(0), 10, &r));
  CHECK_TRUE(back.raycast(V(2, 0), dir_of(kPi), 10, &r));  // From the +x side it faces.
  REAL_EQUAL(1.0, r, 1e-12);
  World front;
  front.segments.push_back(Segment{V(1, 5), V(1, -5), 0.5, true});
  CHECK_TRUE(front.raycast(V(0, 0), dir_of(0), 10, &r));
  REAL_EQUAL(1.0, r, 1e-12);
  // A back face in front of a front face is transparent.
  front.segments.insert(front.segments.begin(), Segment{V(0.5, -5), V(0.5, 5), 0.9, true});
  double refl = 0;
  CHECK_TRUE(front.raycast(V(0, 0), dir_of(0), 10, &r, &refl));
  REAL_EQUAL(1.0, r, 1e-12);
  REAL_EQUAL(0.5, refl, 1e-12);
}

TEST(Raycast, NearestOfTwoWhateverTheOrder) {
  World w;
  w.add_polyline({V(2, -5), V(2, 5)}, false, 0.2);
  w.add_polyline({V(1, -5), V(1, 5)}, false, 0.7);
  double r = 0, refl = 0;
  std::size_t seg = 99;
  CHECK_TRUE(w.raycast(V(0, 0), dir_of(0), 10, &r, &refl));
  REAL_EQUAL(1.0, r, 1e-12);
  REAL_EQUAL(0.7, refl, 1e-12);
  CHECK_TRUE(w.raycast_segment(V(0, 0), dir_of(0), 10, &r, &seg));
  LONGS_EQUAL(1, seg);
}

TEST(Raycast, HelpersBuildTheDescribedShapes) {
  World w;
  w.add_box(V(2, 0), 0.4, 1.0, 0.0);  // Near face at x = 1.8.
  LONGS_EQUAL(4, w.segments.size());
  double r = 0;
  CHECK_TRUE(w.raycast(V(0, 0), dir_of(0), 10, &r));
  REAL_EQUAL(1.8, r, 1e-12);
  World c;
  c.add_circle(V(0, 3), 0.04, 12);
  LONGS_EQUAL(12, c.segments.size());
  CHECK_TRUE(c.raycast(V(0, 0), dir_of(kPi / 2), 10, &r));
  // Vertices on the circle every 30° from 0°, so one sits at -90°, facing the origin.
  REAL_EQUAL(3.0 - 0.04, r, 1e-12);
  // A ray through the middle of the flat side between the -90° and -60° vertices: that side is at 0.04*cos(15°)
  // from the centre, so the ray from the centre outwards at -75° crosses it there.
  CHECK_TRUE(c.raycast(V(0, 3), dir_of(-75 * kDeg), 10, &r));
  REAL_EQUAL(0.04 * std::cos(15 * kDeg), r, 1e-12);
  dockcore::DockProfile p;
  CHECK_TRUE(dockcore::builtin_profile("plate-v", p) == dockcore::ProfileError::kOk);
  World d;
  d.add_dock(p, Pose2{2, 0, static_cast<Real>(kPi)});  // Face at x = 2 looking back at the origin.
  LONGS_EQUAL(p.segment_count(), d.segments.size());
  CHECK_TRUE(d.raycast(V(0, 0), dir_of(0), 10, &r));
  REAL_EQUAL(2.0, r, 1e-12);
}

TEST_GROUP(LidarSim){};

TEST(LidarSim, ModelsHaveTheirDatasheetGeometry) {
  LidarModel m;
  CHECK_TRUE(lidar_model("ld06", &m));
  LONGS_EQUAL(450, m.beams);
  REAL_EQUAL(0.8 * kDeg, m.angle_increment_rad, 1e-12);
  REAL_EQUAL(10.0, m.rate_hz, 0);
  REAL_EQUAL(0.02, m.min_range_m, 0);
  REAL_EQUAL(12.0, m.max_range_m, 0);
  REAL_EQUAL(0.010, m.sigma_const_m, 0);
  CHECK_TRUE(lidar_model("rplidar-a1", &m));
  LONGS_EQUAL(360, m.beams);
  REAL_EQUAL(1.0 * kDeg, m.angle_increment_rad, 1e-12);
  REAL_EQUAL(0.15, m.min_range_m, 0);
  CHECK_TRUE(lidar_model("industrial", &m));
  LONGS_EQUAL(1081, m.beams);
  REAL_EQUAL(-135 * kDeg, m.angle_min_rad, 1e-12);
  REAL_EQUAL(135 * kDeg, beam_angle(m, m.beams - 1), 1e-9);
  REAL_EQUAL(30.0, m.max_range_m, 0);
  CHECK_FALSE(lidar_model("nope", &m));
  for (const std::string& n : lidar_model_names()) CHECK_TRUE(lidar_model(n, nullptr));
  LONGS_EQUAL(4, lidar_model_names().size());
}

TEST(LidarSim, IdealScanMatchesGeometryAndCarriesMetadata) {
  World w;
  w.add_polyline({V(1, -50), V(1, 50)});
  const LidarModel m = ideal_model();
  Rng rng(1);
  static dockcore::LaserScan s;
  simulate_scan(w, Pose2{}, m, rng, &s, 12345);
  LONGS_EQUAL(450, s.count);
  REAL_EQUAL(m.angle_min_rad, s.angle_min_rad, 1e-12);
  REAL_EQUAL(m.angle_increment_rad, s.angle_increment_rad, 1e-12);
  CHECK_EQUAL(12345u, s.stamp_us);
  int checked = 0;
  for (std::size_t i = 0; i < s.count; ++i) {
    const double a = beam_angle(m, i);
    const double expect = std::cos(a) > 1.0 / 12.0 ? 1.0 / std::cos(a) : 0.0;  // Beyond 12 m reads as 0.
    if (std::fabs(std::cos(a) - 1.0 / 12.0) < 1e-3) continue;                   // Skip the max-range border beam.
    REAL_EQUAL(expect, s.ranges_m[i], 1e-9);
    if (expect > 0) {
      CHECK_TRUE(s.intensities[i] > 0);
      ++checked;
    } else {
      REAL_EQUAL(0.0, s.intensities[i], 0);
    }
  }
  CHECK_TRUE(checked > 200);  // Beams in (-85°, 85°).
}

TEST(LidarSim, LidarPoseRotatesAndTranslatesTheBeams) {
  World w;
  w.add_polyline({V(-50, 4), V(50, 4)});  // y = 4.
  const LidarModel m = ideal_model();
  Rng rng(1);
  static dockcore::LaserScan s;
  simulate_scan(w, Pose2{2, 3, static_cast<Real>(kPi / 2)}, m, rng, &s);
  // Lidar at y = 3 facing +y: beam angle a (lidar frame) meets the wall at 1/cos(a).
  for (std::size_t i = 0; i < s.count; ++i) {
    const double a = beam_angle(m, i);
    if (std::cos(a) < 0.2) continue;
    REAL_EQUAL(1.0 / std::cos(a), s.ranges_m[i], 1e-9);
  }
}

TEST(LidarSim, BlindZoneAndMaxRangeReadZero) {
  LidarModel m = ideal_model("rplidar-a1");  // 0.15-12 m.
  static dockcore::LaserScan s;
  Rng rng(3);
  const std::size_t fwd = 180;  // angle_min = -pi, 1° steps: beam 180 is 0°.
  REAL_EQUAL(0.0, beam_angle(m, fwd), 1e-12);
  for (const double x : {0.10, 0.16, 11.9, 12.1}) {
    World w;
    w.add_polyline({V(x, -0.01), V(x, 0.01)});
    simulate_scan(w, Pose2{}, m, rng, &s);
    REAL_EQUAL((x > 0.15 && x < 12.0) ? x : 0.0, s.ranges_m[fwd], 1e-9);
  }
  // LD06 sees down to 0.02 m.
  m = ideal_model("ld06");
  World w;
  w.add_polyline({V(0.03, -0.01), V(0.03, 0.01)});
  simulate_scan(w, Pose2{}, m, rng, &s);
  REAL_EQUAL(0.03, s.ranges_m[225], 1e-9);
  World w2;
  w2.add_polyline({V(0.015, -0.001), V(0.015, 0.001)});
  simulate_scan(w2, Pose2{}, m, rng, &s);
  REAL_EQUAL(0.0, s.ranges_m[225], 0);
}

TEST(LidarSim, ConstantNoiseIsUnbiasedWithTheModelSigma) {
  LidarModel m = ideal_model("ld06");
  m.sigma_const_m = 0.010;
  World w;
  w.add_polyline({V(2, -50), V(2, 50)});
  Rng rng(11);
  static dockcore::LaserScan s;
  Stats st;
  for (int k = 0; k < 200; ++k) {
    simulate_scan(w, Pose2{}, m, rng, &s);
    for (std::size_t i = 0; i < s.count; ++i) {
      const double a = beam_angle(m, i);
      if (std::fabs(a) > 30 * kDeg) continue;
      st.add(s.ranges_m[i] - 2.0 / std::cos(a));
    }
  }
  CHECK_TRUE(st.n > 10000);
  REAL_EQUAL(0.0, st.mean(), 4 * 0.010 / std::sqrt(st.n));
  REAL_EQUAL(0.010, st.sd(), 0.0005);  // 5 %; the estimate's own spread is ~0.6 %.
}

TEST(LidarSim, ProportionalNoiseScalesWithRange) {
  LidarModel m = ideal_model("industrial");
  m.sigma_const_m = 0;
  m.sigma_prop = 0.01;
  World w;
  w.add_polyline({V(5, -50), V(5, 50)});
  Rng rng(12);
  static dockcore::LaserScan s;
  Stats rel;
  for (int k = 0; k < 100; ++k) {
    simulate_scan(w, Pose2{}, m, rng, &s);
    for (std::size_t i = 0; i < s.count; ++i) {
      const double a = beam_angle(m, i);
      if (std::fabs(a) > 40 * kDeg) continue;
      const double truth = 5.0 / std::cos(a);
      rel.add((s.ranges_m[i] - truth) / truth);
    }
  }
  REAL_EQUAL(0.0, rel.mean(), 4 * 0.01 / std::sqrt(rel.n));
  REAL_EQUAL(0.01, rel.sd(), 0.0005);
}

TEST(LidarSim, DropoutFractionMatches) {
  LidarModel m = ideal_model("ld06");
  m.dropout_prob = 0.2;
  const World w = room(3);
  Rng rng(5);
  static dockcore::LaserScan s;
  double zeros = 0, total = 0;
  for (int k = 0; k < 100; ++k) {
    simulate_scan(w, Pose2{0.3, -0.2, 0.4}, m, rng, &s);
    for (std::size_t i = 0; i < s.count; ++i) {
      zeros += s.ranges_m[i] == 0 ? 1 : 0;
      total += 1;
    }
  }
  // 45000 beams: 1 sigma of the fraction is 0.0019.
  REAL_EQUAL(0.2, zeros / total, 0.01);
}

TEST(LidarSim, AngularJitterSpreadsRangesOnASlantedWall) {
  LidarModel m = ideal_model("ld06");
  m.angular_jitter_rad = 0.005;
  World w;
  w.add_polyline({V(1, -50), V(1, 50)});
  Rng rng(8);
  static dockcore::LaserScan s;
  // Beam 281 is at -180° + 281*0.8° = 44.8°; r = 1/cos a, dr/da = sin a / cos^2 a.
  const std::size_t i = 281;
  const double a = beam_angle(m, i);
  Stats st;
  for (int k = 0; k < 4000; ++k) {
    simulate_scan(w, Pose2{}, m, rng, &s);
    st.add(s.ranges_m[i] - 1.0 / std::cos(a));
  }
  const double expect_sd = 0.005 * std::sin(a) / (std::cos(a) * std::cos(a));
  REAL_EQUAL(expect_sd, st.sd(), 0.1 * expect_sd);
}

TEST(LidarSim, MixedPixelsOnlyAtDepthEdgesAndBetweenTheSurfaces) {
  // A board 1 m ahead in front of a wall 2 m ahead: edges at +-atan(0.15).
  World w;
  w.add_polyline({V(1, -0.15), V(1, 0.15)});
  w.add_polyline({V(2, -50), V(2, 50)});
  LidarModel m = ideal_model("ld06");
  m.mixed_pixels = true;
  m.mixed_pixel_prob = 1.0;
  m.beam_divergence_rad = 2.0 * kDeg;  // Wide, so each edge has a beam straddling it in every scan.
  static dockcore::LaserScan s;
  Rng rng(9);
  int mixed = 0;
  for (int k = 0; k < 20; ++k) {
    simulate_scan(w, Pose2{}, m, rng, &s);
    for (std::size_t i = 0; i < s.count; ++i) {
      const double a = beam_angle(m, i);
      if (std::fabs(a) > 30 * kDeg) continue;
      const double board = std::fabs(std::tan(a)) <= 0.15 ? 1.0 / std::cos(a) : 0.0;
      const double wall = 2.0 / std::cos(a);  // Centre ray on the wall.
      const double r = s.ranges_m[i];
      const double edge_dist = std::fabs(std::fabs(a) - std::atan(0.15));
      if (edge_dist > 1.0 * kDeg + 1e-9) {
        REAL_EQUAL(board > 0 ? board : wall, r, 1e-9);  // Away from the edges: the surface itself.
      } else if (std::fabs(r - (board > 0 ? board : wall)) > 1e-9) {
        CHECK_TRUE(r > 0.99 && r < 2.0 / std::cos(std::fabs(a) + 1.0 * kDeg) + 1e-9);
        ++mixed;
      }
    }
  }
  CHECK_TRUE(mixed >= 20);  // At least one straddling beam per edge; prob 1 blends it.
  // Switched off: every beam reads a real surface.
  m.mixed_pixels = false;
  simulate_scan(w, Pose2{}, m, rng, &s);
  for (std::size_t i = 0; i < s.count; ++i) {
    const double a = beam_angle(m, i);
    if (std::fabs(a) > 30 * kDeg) continue;
    const double expect = std::fabs(std::tan(a)) <= 0.15 ? 1.0 / std::cos(a) : 2.0 / std::cos(a);
    REAL_EQUAL(expect, s.ranges_m[i], 1e-9);
  }
}

TEST(LidarSim, IntensityFollowsReflectivityRangeAndIncidence) {
  World w;
  w.add_polyline({V(1, -0.5), V(1, 0.5)}, false, 0.9);
  w.add_polyline({V(-1, -0.5), V(-1, 0.5)}, false, 0.3);
  w.add_polyline({V(-0.5, 3), V(0.5, 3)}, false, 0.9);
  LidarModel m = ideal_model("rplidar-a1");    // Beam 180 = 0°, 0 = -180°, 270 = +90°.
  m.intensity_output = IntensityOutput::kRaw;  // the surface model itself, not the A1's saturated quality
  Rng rng(1);
  static dockcore::LaserScan s;
  simulate_scan(w, Pose2{}, m, rng, &s);
  const double i_bright = s.intensities[180], i_dark = s.intensities[0], i_far = s.intensities[270];
  // Same range, head-on: ratio of reflectivities.
  REAL_EQUAL(3.0, i_bright / i_dark, 1e-9);
  // Range 3 vs 1 with ref range 4: (1 + 1/16) / (1 + 9/16).
  REAL_EQUAL((1 + 1.0 / 16) / (1 + 9.0 / 16), i_far / i_bright, 1e-9);
  // 20° off normal on the near wall: cos 20°, and range 1/cos 20°.
  const double a = 20 * kDeg, rr = 1 / std::cos(a);
  REAL_EQUAL(std::cos(a) * (1 + 1.0 / 16) / (1 + rr * rr / 16), s.intensities[200] / i_bright, 1e-9);
}

TEST(LidarSim, SameSeedSameScanDifferentSeedDifferentScan) {
  dockcore::DockProfile p;
  CHECK_TRUE(dockcore::builtin_profile("breakpoint", p) == dockcore::ProfileError::kOk);
  SceneSpec spec;
  spec.profile = p;
  spec.lidar_pose_in_world = Pose2{0, 0, 0.1};
  spec.dock_pose_in_world = dock_pose_in_world_from_lidar(spec.lidar_pose_in_world, 1.5, 0.2, 0.1);
  spec.clutter_level = 3;
  Rng scene_rng(77);
  const World w = build_scene(spec, scene_rng);
  LidarModel m;
  CHECK_TRUE(lidar_model("ld06", &m));
  m.dropout_prob = 0.05;
  m.angular_jitter_rad = 0.002;
  static dockcore::LaserScan a, b, c;
  Rng r1(42), r2(42), r3(43);
  simulate_scan(w, spec.lidar_pose_in_world, m, r1, &a, 7);
  simulate_scan(w, spec.lidar_pose_in_world, m, r2, &b, 7);
  simulate_scan(w, spec.lidar_pose_in_world, m, r3, &c, 7);
  LONGS_EQUAL(a.count, b.count);
  CHECK_EQUAL(0, std::memcmp(a.ranges_m, b.ranges_m, sizeof(Real) * a.count));
  CHECK_EQUAL(0, std::memcmp(a.intensities, b.intensities, sizeof(Real) * a.count));
  CHECK_TRUE(std::memcmp(a.ranges_m, c.ranges_m, sizeof(Real) * a.count) != 0);
  // Scene generation is deterministic too.
  Rng scene_rng2(77);
  const World w2 = build_scene(spec, scene_rng2);
  LONGS_EQUAL(w.segments.size(), w2.segments.size());
  for (std::size_t i = 0; i < w.segments.size(); ++i) {
    CHECK_TRUE(w.segments[i].a == w2.segments[i].a && w.segments[i].b == w2.segments[i].b);
  }
}

TEST(LidarSim, BucketedScanAgreesWithBruteForceRaycast) {
  // The per-scan bearing buckets must not lose a segment: compare with World::raycast beam by beam.
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    Rng rng(seed);
    ClutterSceneSpec cs;
    cs.lidar_pose_in_world = Pose2{static_cast<Real>(rng.uniform(-1, 1)), static_cast<Real>(rng.uniform(-1, 1)),
                                   static_cast<Real>(rng.uniform(-3, 3))};
    cs.clutter.clutter_level = 3;
    cs.clutter.look_alikes = 3;
    const World w = build_clutter_scene(cs, rng);
    const LidarModel m = ideal_model("industrial");
    static dockcore::LaserScan s;
    simulate_scan(w, cs.lidar_pose_in_world, m, rng, &s);
    for (std::size_t i = 0; i < s.count; ++i) {
      const double a = static_cast<double>(cs.lidar_pose_in_world.yaw_rad) + beam_angle(m, i);
      double r = 0;
      const bool hit = w.raycast(V(cs.lidar_pose_in_world.x_m, cs.lidar_pose_in_world.y_m), dir_of(a), 30, &r);
      // The scan's beam direction comes from a Real yaw plus the beam angle, rounded differently from a; its range
      // is stored in Real: a few ulps of r in float.
      DOUBLES_EQUAL(hit && r >= m.min_range_m ? r : 0.0, s.ranges_m[i], dockcore_test::real_tol(r, 1e-9, 16));
    }
  }
}

TEST_GROUP(Scenes){};

TEST(Scenes, DockPoseFromLidarFacesTheLidar) {
  Pose2 p = dock_pose_from_lidar(2.0, 0.0, 0.0);
  REAL_EQUAL(2.0, p.x_m, 1e-12);
  REAL_EQUAL(0.0, p.y_m, 1e-12);
  REAL_EQUAL(kPi, std::fabs(p.yaw_rad), 1e-12);
  p = dock_pose_from_lidar(1.5, kPi / 2, 0.0);
  REAL_EQUAL(0.0, p.x_m, 1e-12);
  REAL_EQUAL(1.5, p.y_m, 1e-12);
  REAL_EQUAL(-kPi / 2, p.yaw_rad, 1e-12);
  // With dock yaw 0.3 the dock's +x axis is 0.3 rad counter-clockwise from the direction to the lidar.
  const double bearing = -0.7;
  p = dock_pose_from_lidar(1.2, bearing, 0.3);
  const double to_lidar = std::atan2(-p.y_m, -p.x_m);
  REAL_EQUAL(0.3, dockcore::wrap_angle(p.yaw_rad - static_cast<Real>(to_lidar)), 1e-12);
  REAL_EQUAL(1.2, std::hypot(p.x_m, p.y_m), 1e-12);
  // In the world: the lidar frame composed with the relative pose.
  const Pose2 lidar{3, -1, 1.0};
  const Pose2 pw = dock_pose_in_world_from_lidar(lidar, 1.2, bearing, 0.3);
  const Pose2 back = lidar.inverse().compose(pw);
  REAL_EQUAL(p.x_m, back.x_m, 1e-12);
  REAL_EQUAL(p.y_m, back.y_m, 1e-12);
  REAL_EQUAL(p.yaw_rad, back.yaw_rad, 1e-12);
}

TEST(Scenes, WallIsFlushWithTheDockBackAndSpansBothSides) {
  dockcore::DockProfile p;
  CHECK_TRUE(dockcore::builtin_profile("breakpoint", p) == dockcore::ProfileError::kOk);  // min x = -0.10.
  SceneSpec spec;
  spec.profile = p;
  spec.dock_pose_in_world = Pose2{};
  spec.lidar_pose_in_world = Pose2{1.0, 0, static_cast<Real>(kPi)};
  spec.clutter_level = 0;
  Rng rng(1);
  std::vector<SceneObject> objs;
  const World w = build_scene(spec, rng, &objs);
  LONGS_EQUAL(p.segment_count() + 1, w.segments.size());
  LONGS_EQUAL(2, objs.size());
  double r = 0;
  std::size_t seg = 0;
  // Beside the dock the ray meets the wall at x = -0.10.
  for (const double y : {-2.5, -0.5, 0.5, 2.5}) {
    const Vec2 target = V(-0.10, y);
    const Vec2 d = (target - V(1, 0)).normalized();
    CHECK_TRUE(w.raycast_segment(V(1, 0), d, 20, &r, &seg));
    LONGS_EQUAL(p.segment_count(), seg);
    REAL_EQUAL((target - V(1, 0)).norm(), r, 1e-9);
  }
  // Straight on, the dock face at x = 0 comes first.
  CHECK_TRUE(w.raycast_segment(V(1, 0), V(-1, 0), 20, &r, &seg));
  REAL_EQUAL(1.0, r, 1e-12);
  CHECK_TRUE(seg < p.segment_count());
}

namespace {

// Dock outline points visible from the lidar with nothing but the dock in the world.
std::vector<Vec2> visible_dock_points(const dockcore::DockProfile& p, const Pose2& dock, const Vec2& lidar) {
  World alone;
  alone.add_dock(p, dock);
  std::vector<Vec2> out;
  for (const Vec2& q : dock_outline_points(p, dock, 7)) {
    double r = 0;
    const double d = (q - lidar).norm();
    // q, lidar and d are Real: in float the ray's hit and |q - lidar| agree to a few ulps of d, not to 1e-9.
    if (alone.raycast(lidar, (q - lidar) / d, 50, &r) && std::fabs(r - d) < dockcore_test::real_tol(d, 1e-9, 16)) {
      out.push_back(q);
    }
  }
  return out;
}

}  // namespace

TEST(Scenes, ClutterNeverHidesTheDockNorContainsTheLidar) {
  int scenes = 0, objects_placed = 0, points_checked = 0;
  for (const char* name : {"breakpoint", "v-marker", "plate-v"}) {
    dockcore::DockProfile p;
    CHECK_TRUE(dockcore::builtin_profile(name, p) == dockcore::ProfileError::kOk);
    for (std::uint64_t seed = 1; seed <= 30; ++seed) {
      Rng rng(seed * 1000 + 7);
      SceneSpec spec;
      spec.profile = p;
      spec.lidar_pose_in_world = Pose2{static_cast<Real>(rng.uniform(-2, 2)), static_cast<Real>(rng.uniform(-2, 2)),
                                       static_cast<Real>(rng.uniform(-kPi, kPi))};
      spec.dock_pose_in_world = dock_pose_in_world_from_lidar(spec.lidar_pose_in_world, rng.uniform(0.4, 3.0),
                                                              rng.uniform(-kPi, kPi), rng.uniform(-1.0, 1.0));
      spec.clutter_level = 3;
      spec.look_alikes = 3;
      std::vector<SceneObject> objs;
      const World w = build_scene(spec, rng, &objs);
      ++scenes;
      const Vec2 lidar = V(spec.lidar_pose_in_world.x_m, spec.lidar_pose_in_world.y_m);
      for (const SceneObject& o : objs) {
        if (o.kind == ObjectKind::kDock || o.kind == ObjectKind::kWall) continue;
        ++objects_placed;
        CHECK_TRUE((o.centre_m - lidar).norm() > o.radius_m + spec.clutter.lidar_clearance_m - 1e-9);
      }
      const std::vector<Vec2> pts = visible_dock_points(p, spec.dock_pose_in_world, lidar);
      CHECK_TRUE(pts.size() >= 7);  // At least one face's worth.
      for (const Vec2& q : pts) {
        double r = 0;
        std::size_t seg = 0;
        const double d = (q - lidar).norm();
        CHECK_TRUE(w.raycast_segment(lidar, (q - lidar) / d, 50, &r, &seg));
        CHECK_TRUE(seg < p.segment_count());  // Dock segments come first.
        DOUBLES_EQUAL(d, r, dockcore_test::real_tol(d, 1e-9, 16));  // Real points: see visible_dock_points
        ++points_checked;
      }
    }
  }
  CHECK_TRUE(objects_placed > scenes * 8);  // Level 3 + 3 look-alikes asks for 15 per scene; most fit.
  CHECK_TRUE(points_checked > 1000);
}

TEST(Scenes, WithoutDockKeepsTheSameClutter) {
  dockcore::DockProfile p;
  CHECK_TRUE(dockcore::builtin_profile("plate-v", p) == dockcore::ProfileError::kOk);
  SceneSpec spec;
  spec.profile = p;
  spec.lidar_pose_in_world = Pose2{};
  spec.dock_pose_in_world = dock_pose_from_lidar(1.0, 0.3, 0.0);
  spec.clutter_level = 2;
  Rng a(5), b(5);
  const World with = build_scene(spec, a);
  spec.with_dock = false;
  const World without = build_scene(spec, b);
  LONGS_EQUAL(with.segments.size() - p.segment_count(), without.segments.size());
  for (std::size_t i = 0; i < without.segments.size(); ++i) {
    CHECK_TRUE(without.segments[i].a == with.segments[i + p.segment_count()].a);
  }
}

TEST(Scenes, ClutterSceneHasARoomAroundTheLidarAndTheLookAlikes) {
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    Rng rng(seed);
    ClutterSceneSpec cs;
    cs.lidar_pose_in_world = Pose2{1, 2, 0.5};
    cs.clutter.clutter_level = 2;
    cs.clutter.look_alikes = 3;
    std::vector<SceneObject> objs;
    const World w = build_clutter_scene(cs, rng, &objs);
    int look = 0;
    for (const SceneObject& o : objs) {
      if (o.kind == ObjectKind::kLookAlikeBoard || o.kind == ObjectKind::kLookAlikeCorner ||
          o.kind == ObjectKind::kLookAlikeBox)
        ++look;
      if (o.kind != ObjectKind::kWall) CHECK_TRUE((o.centre_m - V(1, 2)).norm() > o.radius_m);
    }
    LONGS_EQUAL(3, look);
    // Closed room: every beam of an ideal scan returns, within the room's diagonal (<= 2*sqrt(2)*5 m).
    const LidarModel m = ideal_model("industrial");
    static dockcore::LaserScan s;
    simulate_scan(w, cs.lidar_pose_in_world, m, rng, &s);
    for (std::size_t i = 0; i < s.count; ++i) {
      CHECK_TRUE(s.ranges_m[i] > 0.3 && s.ranges_m[i] < 10 * std::sqrt(2.0));
    }
  }
}

// What each model reports as intensity, judged by the core's intensity check as a real sensor's would be: an LD06's
// 0..255 follows the surfaces and is usable; an RPLIDAR's standard-scan quality saturates at 15 as a real A1's does;
// express mode's constant 47 is flat and a driver without intensity is absent.
TEST(LidarSim, IntensityOutputsAreJudgedAsTheRealSensorsAre) {
  World w = room(1.5);
  w.add_box(V(0.6, 0.4), 0.3, 0.4, 0.3, 0.9);
  w.add_circle(V(-0.5, -0.6), 0.1, 12, 0.2);
  struct Case {
    const char* model;
    const char* output;
    dockcore::IntensityVerdict want;
  };
  const Case cases[] = {{"ld06", nullptr, dockcore::IntensityVerdict::kUsable},
                        {"rplidar-a1", nullptr, dockcore::IntensityVerdict::kFlat},
                        {"rplidar-a2", "constant", dockcore::IntensityVerdict::kFlat},
                        {"ld06", "none", dockcore::IntensityVerdict::kAbsent},
                        {"industrial", nullptr, dockcore::IntensityVerdict::kUsable}};
  for (const Case& c : cases) {
    LidarModel m;
    CHECK(lidar_model(c.model, &m));
    if (c.output != nullptr) CHECK(intensity_output(c.output, &m.intensity_output));
    Rng rng(7);
    dockcore::IntensityCheck check;
    dockcore::LaserScan scan;
    for (int k = 0; k < 20; ++k) {
      const Pose2 pose{static_cast<Real>(0.02 * k - 0.2), static_cast<Real>(-0.1), static_cast<Real>(0.05 * k)};
      simulate_scan(w, pose, m, rng, &scan);
      check.add(scan.view());
    }
    if (check.verdict() != c.want) {
      std::printf("%s/%s: %s, last share %.2f of %u\n", c.model, to_string(m.intensity_output),
                  dockcore::to_string(check.verdict()), static_cast<double>(check.last().share),
                  static_cast<unsigned>(check.last().returns));
    }
    CHECK(check.verdict() == c.want);
  }
  dockcore::LaserScan scan;
  LidarModel m;
  CHECK(lidar_model("ld06", &m));
  Rng rng(1);
  simulate_scan(w, Pose2{}, m, rng, &scan);
  for (std::size_t i = 0; i < scan.count; ++i) {
    CHECK(scan.intensities[i] == std::round(scan.intensities[i]));
    CHECK(scan.intensities[i] >= 0 && scan.intensities[i] <= 255);
  }
  IntensityOutput o;
  CHECK(!intensity_output("bright", &o));
}

// Retro-reflective tape saturates an LD06 at every docking range and at incidences up to the cut-off; the face
// around it reads as diffuse, and a beam whose footprint straddles a stripe's end reads in between.
TEST(LidarSim, TapeReadsSaturatedTheFaceDiffuseAndItsEdgesInBetween) {
  dockcore::DockProfile p;
  CHECK(dockcore::builtin_profile("plate-v", p) == dockcore::ProfileError::kOk);
  dockcore::ReflectorStripe st;
  st.segment = 1;
  st.from_m = static_cast<Real>(0.10);
  st.to_m = static_cast<Real>(0.20);
  CHECK(dockcore::add_reflector(p, st) == dockcore::ProfileError::kOk);
  LidarModel m = ideal_model("ld06");
  m.beams = 3600;  // 0.1°: several beams on the stripe and on its ends
  m.angle_increment_rad = 2 * kPi / 3600;
  for (const double dist : {0.4, 1.2, 2.4}) {
    for (const double yaw_deg : {0.0, 40.0}) {
      World w;
      w.add_dock(p, Pose2{static_cast<Real>(dist), 0, static_cast<Real>(kPi + yaw_deg * kDeg)}, 0.8);
      CHECK(w.has_retro());
      Rng rng(1);
      static dockcore::LaserScan s;
      simulate_scan(w, Pose2{}, m, rng, &s);
      int tape = 0, face = 0, between = 0;
      for (std::size_t i = 0; i < s.count; ++i) {
        if (s.ranges_m[i] <= 0) continue;
        const double v = static_cast<double>(s.intensities[i]);
        if (v >= 255)
          ++tape;
        else if (v < 235)
          ++face;
        else
          ++between;
      }
      CHECK_TEXT(tape >= 3, "tape beams");
      CHECK_TEXT(face >= 10, "face beams");
      CHECK(between <= 4);  // only footprints straddling a stripe end
    }
  }
  // Past the cut-off angle the tape is an ordinary surface.
  World w;
  w.add_dock(p, Pose2{static_cast<Real>(1.0), 0, static_cast<Real>(kPi + 70 * kDeg)}, 0.8);
  Rng rng(1);
  static dockcore::LaserScan s;
  simulate_scan(w, Pose2{}, ideal_model("ld06"), rng, &s);
  for (std::size_t i = 0; i < s.count; ++i) CHECK(s.intensities[i] < 235);
}

// A segment's own retro cut-off (chrome): bright only within it of normal incidence, diffuse past it, while tape with
// the model's cut-off stays bright at the same incidence.
TEST(LidarSim, SegmentRetroCutoffOverridesTheModels) {
  for (const double inc_deg : {0.0, 8.0, 25.0}) {
    for (const bool chrome : {true, false}) {
      World w;
      Segment g;  // A 0.3 m board 1 m ahead, turned by inc_deg about its centre.
      const double c = std::cos(inc_deg * kDeg), s = std::sin(inc_deg * kDeg);
      g.a = Vec2(static_cast<Real>(1.0 - 0.15 * s), static_cast<Real>(-0.15 * c));
      g.b = Vec2(static_cast<Real>(1.0 + 0.15 * s), static_cast<Real>(0.15 * c));
      g.retro = true;
      if (chrome) g.retro_cutoff_rad = 12 * kDeg;
      w.segments.push_back(g);
      LidarModel m = ideal_model("ld06");
      Rng rng(1);
      static dockcore::LaserScan scan;
      simulate_scan(w, Pose2{}, m, rng, &scan);
      const std::size_t centre = static_cast<std::size_t>(std::lround(-m.angle_min_rad / m.angle_increment_rad));
      CHECK(scan.ranges_m[centre] > 0);
      const bool bright = scan.intensities[centre] >= 255;
      CHECK_EQUAL(!chrome || inc_deg < 12.0, bright);
    }
  }
}
