// read_reflector_stripes on simulated scans: taped docks at charger range and at 1 m (noise, mixed pixels, a mounted
// lidar), an untaped face, flat and absent intensities, too few beams and too many runs.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <utility>

#include "dockcore/perception/dock_profile.hpp"
#include "dockcore/perception/profile_geometry.hpp"
#include "dockcore/perception/reflector_read.hpp"
#include "docksim/lidar_sim.hpp"
#include "docksim/scenes.hpp"

#include "coded_docks.hpp"
#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using dockcore_test::coded_plate;
using dockcore_test::ld06;
using dockcore_test::pose;

namespace {

LaserScan g_scan;

/// Simulates `prof` with the robot at the world origin, its lidar at `mount`, the dock `dist` metres in front of the
/// lidar at `bearing` and turned by `yaw`. Returns the dock's pose in the robot frame.
Pose2 simulate(const DockProfile& prof, double dist, double bearing, double yaw, const docksim::LidarModel& model,
               std::uint64_t seed, const Pose2& mount = Pose2{}) {
  docksim::SceneSpec spec;
  spec.profile = prof;
  spec.lidar_pose_in_world = mount;
  spec.dock_pose_in_world = docksim::dock_pose_in_world_from_lidar(mount, dist, bearing, yaw);
  spec.clutter_level = 0;
  docksim::Rng rng(seed);
  const docksim::World w = docksim::build_scene(spec, rng);
  docksim::simulate_scan(w, mount, model, rng, &g_scan, 1000);
  return spec.dock_pose_in_world;
}

/// The largest edge error of `got` against `want`'s stripes, metres; 1 when the counts or segments differ.
double worst_edge_error(const StripeRead& got, const DockProfile& want) {
  if (got.count != want.reflector_count) return 1;
  double worst = 0;
  for (std::size_t q = 0; q < got.count; ++q) {
    if (got.stripes[q].segment != want.reflectors[q].segment) return 1;
    worst = std::max(worst, std::fabs(static_cast<double>(got.stripes[q].from_m - want.reflectors[q].from_m)));
    worst = std::max(worst, std::fabs(static_cast<double>(got.stripes[q].to_m - want.reflectors[q].to_m)));
  }
  return worst;
}

}  // namespace

TEST_GROUP(ReflectorRead){};

// On the charger the lidar sees the face from 0.15-0.4 m: each edge is read to within a beam spacing (2-6 mm), whatever
// the noise, mixed pixels at the wings' depth edges, a lidar mounted off the robot's centre and a dock a little
// turned; what was read makes a valid profile again.
TEST(ReflectorRead, TapedDockAtTeachRange) {
  const DockProfile code = coded_plate({{0.0, 0.10}, {0.15, 0.19}, {0.24, 0.30}});
  const docksim::LidarModel m = ld06(0.005);
  StripeReadParams params;
  double worst = 0;
  int n = 0;
  for (double dist : {0.15, 0.25, 0.4}) {
    for (double yaw_deg : {-8.0, 0.0, 8.0}) {
      for (std::uint64_t seed = 1; seed <= 3; ++seed) {
        const Pose2 mount = pose(0.12, -0.02, seed == 3 ? kPi : 0.0);
        const Pose2 dock = simulate(code, dist, deg_to_rad(yaw_deg * 0.5), deg_to_rad(yaw_deg), m, seed, mount);
        const StripeRead r = read_reflector_stripes(g_scan.view(), mount, code, dock, params);
        char msg[160];
        std::snprintf(msg, sizeof msg, "%.2f m, yaw %.0f deg, seed %d: %s, %zu stripes, error %.1f mm", dist, yaw_deg,
                      static_cast<int>(seed), to_string(r.status), r.count, worst_edge_error(r, code) * 1e3);
        CHECK_TEXT(r.status == StripeReadStatus::kOk, msg);
        // An edge lies between two beams: within a beam spacing on the face (0.8° at the range), plus the jitter's
        // and the footprint's blur.
        CHECK_TEXT(worst_edge_error(r, code) < 0.002 + dist * deg_to_rad(0.8), msg);
        worst = std::max(worst, worst_edge_error(r, code));
        ++n;
        DockProfile again;
        CHECK_EQUAL(static_cast<int>(ProfileError::kOk), static_cast<int>(builtin_profile("plate-v", again)));
        for (std::size_t q = 0; q < r.count; ++q) {
          CHECK_EQUAL(static_cast<int>(ProfileError::kOk), static_cast<int>(add_reflector(again, r.stripes[q])));
        }
      }
    }
  }
  std::printf("\nteach range: %d scans, worst edge error %.1f mm\n", n, worst * 1e3);
}

// At 1 m a beam covers 14 mm of the face: the edges are read to about half that, and a 6 cm stripe still reads.
TEST(ReflectorRead, TapedDockAtOneMetre) {
  const DockProfile code = coded_plate({{0.02, 0.08}, {0.12, 0.18}, {0.22, 0.28}});
  const docksim::LidarModel m = ld06(0.01);
  double worst = 0;
  for (double bearing_deg : {-20.0, 0.0, 20.0}) {
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      const Pose2 dock = simulate(code, 1.0, deg_to_rad(bearing_deg), deg_to_rad(10.0), m, seed);
      const StripeRead r = read_reflector_stripes(g_scan.view(), Pose2{}, code, dock, StripeReadParams{});
      CHECK(r.status == StripeReadStatus::kOk);
      CHECK_EQUAL(3u, r.count);
      worst = std::max(worst, worst_edge_error(r, code));
    }
  }
  std::printf("\n1 m: worst edge error %.1f mm\n", worst * 1e3);
  CHECK(worst < 0.010);
}

// A face without tape reads no stripes, and so does a tape pattern read on another pose of the dock.
TEST(ReflectorRead, UntapedFaceReadsNoStripes) {
  const DockProfile plain = coded_plate({});
  for (double dist : {0.2, 1.0}) {
    const Pose2 dock = simulate(plain, dist, 0.0, 0.0, ld06(0.005), 4);
    const StripeRead r = read_reflector_stripes(g_scan.view(), Pose2{}, plain, dock, StripeReadParams{});
    CHECK(r.status == StripeReadStatus::kOk);
    CHECK_EQUAL(0u, r.count);
    CHECK(r.inlier_beams >= 10);
    CHECK_EQUAL(0, r.bright_beams);
  }
}

// An RPLIDAR's flat quality (15, or a constant 47 in express mode) and a driver without intensities never give
// stripes; a scan without an intensity array says so.
TEST(ReflectorRead, FlatOrAbsentIntensityReadsNoStripes) {
  const DockProfile code = coded_plate({{0.0, 0.10}, {0.20, 0.30}});
  for (docksim::IntensityOutput o : {docksim::IntensityOutput::kRplidarQuality, docksim::IntensityOutput::kConstant,
                                     docksim::IntensityOutput::kNone}) {
    docksim::LidarModel m = ld06(0.005);
    m.intensity_output = o;
    const Pose2 dock = simulate(code, 0.3, 0.0, 0.0, m, 5);
    const StripeRead r = read_reflector_stripes(g_scan.view(), Pose2{}, code, dock, StripeReadParams{});
    CHECK_EQUAL(0u, r.count);
    CHECK_EQUAL(0, r.bright_beams);
    if (o != docksim::IntensityOutput::kRplidarQuality) CHECK(r.status == StripeReadStatus::kNoIntensity);
  }
  const Pose2 dock = simulate(code, 0.3, 0.0, 0.0, ld06(0.005), 5);
  ScanView v = g_scan.view();
  v.intensities = nullptr;
  const StripeRead r = read_reflector_stripes(v, Pose2{}, code, dock, StripeReadParams{});
  CHECK(r.status == StripeReadStatus::kNoIntensity);
  CHECK_EQUAL(0u, r.count);
  STRCMP_EQUAL("no_intensity", to_string(r.status));
}

// A pose where the dock is not (or a dock out of sight) has too few beams on it to read anything.
TEST(ReflectorRead, NoDockAtThePoseIsTooFewBeams) {
  const DockProfile code = coded_plate({{0.0, 0.10}});
  simulate(code, 0.3, 0.0, 0.0, ld06(0.005), 6);
  const StripeRead r =
      read_reflector_stripes(g_scan.view(), Pose2{}, code, pose(0.0, 0.8, -kPi / 2), StripeReadParams{});
  CHECK(r.status == StripeReadStatus::kTooFewBeams);
  CHECK_EQUAL(0u, r.count);
  ScanView empty{};
  CHECK(read_reflector_stripes(empty, Pose2{}, code, pose(0.3, 0, kPi), StripeReadParams{}).status ==
        StripeReadStatus::kTooFewBeams);
}

// Bright and dark beams in alternating blocks of 12 (11 mm) across the face (a patterned surface, not tape) are more
// runs than a profile can carry: no stripes at all rather than the first eight.
TEST(ReflectorRead, TooManyRunsIsNoCode) {
  DockProfile plate;
  CHECK_EQUAL(static_cast<int>(ProfileError::kOk), static_cast<int>(builtin_profile("plate-v", plate)));
  const Pose2 dock = pose(0.3, 0.0, kPi);
  PlacedProfile placed;
  placed.place(plate, dock);
  g_scan.reset(2000, -kPi, 2 * kPi / 2000, 0);
  for (std::size_t i = 0; i < g_scan.count; ++i) {
    const Real a = g_scan.view().angle_rad(i);
    Real range_m = 0;
    std::size_t seg = 0;
    if (placed.raycast(Vec2(std::cos(a), std::sin(a)), &range_m, &seg)) g_scan.ranges_m[i] = range_m;
    g_scan.intensities[i] = static_cast<Real>((i / 12) % 2 == 0 ? 250 : 100);
  }
  const StripeRead r = read_reflector_stripes(g_scan.view(), Pose2{}, plate, dock, StripeReadParams{});
  CHECK(r.status == StripeReadStatus::kTooManyStripes);
  CHECK_EQUAL(0u, r.count);
  // The same beams with one bright block in the face's middle: one stripe, its edges half-way between beams.
  for (std::size_t i = 0; i < g_scan.count; ++i) {
    const Real a = g_scan.view().angle_rad(i);
    g_scan.intensities[i] = static_cast<Real>(std::fabs(static_cast<double>(a)) < 0.2 ? 250 : 100);
  }
  const StripeRead one = read_reflector_stripes(g_scan.view(), Pose2{}, plate, dock, StripeReadParams{});
  CHECK(one.status == StripeReadStatus::kOk);
  CHECK_EQUAL(1u, one.count);
  CHECK_EQUAL(1, one.stripes[0].segment);
  // |bearing| < 0.2 rad at 0.3 m: 0.3·tan(0.2) = 60.8 mm either side of the face's centre (0.15 m along it).
  const double half_m = 0.3 * std::tan(0.2);
  const double spacing_m = 0.3 * 2 * kPi / 2000;
  DOUBLES_EQUAL(0.15 - half_m, static_cast<double>(one.stripes[0].from_m), spacing_m);
  DOUBLES_EQUAL(0.15 + half_m, static_cast<double>(one.stripes[0].to_m), spacing_m);
}
