// VMarkerDetector on the simulator's scenes: an LD06 model with σ 10 mm and mixed pixels, the dock against a wall
// with clutter, and dock-less cluttered rooms. The detector on scans raycast by hand is test_vmarker_detector.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "dockcore/perception/line_segments.hpp"
#include "dockcore/perception/vmarker_detector.hpp"
#include "docksim/lidar_sim.hpp"
#include "docksim/rng.hpp"
#include "docksim/scenes.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;

namespace {

LaserScan g_scan;
ScanPoints g_points;
LineSegments g_segs;

/// The detector on g_scan: points in the lidar frame (0.05-12 m), line segments, V search without a hint.
VMarkerDetection detect_scan(const VMarkerDetector& det) {
  scan_to_points(g_scan.view(), Pose2{}, 0.05, 12.0, g_points);
  extract_line_segments(g_points, g_scan.view(), SegmentParams{}, g_segs);
  return det.detect(g_segs, nullptr);
}

DockProfile vmarker() {
  DockProfile p;
  builtin_profile("v-marker", p);
  return p;
}

}  // namespace

TEST_GROUP(VMarkerSim){};

TEST(VMarkerSim, DockScenesWithClutter) {
  docksim::LidarModel model;
  CHECK_TRUE(docksim::lidar_model("ld06", &model));
  docksim::Rng rng(2024);
  const VMarkerDetector det;
  int found = 0;
  int good = 0;
  const int n = 300;
  std::vector<double> apex_err;
  std::vector<double> yaw_err;
  for (int k = 0; k < n; ++k) {
    docksim::SceneSpec spec;
    spec.profile = vmarker();
    const double d = rng.uniform(0.5, 1.5);
    const double bearing = rng.uniform(-deg_to_rad(30), deg_to_rad(30));
    const double yaw = rng.uniform(-deg_to_rad(30), deg_to_rad(30));
    spec.lidar_pose_in_world = Pose2{0, 0, 0};
    spec.dock_pose_in_world = docksim::dock_pose_from_lidar(d, bearing, yaw);
    spec.clutter_level = 2;
    const docksim::World world = docksim::build_scene(spec, rng);
    docksim::simulate_scan(world, spec.lidar_pose_in_world, model, rng, &g_scan);
    const VMarkerDetection r = detect_scan(det);
    if (!r.found) continue;
    ++found;
    const Pose2& t = spec.dock_pose_in_world;
    const double ae = (r.apex_m - t.transform(spec.profile.vertices_m[1])).norm();
    const double ye = std::fabs(wrap_angle(r.dock_pose.yaw_rad - t.yaw_rad));
    apex_err.push_back(ae);
    yaw_err.push_back(ye);
    if (ae < 0.02 && ye < deg_to_rad(3)) ++good;
  }
  std::sort(apex_err.begin(), apex_err.end());
  std::sort(yaw_err.begin(), yaw_err.end());
  const auto pct = [](const std::vector<double>& v, double q) {
    return v.empty() ? 0.0 : v[static_cast<std::size_t>(q * (v.size() - 1))];
  };
  std::printf(
      "\nVMarkerSim ld06 (sigma 10 mm), 0.5-1.5 m, +-30/+-30 deg, clutter 2: found %d/%d, within 2 cm & 3 deg %d; apex "
      "median %.1f p95 %.1f mm; yaw median %.2f p95 %.2f deg\n",
      found, n, good, 1000 * pct(apex_err, 0.5), 1000 * pct(apex_err, 0.95), rad_to_deg(pct(yaw_err, 0.5)),
      rad_to_deg(pct(yaw_err, 0.95)));
  // σ = 10 mm doubles the σ = 5 mm figures of the analytic sweep (yaw RMS ~1.7°); mixed pixels at the mouth ends
  // and the wall behind add a little.
  CHECK(found >= n * 97 / 100);
  CHECK(pct(apex_err, 0.95) < 0.02);
  CHECK(pct(yaw_err, 0.5) < deg_to_rad(2));
  CHECK(pct(yaw_err, 0.95) < deg_to_rad(5));
}

TEST(VMarkerSim, ClutterScenesWithoutDock) {
  // Dock-less rooms with clutter (boxes, table legs, people, 90° corners 0.3-1.5 m, wall pieces): false detections
  // are counted. No look-alikes: a 0.212 m-armed 90° V *is* the marker.
  docksim::LidarModel model;
  CHECK_TRUE(docksim::lidar_model("ld06", &model));
  docksim::Rng rng(99);
  const VMarkerDetector det;
  int false_pos = 0;
  const int n = 300;
  for (int k = 0; k < n; ++k) {
    docksim::ClutterSceneSpec spec;
    spec.clutter.clutter_level = 3;
    const docksim::World world = docksim::build_clutter_scene(spec, rng);
    docksim::simulate_scan(world, spec.lidar_pose_in_world, model, rng, &g_scan);
    if (detect_scan(det).found) ++false_pos;
  }
  std::printf("\nVMarkerSim clutter level 3, no dock: %d false detections in %d scans\n", false_pos, n);
  CHECK(false_pos <= n * 2 / 100);
}
