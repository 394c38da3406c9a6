// `dock-sim perception`: how well each dock detector does on the same seeded simulated scans, next to the
// Cramér–Rao bound; false positives on dock-less clutter; cost per scan. Figures are printed, never asserted.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "detectors.hpp"
#include "dockcore/breakpoint_detector.hpp"
#include "dockcore/dock_pose_estimator.hpp"
#include "dockcore/dock_pose_filter.hpp"
#include "dockcore/line_segments.hpp"
#include "dockcore/vmarker_detector.hpp"
#include "docksim/crlb.hpp"
#include "docksim/lidar_sim.hpp"
#include "docksim/profile_file.hpp"
#include "docksim/rng.hpp"
#include "docksim/scenes.hpp"
#include "perception_generated.hpp"
#include "perception_stats.hpp"

namespace docksim_cli {
namespace {

using dockcore::Pose2;
using dockcore::Real;
using json = nlohmann::ordered_json;

constexpr double kDeg = dockcore::kPi / 180.0;
const double kBandEdges[] = {0.3, 0.6, 1.0, 1.5, 2.0, 2.5};
constexpr int kBands = 5;
constexpr int kConfirmScans = 3;

struct Options {
  std::vector<std::string> profiles{"plate-v", "v-marker", "breakpoint"};
  std::vector<std::string> lidars{"ld06", "rplidar-a1", "industrial"};
  std::vector<double> sigmas{0.005, 0.010, 0.020};
  int trials = 300;          // per (profile, lidar, sigma)
  int target_trials = 1000;  // target-zone runs (LD06, σ 10 mm)
  int fp_scenes = 1000;      // dock-less scenes per clutter kind
  int filter_runs = 200;     // 1 s filtered runs at d <= 1 m
  int clutter = 1;
  std::uint64_t seed = 1;
  bool json_out = false;
  bool cost = false;
  int points = 720;
  int scans = 200;
  std::string cost_detector = "all";
};

/// Accumulates one cell of a results table.
struct Cell {
  int n = 0;
  int found = 0;
  bool has_yaw = true;
  std::vector<double> pos, lon, lat, yaw, crlb_lat, crlb_yaw;

  void add(bool ok, const Errors& e, const docksim::Crlb& b) {
    ++n;
    if (b.ok) {
      crlb_lat.push_back(b.sigma_lateral_m);
      crlb_yaw.push_back(b.sigma_yaw_rad);
    }
    if (!ok) return;
    ++found;
    pos.push_back(e.pos_m);
    lon.push_back(e.lon_m);
    lat.push_back(e.lat_m);
    yaw.push_back(e.yaw_rad);
  }
  json to_json() const {
    auto mm = [](double v) { return std::isnan(v) ? json(nullptr) : json(std::round(v * 1e4) / 10.0); };
    auto dg = [](double v) { return std::isnan(v) ? json(nullptr) : json(std::round(v / kDeg * 100) / 100.0); };
    json j;
    j["n"] = n;
    j["detection_rate"] = n ? static_cast<double>(found) / n : 0.0;
    j["pos_mm"] = {
        {"p50", mm(percentile(pos, 0.5))}, {"p95", mm(percentile(pos, 0.95))}, {"max", mm(percentile(pos, 1.0))}};
    j["lateral_mm"] = {
        {"p50", mm(percentile(lat, 0.5))}, {"p95", mm(percentile(lat, 0.95))}, {"max", mm(percentile(lat, 1.0))}};
    j["longitudinal_mm"] = {
        {"p50", mm(percentile(lon, 0.5))}, {"p95", mm(percentile(lon, 0.95))}, {"max", mm(percentile(lon, 1.0))}};
    if (has_yaw) {
      j["yaw_deg"] = {
          {"p50", dg(percentile(yaw, 0.5))}, {"p95", dg(percentile(yaw, 0.95))}, {"max", dg(percentile(yaw, 1.0))}};
    } else {
      j["yaw_deg"] = nullptr;
    }
    j["crlb_lateral_mm_median"] = mm(percentile(crlb_lat, 0.5));
    j["crlb_yaw_deg_median"] = dg(percentile(crlb_yaw, 0.5));
    return j;
  }
};

int band_of(double d) {
  for (int b = 0; b < kBands; ++b) {
    if (d < kBandEdges[b + 1]) return b;
  }
  return kBands - 1;
}

std::string band_name(int b) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f-%.1f m", kBandEdges[b], kBandEdges[b + 1]);
  return buf;
}

/// Thresholds of the estimator for a lidar whose range noise is sigma_m (the user configures the same).
dockcore::EstimatorParams params_for(double sigma_m) {
  return dockcore::estimator_params_for_noise(static_cast<Real>(sigma_m));
}

docksim::LidarModel lidar(const std::string& name, double sigma) {
  docksim::LidarModel m;
  if (!docksim::lidar_model(name, &m)) throw CLI::ValidationError("--lidars", "unknown lidar model " + name);
  m.sigma_const_m = sigma;
  m.sigma_prop = 0;
  return m;
}

/// One simulated docking scene seen from the origin.
struct Scene {
  Pose2 truth;  // dock in the lidar (= robot) frame
  dockcore::LaserScan scan;
};

void simulate(const dockcore::DockProfile& prof, const docksim::LidarModel& m, double d, double b, double y,
              int clutter, docksim::Rng& rng, Scene* out) {
  docksim::SceneSpec spec;
  spec.profile = prof;
  spec.dock_pose_in_world = docksim::dock_pose_from_lidar(d, b, y);
  spec.lidar_pose_in_world = Pose2{};
  spec.clutter_level = clutter;
  const docksim::World w = docksim::build_scene(spec, rng);
  out->truth = spec.dock_pose_in_world;
  docksim::simulate_scan(w, Pose2{}, m, rng, &out->scan, 0);
}

struct Progress {
  const char* what;
  long total;
  long done = 0;
  void tick() {
    ++done;
    if (done % 50 == 0 || done == total) {
      std::fprintf(stderr, "\r%-28s %6ld / %ld", what, done, total);
      if (done == total) std::fprintf(stderr, "\n");
    }
  }
};

// ---------------------------------------------------------------- accuracy over the full grid

json run_accuracy(const Options& o) {
  json out = json::array();
  auto scene = std::make_unique<Scene>();
  for (const auto& pname : o.profiles) {
    const dockcore::DockProfile prof = docksim::resolve_profile(pname);
    for (const auto& lname : o.lidars) {
      for (double sigma : o.sigmas) {
        const docksim::LidarModel m = lidar(lname, sigma);
        DetectorSet set(prof, params_for(sigma), {Detector::kEstimator, Detector::kBreakpoint, Detector::kVMarker});
        std::map<std::string, std::vector<Cell>> cells;  // detector -> bands
        docksim::Rng rng(o.seed);
        Progress pr{"accuracy", o.trials};
        for (int t = 0; t < o.trials; ++t) {
          const double d = rng.uniform(0.3, 2.5);
          const double b = rng.uniform(-60, 60) * kDeg;
          const double y = rng.uniform(-45, 45) * kDeg;
          simulate(prof, m, d, b, y, o.clutter, rng, scene.get());
          const docksim::Crlb bound =
              docksim::dock_pose_crlb(prof, scene->truth, m.angle_min_rad, m.angle_increment_rad, m.beams, sigma, 0);
          for (const DetectorResult& r : set.run(scene->scan.view(), Pose2{})) {
            if (!r.applicable) continue;
            auto& bands = cells[detector_name(r.detector)];
            if (bands.empty()) bands.resize(kBands);
            Cell& c = bands[static_cast<std::size_t>(band_of(d))];
            c.has_yaw = r.has_yaw;
            c.add(r.found, errors_of(scene->truth, r.pose), bound);
          }
          pr.tick();
        }
        for (const auto& [det, bands] : cells) {
          for (int bi = 0; bi < kBands; ++bi) {
            json row;
            row["profile"] = pname;
            row["lidar"] = lname;
            row["sigma_mm"] = sigma * 1000;
            row["detector"] = det;
            row["band"] = band_name(bi);
            row.update(bands[static_cast<std::size_t>(bi)].to_json());
            out.push_back(row);
          }
        }
      }
    }
  }
  return out;
}

// ---------------------------------------------------------------- the targets

json run_targets(const Options& o) {
  json out;
  const double sigma = 0.010;
  const docksim::LidarModel m = lidar("ld06", sigma);
  auto scene = std::make_unique<Scene>();
  for (const auto& pname : o.profiles) {
    const dockcore::DockProfile prof = docksim::resolve_profile(pname);
    DetectorSet set(prof, params_for(sigma), {Detector::kEstimator, Detector::kBreakpoint, Detector::kVMarker});
    json pj;
    // Detection over the zone: d <= 2.0 m, |bearing| <= 45°, |yaw| <= 30°.
    std::map<std::string, Cell> zone;
    std::map<std::string, Cell> near;  // single scan at d <= 0.6 m
    docksim::Rng rng(o.seed + 101);
    Progress pr{"targets: zone", o.target_trials};
    for (int t = 0; t < o.target_trials; ++t) {
      const double d = rng.uniform(0.3, 2.0);
      const double b = rng.uniform(-45, 45) * kDeg;
      const double y = rng.uniform(-30, 30) * kDeg;
      simulate(prof, m, d, b, y, o.clutter, rng, scene.get());
      for (const DetectorResult& r : set.run(scene->scan.view(), Pose2{})) {
        if (!r.applicable) continue;
        Cell& c = zone[detector_name(r.detector)];
        c.has_yaw = r.has_yaw;
        c.add(r.found, errors_of(scene->truth, r.pose), docksim::Crlb{});
      }
      pr.tick();
    }
    Progress pr2{"targets: near", o.target_trials / 2};
    for (int t = 0; t < o.target_trials / 2; ++t) {
      const double d = rng.uniform(0.3, 0.6);
      const double b = rng.uniform(-45, 45) * kDeg;
      const double y = rng.uniform(-30, 30) * kDeg;
      simulate(prof, m, d, b, y, o.clutter, rng, scene.get());
      const docksim::Crlb bound =
          docksim::dock_pose_crlb(prof, scene->truth, m.angle_min_rad, m.angle_increment_rad, m.beams, sigma, 0);
      for (const DetectorResult& r : set.run(scene->scan.view(), Pose2{})) {
        if (!r.applicable) continue;
        Cell& c = near[detector_name(r.detector)];
        c.has_yaw = r.has_yaw;
        c.add(r.found, errors_of(scene->truth, r.pose), bound);
      }
      pr2.tick();
    }
    // One second of filtering (10 LD06 scans) from a standing robot at d <= 1.0 m, estimator in tracking mode.
    auto est = std::make_unique<dockcore::DockPoseEstimator>();
    est->configure(prof, params_for(sigma));
    Cell filtered;
    Progress pr3{"targets: filtered", o.filter_runs};
    for (int t = 0; t < o.filter_runs; ++t) {
      const double d = rng.uniform(0.3, 1.0);
      const double b = rng.uniform(-45, 45) * kDeg;
      const double y = rng.uniform(-30, 30) * kDeg;
      docksim::SceneSpec spec;
      spec.profile = prof;
      spec.dock_pose_in_world = docksim::dock_pose_from_lidar(d, b, y);
      spec.clutter_level = o.clutter;
      const docksim::World w = docksim::build_scene(spec, rng);
      dockcore::DockPoseFilter filter;
      const Pose2 odom{};
      for (int k = 0; k < 10; ++k) {
        docksim::simulate_scan(w, Pose2{}, m, rng, &scene->scan, static_cast<std::uint64_t>(k) * 100000);
        Pose2 hint{};
        const bool have = filter.initialised();
        if (have) hint = filter.dock_in_robot(odom);
        const dockcore::DockEstimate e = est->estimate(scene->scan.view(), Pose2{}, have ? &hint : nullptr);
        if (e.found) filter.update(e.pose, e.covariance, odom, scene->scan.stamp_us);
      }
      filtered.add(filter.initialised(), errors_of(spec.dock_pose_in_world, filter.dock_in_robot(odom)),
                   docksim::Crlb{});
      pr3.tick();
    }
    for (auto& [det, c] : zone) pj["zone_d<=2.0_b<=45_yaw<=30"][det] = c.to_json();
    for (auto& [det, c] : near) pj["single_scan_d<=0.6"][det] = c.to_json();
    pj["filtered_1s_d<=1.0"]["estimator"] = filtered.to_json();
    out[pname] = pj;
  }
  return out;
}

// ---------------------------------------------------------------- false positives

json run_false_positives(const Options& o) {
  json out;
  auto scan = std::make_unique<dockcore::LaserScan>();
  const double sigma = 0.010;
  const docksim::LidarModel m = lidar("ld06", sigma);
  for (const auto& pname : o.profiles) {
    const dockcore::DockProfile prof = docksim::resolve_profile(pname);
    DetectorSet set(prof, params_for(sigma), {Detector::kEstimator, Detector::kBreakpoint, Detector::kVMarker});
    // Hinted search: the dock is expected 1 m ahead (a dock database / staging pose), within 0.5 m.
    dockcore::EstimatorParams hinted = params_for(sigma);
    hinted.hint_radius_m = static_cast<Real>(0.5);
    auto est_hint = std::make_unique<dockcore::DockPoseEstimator>();
    est_hint->configure(prof, hinted);
    const Pose2 hint = docksim::dock_pose_from_lidar(1.0, 0.0, 0.0);
    auto est_confirm = std::make_unique<dockcore::DockPoseEstimator>();
    est_confirm->configure(prof, params_for(sigma));
    json pj;
    for (int kind = 0; kind < 2; ++kind) {
      const char* label = kind == 0 ? "clutter" : "clutter+look-alikes";
      std::map<std::string, int> fp;
      int fp_hint = 0;
      int fp_confirmed = 0;
      docksim::Rng rng(o.seed + 7 + static_cast<std::uint64_t>(kind));
      Progress pr{label, o.fp_scenes};
      for (int t = 0; t < o.fp_scenes; ++t) {
        docksim::ClutterSceneSpec spec;
        spec.clutter.clutter_level = 2;
        spec.clutter.look_alikes = kind == 0 ? 0 : 3;
        const docksim::World w = docksim::build_clutter_scene(spec, rng);
        docksim::simulate_scan(w, Pose2{}, m, rng, scan.get(), 0);
        for (const DetectorResult& r : set.run(scan->view(), Pose2{})) {
          if (!r.applicable) continue;
          fp[detector_name(r.detector)] += r.found ? 1 : 0;
        }
        if (est_hint->estimate(scan->view(), Pose2{}, &hint).found) ++fp_hint;
        // Acquisition confirmation: a standing robot takes kConfirmScans fresh scans and accepts the dock only when
        // every one finds it at a consistent pose (what a tracker does before it starts to move).
        {
          Pose2 first{};
          bool confirmed = true;
          for (int k = 0; k < kConfirmScans && confirmed; ++k) {
            if (k > 0) docksim::simulate_scan(w, Pose2{}, m, rng, scan.get(), 0);
            const dockcore::DockEstimate e = est_confirm->estimate(scan->view(), Pose2{});
            confirmed = e.found && (k == 0 || errors_of(first, e.pose).pos_m < 0.05);
            if (k == 0) first = e.pose;
          }
          if (confirmed) ++fp_confirmed;
        }
        pr.tick();
      }
      for (auto& [det, n] : fp) {
        pj[label][det] = {
            {"scenes", o.fp_scenes}, {"false_positives", n}, {"rate", static_cast<double>(n) / o.fp_scenes}};
      }
      pj[label]["estimator_confirmed_3_scans"] = {{"scenes", o.fp_scenes},
                                                  {"false_positives", fp_confirmed},
                                                  {"rate", static_cast<double>(fp_confirmed) / o.fp_scenes}};
      pj[label]["estimator_hinted_0.5m"] = {
          {"scenes", o.fp_scenes}, {"false_positives", fp_hint}, {"rate", static_cast<double>(fp_hint) / o.fp_scenes}};
    }
    out[pname] = pj;
  }
  return out;
}

// ---------------------------------------------------------------- cost

json run_cost(const Options& o) {
  json out;
  const dockcore::DockProfile prof = docksim::resolve_profile(o.profiles.front());
  docksim::LidarModel m = lidar("ld06", 0.010);
  m.beams = static_cast<std::size_t>(o.points);
  m.angle_increment_rad = 2 * dockcore::kPi / o.points;
  m.angle_min_rad = -dockcore::kPi;
  docksim::Rng rng(o.seed);
  docksim::SceneSpec spec;
  spec.profile = prof;
  spec.dock_pose_in_world = docksim::dock_pose_from_lidar(1.0, 0.3, 0.2);
  spec.clutter_level = 2;
  const docksim::World w = docksim::build_scene(spec, rng);
  std::vector<std::unique_ptr<dockcore::LaserScan>> scans;
  for (int k = 0; k < o.scans; ++k) {
    scans.push_back(std::make_unique<dockcore::LaserScan>());
    docksim::simulate_scan(w, Pose2{}, m, rng, scans.back().get(), 0);
  }
  auto want = [&o](const char* name) { return o.cost_detector == "all" || o.cost_detector == name; };
  auto time_it = [&](const char* name, auto&& fn) {
    std::vector<double> ns;
    int found = 0;
    for (auto& s : scans) {
      const auto t0 = std::chrono::steady_clock::now();
      found += fn(s->view()) ? 1 : 0;
      const auto t1 = std::chrono::steady_clock::now();
      ns.push_back(static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count()));
    }
    out[name] = {
        {"points", o.points}, {"scans", o.scans}, {"ns_per_scan_median", percentile(ns, 0.5)}, {"found", found}};
  };
  const dockcore::EstimatorParams params = params_for(0.010);
  if (want("estimator")) {
    auto est = std::make_unique<dockcore::DockPoseEstimator>();
    est->configure(prof, params);
    time_it("estimator", [&](const dockcore::ScanView& v) { return est->estimate(v, Pose2{}).found; });
  }
  if (want("estimator-tracking")) {
    auto est = std::make_unique<dockcore::DockPoseEstimator>();
    est->configure(prof, params);
    Pose2 last = spec.dock_pose_in_world;
    time_it("estimator-tracking", [&](const dockcore::ScanView& v) {
      const dockcore::DockEstimate e = est->estimate(v, Pose2{}, &last);
      if (e.found) last = e.pose;
      return e.found;
    });
  }
  if (want("breakpoint")) {
    auto bp = std::make_unique<dockcore::BreakpointDetector>();
    time_it("breakpoint", [&](const dockcore::ScanView& v) { return bp->detect(v).found; });
  }
  if (want("vmarker")) {
    auto pts = std::make_unique<dockcore::ScanPoints>();
    auto segs = std::make_unique<dockcore::LineSegments>();
    const dockcore::VMarkerDetector vm;
    time_it("vmarker", [&](const dockcore::ScanView& v) {
      dockcore::scan_to_points(v, Pose2{}, static_cast<Real>(0.05), static_cast<Real>(3.0), *pts);
      dockcore::extract_line_segments(*pts, v, dockcore::SegmentParams{}, *segs);
      return vm.detect(*segs).found;
    });
  }
  return out;
}

// ---------------------------------------------------------------- printing

void print_text(const json& j) {
  auto num = [](const json& v, const char* fmt) {
    static char buf[32];
    if (v.is_null()) return std::string("-");
    std::snprintf(buf, sizeof buf, fmt, v.get<double>());
    return std::string(buf);
  };
  if (j.contains("accuracy")) {
    std::printf("== Accuracy (single scan; errors in the dock frame; CRLB = Cramér–Rao bound, median per band)\n");
    std::printf("%-10s %-10s %4s %-10s %-9s %5s %6s | %6s %6s %6s | %6s %6s | %6s %6s | %6s %6s %6s | %6s\n", "profile",
                "lidar", "σmm", "detector", "band", "n", "det%", "pos50", "pos95", "posmx", "lat50", "lat95", "lon50",
                "lon95", "yaw50", "yaw95", "yawmx", "CRLB");
    for (const auto& r : j["accuracy"]) {
      std::printf("%-10s %-10s %4.0f %-10s %-9s %5d %6.1f | %6s %6s %6s | %6s %6s | %6s %6s | %6s %6s %6s | %s/%s\n",
                  r["profile"].get<std::string>().c_str(), r["lidar"].get<std::string>().c_str(),
                  r["sigma_mm"].get<double>(), r["detector"].get<std::string>().c_str(),
                  r["band"].get<std::string>().c_str(), r["n"].get<int>(), 100 * r["detection_rate"].get<double>(),
                  num(r["pos_mm"]["p50"], "%.1f").c_str(), num(r["pos_mm"]["p95"], "%.1f").c_str(),
                  num(r["pos_mm"]["max"], "%.0f").c_str(), num(r["lateral_mm"]["p50"], "%.1f").c_str(),
                  num(r["lateral_mm"]["p95"], "%.1f").c_str(), num(r["longitudinal_mm"]["p50"], "%.1f").c_str(),
                  num(r["longitudinal_mm"]["p95"], "%.1f").c_str(),
                  r["yaw_deg"].is_null() ? "-" : num(r["yaw_deg"]["p50"], "%.2f").c_str(),
                  r["yaw_deg"].is_null() ? "-" : num(r["yaw_deg"]["p95"], "%.2f").c_str(),
                  r["yaw_deg"].is_null() ? "-" : num(r["yaw_deg"]["max"], "%.1f").c_str(),
                  num(r["crlb_lateral_mm_median"], "%.1fmm").c_str(), num(r["crlb_yaw_deg_median"], "%.2f°").c_str());
    }
  }
  if (j.contains("targets")) {
    std::printf("\n== Targets (LD06, σ 10 mm)\n");
    for (const auto& [pname, pj] : j["targets"].items()) {
      for (const auto& [section, sj] : pj.items()) {
        for (const auto& [det, c] : sj.items()) {
          std::printf(
              "%-10s %-24s %-10s n=%-5d detected %6.2f%%  pos p95 %s mm  yaw p95 %s°  (CRLB lat %s mm, yaw %s°)\n",
              pname.c_str(), section.c_str(), det.c_str(), c["n"].get<int>(), 100 * c["detection_rate"].get<double>(),
              num(c["pos_mm"]["p95"], "%.1f").c_str(),
              c["yaw_deg"].is_null() ? "-" : num(c["yaw_deg"]["p95"], "%.2f").c_str(),
              num(c["crlb_lateral_mm_median"], "%.1f").c_str(), num(c["crlb_yaw_deg_median"], "%.2f").c_str());
        }
      }
    }
  }
  if (j.contains("false_positives")) {
    std::printf("\n== False positives (dock-less scenes, LD06 σ 10 mm, clutter level 2)\n");
    for (const auto& [pname, pj] : j["false_positives"].items()) {
      for (const auto& [kind, kj] : pj.items()) {
        for (const auto& [det, c] : kj.items()) {
          std::printf("%-10s %-20s %-22s %4d / %-5d = %6.2f%%\n", pname.c_str(), kind.c_str(), det.c_str(),
                      c["false_positives"].get<int>(), c["scenes"].get<int>(), 100 * c["rate"].get<double>());
        }
      }
    }
  }
  if (j.contains("cost")) {
    std::printf("\n== Cost per scan\n");
    for (const auto& [det, c] : j["cost"].items()) {
      std::printf("%-20s %5d points  median %10.0f ns/scan  (found in %d of %d scans)\n", det.c_str(),
                  c["points"].get<int>(), c["ns_per_scan_median"].get<double>(), c["found"].get<int>(),
                  c["scans"].get<int>());
    }
  }
}

std::vector<std::string> split_csv(const std::string& s) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= s.size()) {
    const std::size_t comma = s.find(',', start);
    const std::string item = s.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (!item.empty()) out.push_back(item);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

}  // namespace

void register_perception(CLI::App& app) {
  auto o = std::make_shared<Options>();
  auto profiles = std::make_shared<std::string>("plate-v,v-marker,breakpoint");
  auto lidars = std::make_shared<std::string>("ld06,rplidar-a1,industrial");
  auto sigmas = std::make_shared<std::string>("5,10,20");
  auto sections = std::make_shared<std::string>("accuracy,targets,fp");
  CLI::App* sub = app.add_subcommand(
      "perception", "Benchmark the dock detectors: accuracy vs CRLB, targets, false positives, cost per scan");
  sub->add_option("--profiles", *profiles, "Comma-separated profiles (built-in names or .toml files)");
  sub->add_option("--lidars", *lidars, "Comma-separated lidar models");
  sub->add_option("--sigmas-mm", *sigmas, "Comma-separated range noise levels, millimetres");
  sub->add_option("--sections", *sections, "Comma-separated: accuracy, targets, fp, generated");
  auto gen = std::make_shared<GeneratedOptions>();
  sub->add_option("--gen-scenes", gen->scenes, "generated: docking scenes (one scan each)")->check(CLI::PositiveNumber);
  sub->add_option("--gen-fp-scenes", gen->fp_scenes,
                  "generated: dock-less scenes, 3 scans each (default: as many as --gen-scenes)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--gen-filter-runs", gen->filter_runs,
                  "generated: 1 s filtered approaches (default: a fifth of --gen-scenes)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--gen-profiles", gen->profiles, "generated: random profiles in the pool")
      ->check(CLI::Range(1, 10000));
  sub->add_option("--jobs", gen->jobs, "generated: worker threads (the figures do not depend on it)")
      ->check(CLI::Range(1, 64));
  sub->add_option("--trials", o->trials, "Scenes per (profile, lidar, sigma) in the accuracy grid")
      ->check(CLI::PositiveNumber);
  sub->add_option("--target-trials", o->target_trials, "Scenes in the target zone")->check(CLI::PositiveNumber);
  sub->add_option("--fp-scenes", o->fp_scenes, "Dock-less scenes per clutter kind")->check(CLI::PositiveNumber);
  sub->add_option("--filter-runs", o->filter_runs, "1 s filtered runs")->check(CLI::PositiveNumber);
  sub->add_option("--clutter", o->clutter, "Clutter level of docking scenes (0-3)")->check(CLI::Range(0, 6));
  sub->add_option("--seed", o->seed, "Seed: same seed, same scenes, same figures");
  sub->add_flag("--json", o->json_out, "Print one JSON document instead of tables");
  sub->add_flag("--cost", o->cost, "Measure cost per scan instead (use with callgrind for instruction counts)");
  sub->add_option("--points", o->points, "Cost: points per scan (full turn)")->check(CLI::Range(16, 4096));
  sub->add_option("--scans", o->scans, "Cost: scans to run")->check(CLI::PositiveNumber);
  sub->add_option("--detector", o->cost_detector,
                  "Cost: all | estimator | estimator-tracking | breakpoint | vmarker (one detector for callgrind)")
      ->check(CLI::IsMember({"all", "estimator", "estimator-tracking", "breakpoint", "vmarker"}));
  sub->callback([o, gen, profiles, lidars, sigmas, sections]() {
    o->profiles = split_csv(*profiles);
    o->lidars = split_csv(*lidars);
    o->sigmas.clear();
    for (const auto& s : split_csv(*sigmas)) {
      try {
        o->sigmas.push_back(std::stod(s) / 1000.0);
      } catch (const std::exception&) {
        throw CLI::ValidationError("--sigmas-mm", "not a number: " + s);
      }
    }
    for (const auto& l : o->lidars) lidar(l, 0.01);  // validates the names before any work
    json j;
    if (o->cost) {
      j["cost"] = run_cost(*o);
    } else {
      const std::vector<std::string> secs = split_csv(*sections);
      for (const std::string& s : secs) {
        if (s != "accuracy" && s != "targets" && s != "fp" && s != "generated") {
          throw CLI::ValidationError("--sections", "unknown section " + s + " (accuracy, targets, fp, generated)");
        }
      }
      auto has = [&secs](const char* s) { return std::find(secs.begin(), secs.end(), s) != secs.end(); };
      if (has("accuracy")) j["accuracy"] = run_accuracy(*o);
      if (has("targets")) j["targets"] = run_targets(*o);
      if (has("fp")) j["false_positives"] = run_false_positives(*o);
      if (has("generated")) {
        gen->seed = o->seed;
        j["generated"] = run_generated(*gen);
      }
    }
    if (o->json_out) {
      std::printf("%s\n", j.dump().c_str());
    } else {
      print_text(j);
      if (j.contains("generated")) print_generated(j["generated"]);
    }
  });
}

}  // namespace docksim_cli
