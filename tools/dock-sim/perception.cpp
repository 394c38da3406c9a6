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

#include "angles.hpp"
#include "commands.hpp"
#include "detectors.hpp"
#include "dockcore/control/controllers.hpp"
#include "dockcore/dockcore.hpp"
#include "dockcore/perception/breakpoint_detector.hpp"
#include "dockcore/perception/dock_pose_estimator.hpp"
#include "dockcore/perception/dock_pose_filter.hpp"
#include "dockcore/perception/line_segments.hpp"
#include "dockcore/perception/vmarker_detector.hpp"
#include "docksim/cli_checks.hpp"
#include "docksim/crlb.hpp"
#include "docksim/lidar_sim.hpp"
#include "docksim/profile_file.hpp"
#include "docksim/real_perception.hpp"
#include "docksim/realdata.hpp"
#include "docksim/rng.hpp"
#include "docksim/scenes.hpp"
#include "perception_generated.hpp"
#include "perception_reflectors.hpp"
#include "perception_stats.hpp"

namespace docksim_cli {
namespace {

using dockcore::Pose2;
using dockcore::Real;
using json = nlohmann::ordered_json;

const double kBandEdges[] = {0.3, 0.6, 1.0, 1.5, 2.0, 2.5};
constexpr int kBands = 5;
constexpr int kConfirmScans = 3;

struct PerceptionOptions {
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
  bool cost_copies = false;
  // Real data (sections real, composite).
  std::string realdata_dir;                  // --realdata; empty: $DOCKCORE_REALDATA, else <repo>/../shared/realdata
  std::size_t real_limit = 0;                // scans per recording, 0 = all
  std::vector<std::string> real_recordings;  // empty = all
  std::size_t composite_per_cell = 100;      // composites per (recording, profile, kind)
  bool reflective_clutter = false;           // real: scans with intensities and reflective clutter pasted in
  int reflective_objects = 3;                // ... at most this many objects per window
  docksim::EstimatorOverrides
      overrides;  // every section's estimators (--min-evidence-nats, --stripe-hypotheses, --max-candidates)
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
dockcore::EstimatorParams params_for(const PerceptionOptions& o, double sigma_m) {
  return o.overrides.for_noise(sigma_m);
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

json run_accuracy(const PerceptionOptions& o) {
  json out = json::array();
  auto scene = std::make_unique<Scene>();
  for (const auto& pname : o.profiles) {
    const dockcore::DockProfile prof = docksim::resolve_profile(pname);
    for (const auto& lname : o.lidars) {
      for (double sigma : o.sigmas) {
        const docksim::LidarModel m = lidar(lname, sigma);
        DetectorSet set(prof, params_for(o, sigma), {Detector::kEstimator, Detector::kBreakpoint, Detector::kVMarker});
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

// ---------------------------------------------------------------- the perception targets

json run_targets(const PerceptionOptions& o) {
  json out;
  const double sigma = 0.010;
  const docksim::LidarModel m = lidar("ld06", sigma);
  auto scene = std::make_unique<Scene>();
  for (const auto& pname : o.profiles) {
    const dockcore::DockProfile prof = docksim::resolve_profile(pname);
    DetectorSet set(prof, params_for(o, sigma), {Detector::kEstimator, Detector::kBreakpoint, Detector::kVMarker});
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
    est->configure(prof, params_for(o, sigma));
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

json run_false_positives(const PerceptionOptions& o) {
  json out;
  auto scan = std::make_unique<dockcore::LaserScan>();
  const double sigma = 0.010;
  const docksim::LidarModel m = lidar("ld06", sigma);
  for (const auto& pname : o.profiles) {
    const dockcore::DockProfile prof = docksim::resolve_profile(pname);
    DetectorSet set(prof, params_for(o, sigma), {Detector::kEstimator, Detector::kBreakpoint, Detector::kVMarker});
    // Hinted search: the dock is expected 1 m ahead (a dock database / staging pose), within 0.5 m.
    dockcore::EstimatorParams hinted = params_for(o, sigma);
    hinted.hint_radius_m = static_cast<Real>(0.5);
    auto est_hint = std::make_unique<dockcore::DockPoseEstimator>();
    est_hint->configure(prof, hinted);
    const Pose2 hint = docksim::dock_pose_from_lidar(1.0, 0.0, 0.0);
    auto est_confirm = std::make_unique<dockcore::DockPoseEstimator>();
    est_confirm->configure(prof, params_for(o, sigma));
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
        // every one finds it at a consistent pose (what a tracker does before it starts to move). Every scan is
        // simulated whatever the estimator found, so the next scenes are the same for any build of it.
        {
          Pose2 first{};
          bool confirmed = true;
          for (int k = 0; k < kConfirmScans; ++k) {
            if (k > 0) docksim::simulate_scan(w, Pose2{}, m, rng, scan.get(), 0);
            if (!confirmed) continue;
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

json run_cost(const PerceptionOptions& o) {
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
  const dockcore::EstimatorParams params = params_for(o, 0.010);
  // The copies a scan gets on its way through the docking loop: the parser hands over its own buffer
  // (LidarScanOutput::take()), the estimator reads it in place, and Dockcore copies it once, for its tick.
  auto scan_bytes_copied = [&]() {
    dockcore::SmoothController ctrl;
    auto core = std::make_unique<dockcore::Dockcore>(ctrl);
    dockcore::DockcoreConfig cfg;
    cfg.estimator = params;
    core->configure(prof, cfg);
    const std::uint64_t t_us = scans.front()->stamp_us;
    core->on_scan(scans.front()->view(), t_us, t_us);  // read as it is taken; the robot stands: no odometry fed
    return core->scan_copy_bytes();
  };
  if (want("estimator")) {
    auto est = std::make_unique<dockcore::DockPoseEstimator>();
    est->configure(prof, params);
    time_it("estimator", [&](const dockcore::ScanView& v) { return est->estimate(v, Pose2{}).found; });
    if (o.cost_copies) out["estimator"]["scan_bytes_copied"] = scan_bytes_copied();
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
    if (o.cost_copies) out["estimator-tracking"]["scan_bytes_copied"] = scan_bytes_copied();
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

// ---------------------------------------------------------------- real data

constexpr double kTargetSingleFpPct = 1.0;
constexpr double kTargetConfirmedFpPct = 0.05;
constexpr double kTargetCompositePct = 98.0;

double percent_of(std::size_t num, std::size_t den) {
  return den ? 100.0 * static_cast<double>(num) / static_cast<double>(den) : 0.0;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The recordings the real sections run on, loaded once for both.
struct RealData {
  docksim::RealDataLocation where;
  std::vector<docksim::LoadedRecording> recordings;
  double load_s = 0;
  json load_json;  // one entry per recording: scans, skipped lines, pose match
};

std::unique_ptr<RealData> load_real_data(const PerceptionOptions& o) {
  auto d = std::make_unique<RealData>();
  d->where = docksim::locate_realdata(o.realdata_dir);
  // The tables say where it looked; with --json the document does, and stderr tells the person running it.
  if (o.json_out) std::fprintf(stderr, "%s\n", d->where.describe().c_str());
  if (!d->where.found()) return d;
  std::vector<const docksim::RealRecording*> which;
  if (o.real_recordings.empty()) {
    for (const auto& r : docksim::real_recordings()) which.push_back(&r);
  } else {
    for (const auto& name : o.real_recordings) {
      const docksim::RealRecording* r = docksim::find_real_recording(name);
      if (r == nullptr) throw CLI::ValidationError("--real-recordings", "unknown recording " + name);
      which.push_back(r);
    }
  }
  const auto t0 = std::chrono::steady_clock::now();
  d->load_json = json::array();
  for (const docksim::RealRecording* r : which) {
    docksim::LoadedRecording rec;
    std::string error;
    if (!docksim::load_real_recording(d->where.dir, *r, o.real_limit, &rec, &error)) {
      std::fprintf(stderr, "real data: %s: %s (recording left out)\n", r->name, error.c_str());
      continue;
    }
    for (const std::string& e : rec.read.errors)
      std::fprintf(stderr, "%s/%s: %s (skipped)\n", d->where.dir.c_str(), r->file, e.c_str());
    const docksim::PoseMatch& m = rec.match;
    json lj;
    lj["name"] = r->name;
    lj["file"] = r->file;
    lj["environment"] = r->environment;
    lj["scans"] = rec.scans.size();
    lj["skipped_lines"] = rec.read.skipped;
    lj["sigma_mm"] = r->sigma_m * 1000;
    lj["resolution_mm"] = r->resolution_m * 1000;
    lj["pose_source"] = docksim::to_string(r->poses);
    if (r->pose_log != nullptr) {
      lj["pose_log"] = r->pose_log;
      lj["pose_match"] = {{"log_messages", m.log_messages},  {"every", r->pose_every},     {"matched", m.matched},
                          {"mismatched", m.mismatched},      {"log_errors", m.log_errors}, {"ok", m.ok()},
                          {"first_problem", m.first_problem}};
    }
    lj["poses_used"] = rec.has_poses();
    d->load_json.push_back(lj);
    d->recordings.push_back(std::move(rec));
  }
  d->load_s = seconds_since(t0);
  return d;
}

json location_json(const docksim::RealDataLocation& w) {
  json j;
  j["found"] = w.found();
  j["dir"] = w.dir;
  j["source"] = w.source;
  j["looked"] = w.looked;
  j["message"] = w.describe();
  return j;
}

/// The estimator's refusals by reason (only the reasons that occurred).
json rejections_json(const dockcore::EstimatorCounters& c) {
  json rej = json::object();
  for (std::size_t k = 1; k < static_cast<std::size_t>(dockcore::RejectReason::kCount); ++k) {
    if (c.rejected_by[k] != 0) rej[dockcore::to_string(static_cast<dockcore::RejectReason>(k))] = c.rejected_by[k];
  }
  return rej;
}

json run_real_fp(const PerceptionOptions& o, const RealData& d) {
  json out;
  out["data"] = location_json(d.where);
  if (!d.where.found()) return out;
  const auto t0 = std::chrono::steady_clock::now();
  const docksim::ConfirmRule rule;
  out["targets"] = {{"single_scan_fp_max_pct", kTargetSingleFpPct}, {"confirmed_fp_max_pct", kTargetConfirmedFpPct}};
  out["rule"] = {{"scans", rule.scans},
                 {"agree_m", rule.agree_m},
                 {"agree_deg", rule.agree_rad / kDeg},
                 {"static_max_gap_s", rule.static_max_gap_s},
                 {"text", "a window is " + std::to_string(rule.scans) +
                              " consecutive scans; the first is searched without a hint, the others with the first "
                              "detection (carried by the poses into their sensor frame) as the hint; the window is a "
                              "confirmed detection when every scan finds a dock and each lies within 5 cm and 5 deg of "
                              "the first in the world frame (standing sensor: in the sensor frame, stamps <= 1 s "
                              "apart). Denominator: windows (scans - 2 per recording with poses)."}};
  out["recordings"] = d.load_json;
  out["reflective_clutter"] = o.reflective_clutter;
  if (o.reflective_clutter) {
    out["reflective_clutter_text"] =
        "every return given an LD06 intensity (diffuse, reflectivity 0.1-1.0 per 0.5 m world cell), reflective "
        "objects (taped signs, safety vests, chrome legs) pasted into each window's free space, intensity usable; "
        "at most " +
        std::to_string(o.reflective_objects) + " objects, seed " + std::to_string(o.seed) +
        (o.overrides.stripe_hypotheses ? "; [estimator] stripe_hypotheses = true" : "");
  }
  json rows = json::array();
  json totals = json::array();
  for (const auto& pname : o.profiles) {
    const dockcore::DockProfile prof = docksim::resolve_profile(pname);
    if (o.reflective_clutter && prof.reflector_count == 0) {
      throw CLI::ValidationError("--reflective-clutter", "profile " + pname + " has no reflector stripes");
    }
    std::size_t scans = 0, found = 0, windows = 0, confirmed = 0, confirmed_seq = 0;
    Progress pr{"real: false positives", static_cast<long>(d.recordings.size())};
    for (const docksim::LoadedRecording& rec : d.recordings) {
      docksim::ReflectiveClutterOptions ro;
      ro.seed = o.seed;
      ro.objects_max = o.reflective_objects;
      ro.overrides = o.overrides;
      const docksim::RealFpResult r = o.reflective_clutter
                                          ? docksim::measure_real_reflector_false_positives(rec, prof, ro, rule)
                                          : docksim::measure_real_false_positives(rec, prof, rule, o.overrides);
      json row;
      row["recording"] = rec.info->name;
      row["profile"] = pname;
      row["sigma_mm"] = rec.info->sigma_m * 1000;
      row["scans"] = r.scans;
      row["found"] = r.found;
      row["fp_pct"] = percent_of(r.found, r.scans);
      row["confirm_frame"] = docksim::to_string(r.frame);
      if (r.frame != docksim::ConfirmFrame::kNone) {
        row["windows"] = r.windows;
        row["attempts"] = r.attempts;
        row["confirmed"] = r.confirmed;
        row["confirmed_pct"] = percent_of(r.confirmed, r.windows);
        row["confirmed_sequential"] = r.confirmed_sequential;
      } else {
        row["windows"] = nullptr;
        row["attempts"] = nullptr;
        row["confirmed"] = nullptr;
        row["confirmed_pct"] = nullptr;
      }
      json ex = json::array();
      for (const docksim::FalseDock& f : r.examples) {
        ex.push_back({{"scan", f.scan},
                      {"x_m", round6(f.pose.x_m)},
                      {"y_m", round6(f.pose.y_m)},
                      {"yaw_rad", round6(f.pose.yaw_rad)}});
      }
      row["examples"] = ex;
      row["confirmed_starts"] = r.confirmed_starts;
      row["candidates"] = r.counters.candidates;
      row["rejected_by"] = rejections_json(r.counters);
      rows.push_back(row);
      scans += r.scans;
      found += r.found;
      windows += r.windows;
      confirmed += r.confirmed;
      confirmed_seq += r.confirmed_sequential;
      pr.tick();
    }
    totals.push_back(
        {{"profile", pname},
         {"scans", scans},
         {"found", found},
         {"fp_pct", percent_of(found, scans)},
         {"meets_single_target", percent_of(found, scans) <= kTargetSingleFpPct},
         {"windows", windows},
         {"confirmed", confirmed},
         {"confirmed_pct", percent_of(confirmed, windows)},
         {"confirmed_sequential", confirmed_seq},
         {"confirmed_sequential_pct", percent_of(confirmed_seq, windows)},
         {"meets_confirmed_target", windows > 0 && percent_of(confirmed, windows) <= kTargetConfirmedFpPct}});
  }
  out["rows"] = rows;
  out["totals"] = totals;
  out["load_seconds"] = d.load_s;
  out["seconds"] = seconds_since(t0);
  return out;
}

json run_real_composite(const PerceptionOptions& o, const RealData& d) {
  json out;
  out["data"] = location_json(d.where);
  if (!d.where.found()) return out;
  const auto t0 = std::chrono::steady_clock::now();
  docksim::CompositeOptions co;
  co.per_cell = o.composite_per_cell;
  co.seed = o.seed;
  co.overrides = o.overrides;
  const docksim::CompositeSiteParams& sp = co.site;
  out["target_detection_min_pct"] = kTargetCompositePct;
  out["per_cell"] = co.per_cell;
  out["seed"] = o.seed;
  out["match"] = {{"m", co.match_m}, {"deg", co.match_rad / kDeg}};
  out["sites"] = {{"range_m", {sp.min_range_m, sp.max_range_m}},
                  {"wall_margin_m", sp.margin_m},
                  {"max_incidence_deg", sp.max_incidence_rad / kDeg},
                  {"gap_m", {sp.gap_min_m, sp.gap_max_m}},
                  {"free_distance_m", {sp.free_min_m, sp.free_max_m}},
                  {"free_yaw_deg", sp.free_yaw_rad / kDeg},
                  {"free_behind_m", sp.free_behind_m}};
  json rows = json::array();
  json totals = json::array();
  auto mm = [](const std::vector<double>& v) {
    const double p = percentile(v, 0.95);
    return std::isnan(p) ? json(nullptr) : json(std::round(p * 1e4) / 10.0);
  };
  auto dg = [](const std::vector<double>& v) {
    const double p = percentile(v, 0.95);
    return std::isnan(p) ? json(nullptr) : json(std::round(p / kDeg * 100) / 100.0);
  };
  auto mm50 = [](const std::vector<double>& v) {
    const double p = percentile(v, 0.5);
    return std::isnan(p) ? json(nullptr) : json(std::round(p * 1e4) / 10.0);
  };
  // Placed and detected per view-angle bin; the first bin is the detection targets' envelope (|dock yaw| <= 30°).
  auto by_view = [](const docksim::CompositeResult& r) {
    json a = json::array();
    double lo_deg = 0;
    for (int b = 0; b < docksim::kCompositeViewBins; ++b) {
      a.push_back({{"view_deg", {lo_deg, docksim::kCompositeViewBinDeg[b]}},
                   {"placed", r.placed_by_view[b]},
                   {"detected", r.detected_by_view[b]},
                   {"detection_pct", r.placed_by_view[b] ? json(percent_of(r.detected_by_view[b], r.placed_by_view[b]))
                                                         : json(nullptr)}});
      lo_deg = docksim::kCompositeViewBinDeg[b];
    }
    return a;
  };
  for (const auto& pname : o.profiles) {
    const dockcore::DockProfile prof = docksim::resolve_profile(pname);
    for (int k = 0; k < docksim::kCompositeKinds; ++k) {
      const auto kind = static_cast<docksim::CompositeKind>(k);
      docksim::CompositeResult all;
      Progress pr{"real: composites", static_cast<long>(d.recordings.size())};
      for (const docksim::LoadedRecording& rec : d.recordings) {
        const docksim::CompositeResult r = docksim::measure_real_composites(rec, prof, kind, co);
        rows.push_back({{"recording", rec.info->name},
                        {"profile", pname},
                        {"kind", docksim::to_string(kind)},
                        {"scans_tried", r.scans_tried},
                        {"no_site", r.no_site},
                        {"placed", r.placed},
                        {"detected", r.detected},
                        {"wrong", r.wrong},
                        {"missed", r.missed},
                        {"detection_pct", r.placed ? json(percent_of(r.detected, r.placed)) : json(nullptr)},
                        {"by_view", by_view(r)},
                        {"pos_mm_p95", mm(r.pos_err_m)},
                        {"yaw_deg_p95", dg(r.yaw_err_rad)},
                        {"wrong_pos_mm_median", mm50(r.wrong_pos_err_m)},
                        {"rejected_by", rejections_json(r.counters)}});
        all.scans_tried += r.scans_tried;
        all.no_site += r.no_site;
        all.placed += r.placed;
        all.detected += r.detected;
        all.wrong += r.wrong;
        all.missed += r.missed;
        for (int b = 0; b < docksim::kCompositeViewBins; ++b) {
          all.placed_by_view[b] += r.placed_by_view[b];
          all.detected_by_view[b] += r.detected_by_view[b];
        }
        all.pos_err_m.insert(all.pos_err_m.end(), r.pos_err_m.begin(), r.pos_err_m.end());
        all.yaw_err_rad.insert(all.yaw_err_rad.end(), r.yaw_err_rad.begin(), r.yaw_err_rad.end());
        pr.tick();
      }
      totals.push_back(
          {{"profile", pname},
           {"kind", docksim::to_string(kind)},
           {"placed", all.placed},
           {"detected", all.detected},
           {"wrong", all.wrong},
           {"missed", all.missed},
           {"detection_pct", all.placed ? json(percent_of(all.detected, all.placed)) : json(nullptr)},
           {"by_view", by_view(all)},
           {"meets_target", all.placed_by_view[0] > 0 &&
                                percent_of(all.detected_by_view[0], all.placed_by_view[0]) >= kTargetCompositePct},
           {"pos_mm_p95", mm(all.pos_err_m)},
           {"yaw_deg_p95", dg(all.yaw_err_rad)}});
    }
  }
  out["rows"] = rows;
  out["totals"] = totals;
  out["seconds"] = seconds_since(t0);
  return out;
}

void print_real_text(const json& j) {
  for (const char* section : {"real", "composite"}) {
    if (j.contains(section) && !j[section]["data"]["found"].get<bool>()) {
      std::printf("%s\n", j[section]["data"]["message"].get<std::string>().c_str());  // one line: skipped
      return;
    }
  }
  auto opt = [](const json& v, const char* fmt) {
    char buf[32];
    if (v.is_null()) return std::string("-");
    std::snprintf(buf, sizeof buf, fmt, v.get<double>());
    return std::string(buf);
  };
  if (j.contains("real")) {
    const json& r = j["real"];
    std::printf(
        "\n== Real data: false positives (dock-less real scans; estimator with params for each recording's "
        "noise, lidar at the origin, no hint)\n%s\n",
        r["data"]["message"].get<std::string>().c_str());
    if (r["data"]["found"].get<bool>()) {
      std::printf("\n-- Recordings (σ = README p25 noise at 1-2 m; poses matched by order, verified range by range)\n");
      std::printf("%-26s %6s %7s %6s %6s  %-18s %s\n", "recording", "scans", "skipped", "σ mm", "res mm", "poses",
                  "pose match");
      for (const auto& l : r["recordings"]) {
        std::string match = "-";
        if (l.contains("pose_match")) {
          const auto& m = l["pose_match"];
          char buf[160];
          std::snprintf(buf, sizeof buf, "%zu of %zu scans = log messages (every %zu) %s%s",
                        m["matched"].get<std::size_t>(), l["scans"].get<std::size_t>(), m["every"].get<std::size_t>(),
                        m["ok"].get<bool>() ? "ok" : "NOT USED: ", m["first_problem"].get<std::string>().c_str());
          match = buf;
        } else if (l["poses_used"].get<bool>()) {
          match = "standing sensor (identity poses)";
        }
        std::printf("%-26s %6zu %7zu %6.1f %6.2g  %-18s %s\n", l["name"].get<std::string>().c_str(),
                    l["scans"].get<std::size_t>(), l["skipped_lines"].get<std::size_t>(), l["sigma_mm"].get<double>(),
                    l["resolution_mm"].get<double>(), l["pose_source"].get<std::string>().c_str(), match.c_str());
      }
      if (r.contains("reflective_clutter_text")) {
        std::printf("\nReflective clutter: %s\n", r["reflective_clutter_text"].get<std::string>().c_str());
      }
      std::printf("\nConfirmed: %s\n\n", r["rule"]["text"].get<std::string>().c_str());
      std::printf("(att = windows whose first scan found a dock: the only ones that can confirm)\n");
      std::printf("%-26s %-10s %6s %5s %7s | %-6s %7s %5s %5s %7s\n", "recording", "profile", "scans", "FP", "FP %",
                  "frame", "windows", "att", "conf", "conf %");
      for (const auto& row : r["rows"]) {
        std::printf("%-26s %-10s %6zu %5zu %7.2f | %-6s %7s %5s %5s %7s\n", row["recording"].get<std::string>().c_str(),
                    row["profile"].get<std::string>().c_str(), row["scans"].get<std::size_t>(),
                    row["found"].get<std::size_t>(), row["fp_pct"].get<double>(),
                    row["confirm_frame"].get<std::string>().c_str(),
                    row["windows"].is_null() ? "-" : std::to_string(row["windows"].get<std::size_t>()).c_str(),
                    row["attempts"].is_null() ? "-" : std::to_string(row["attempts"].get<std::size_t>()).c_str(),
                    row["confirmed"].is_null() ? "-" : std::to_string(row["confirmed"].get<std::size_t>()).c_str(),
                    opt(row["confirmed_pct"], "%.3f").c_str());
      }
      std::printf(
          "\n-- Totals per profile (targets: single scan <= %.2f %% of scans, confirmed <= %.2f %% of windows)\n",
          kTargetSingleFpPct, kTargetConfirmedFpPct);
      std::printf("%-10s %6s %5s %7s %-6s | %7s %5s %7s %-6s | %s\n", "profile", "scans", "FP", "FP %", "target",
                  "windows", "conf", "conf %", "target", "of which sequential test (>= 12 nats)");
      for (const auto& t : r["totals"]) {
        std::printf("%-10s %6zu %5zu %7.2f %-6s | %7zu %5zu %7.3f %-6s | %zu (%.3f %%)\n",
                    t["profile"].get<std::string>().c_str(), t["scans"].get<std::size_t>(),
                    t["found"].get<std::size_t>(), t["fp_pct"].get<double>(),
                    t["meets_single_target"].get<bool>() ? "met" : "MISSED", t["windows"].get<std::size_t>(),
                    t["confirmed"].get<std::size_t>(), t["confirmed_pct"].get<double>(),
                    t["meets_confirmed_target"].get<bool>() ? "met" : "MISSED",
                    t["confirmed_sequential"].get<std::size_t>(), t["confirmed_sequential_pct"].get<double>());
      }
      std::printf("(loading %.1f s, measuring %.1f s)\n", r["load_seconds"].get<double>(), r["seconds"].get<double>());
    }
  }
  if (j.contains("composite")) {
    const json& c = j["composite"];
    std::printf("\n== Real data: composite scenes (a dock ray-cast into real scans with the recording's noise)\n%s\n",
                c["data"]["message"].get<std::string>().c_str());
    if (c["data"]["found"].get<bool>()) {
      std::printf("detected = found within %.0f cm / %.0f° of the truth; wrong = found elsewhere; seed %llu\n",
                  100 * c["match"]["m"].get<double>(), c["match"]["deg"].get<double>(),
                  static_cast<unsigned long long>(c["seed"].get<std::uint64_t>()));
      std::printf("\n%-26s %-10s %-13s %6s %7s %6s %5s %5s %6s %8s %8s %8s\n", "recording", "profile", "kind", "tried",
                  "no site", "placed", "det", "wrong", "missed", "det %", "pos95mm", "yaw95°");
      for (const auto& row : c["rows"]) {
        std::printf("%-26s %-10s %-13s %6zu %7zu %6zu %5zu %5zu %6zu %8s %8s %8s\n",
                    row["recording"].get<std::string>().c_str(), row["profile"].get<std::string>().c_str(),
                    row["kind"].get<std::string>().c_str(), row["scans_tried"].get<std::size_t>(),
                    row["no_site"].get<std::size_t>(), row["placed"].get<std::size_t>(),
                    row["detected"].get<std::size_t>(), row["wrong"].get<std::size_t>(),
                    row["missed"].get<std::size_t>(), opt(row["detection_pct"], "%.1f").c_str(),
                    opt(row["pos_mm_p95"], "%.1f").c_str(), opt(row["yaw_deg_p95"], "%.2f").c_str());
      }
      std::printf(
          "\n-- Totals per profile and placement (target: detected >= %.0f %% with the face turned at most 30° "
          "from the lidar, the detection targets' envelope)\n",
          c["target_detection_min_pct"].get<double>());
      std::printf("view = the dock face's turn from facing the lidar; det %% (n) per view bin\n");
      std::printf("%-10s %-13s %6s %6s %5s %6s %8s %14s %14s %14s %-6s %8s %8s\n", "profile", "kind", "placed", "det",
                  "wrong", "missed", "det %", "view 0-30°", "view 30-45°", "view 45-60°", "target", "pos95mm",
                  "yaw95°");
      for (const auto& t : c["totals"]) {
        std::string bins[3];
        for (std::size_t b = 0; b < 3 && b < t["by_view"].size(); ++b) {
          const json& v = t["by_view"][b];
          bins[b] = opt(v["detection_pct"], "%.1f") + " (" + std::to_string(v["placed"].get<std::size_t>()) + ")";
        }
        std::printf("%-10s %-13s %6zu %6zu %5zu %6zu %8s %14s %14s %14s %-6s %8s %8s\n",
                    t["profile"].get<std::string>().c_str(), t["kind"].get<std::string>().c_str(),
                    t["placed"].get<std::size_t>(), t["detected"].get<std::size_t>(), t["wrong"].get<std::size_t>(),
                    t["missed"].get<std::size_t>(), opt(t["detection_pct"], "%.1f").c_str(), bins[0].c_str(),
                    bins[1].c_str(), bins[2].c_str(), t["meets_target"].get<bool>() ? "met" : "MISSED",
                    opt(t["pos_mm_p95"], "%.1f").c_str(), opt(t["yaw_deg_p95"], "%.2f").c_str());
      }
      std::printf("(measuring %.1f s)\n", c["seconds"].get<double>());
    }
  }
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
  print_real_text(j);
  if (j.contains("cost")) {
    std::printf("\n== Cost per scan\n");
    for (const auto& [det, c] : j["cost"].items()) {
      std::printf("%-20s %5d points  median %10.0f ns/scan  (found in %d of %d scans)", det.c_str(),
                  c["points"].get<int>(), c["ns_per_scan_median"].get<double>(), c["found"].get<int>(),
                  c["scans"].get<int>());
      if (c.contains("scan_bytes_copied"))
        std::printf("  scan bytes copied: %zu (Dockcore's copy for the tick)", c["scan_bytes_copied"].get<std::size_t>());
      std::printf("\n");
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
  auto o = std::make_shared<PerceptionOptions>();
  auto profiles = std::make_shared<std::string>("plate-v,v-marker,breakpoint");
  auto lidars = std::make_shared<std::string>("ld06,rplidar-a1,industrial");
  auto sigmas = std::make_shared<std::string>("5,10,20");
  auto sections = std::make_shared<std::string>("accuracy,targets,fp");
  CLI::App* sub = app.add_subcommand(
      "perception", "Benchmark the dock detectors: accuracy vs CRLB, targets, false positives, cost per scan");
  sub->add_option("--profiles", *profiles, "Comma-separated profiles (built-in names or .toml files)");
  sub->add_option("--lidars", *lidars, "Comma-separated lidar models");
  sub->add_option("--sigmas-mm", *sigmas, "Comma-separated range noise levels, millimetres");
  sub->add_option("--sections", *sections,
                  "Comma-separated: accuracy, targets, fp (simulated); generated (generated worlds); reflectors "
                  "(reflector docks on generated worlds); real (false positives on the real dock-less recordings), "
                  "composite (docks ray-cast into real scans)");
  auto gen = std::make_shared<GeneratedOptions>();
  sub->add_option("--gen-scenes", gen->scenes, "generated: docking scenes (one scan each)")->check(CLI::PositiveNumber);
  sub->add_option("--gen-fp-scenes", gen->fp_scenes,
                  "generated: dock-less scenes, 3 scans each (default: as many as --gen-scenes)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--gen-filter-runs", gen->filter_runs,
                  "generated: 1 s filtered approaches (default: a fifth of --gen-scenes)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--gen-profiles", gen->profiles, "generated, reflectors: random profiles in the pool")
      ->check(CLI::Range(1, 10000));
  auto refl = std::make_shared<ReflectorOptions>();
  sub->add_option("--refl-scenes", refl->scenes, "reflectors: docking scenes (one scan each)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--refl-fp-scenes", refl->fp_scenes,
                  "reflectors: dock-less scenes, 3 scans each (default: as many as --refl-scenes)")
      ->check(CLI::PositiveNumber);
  sub->add_flag("--read-range", refl->read_range,
                "reflectors: also measure the readable range of a code per lidar (ld06, industrial) and region width "
                "(5, 7.5, 10 cm)");
  sub->add_option("--read-range-scenes", refl->read_range_scenes,
                  "reflectors: docking scenes per (lidar, region width) of --read-range")
      ->check(CLI::PositiveNumber);
  sub->add_option("--jobs", gen->jobs, "generated, reflectors: worker threads (the figures do not depend on it)")
      ->check(CLI::Range(1, 64));
  sub->add_option("--realdata", o->realdata_dir,
                  "Real-data folder (default: $DOCKCORE_REALDATA, else <repo>/../shared/realdata)");
  sub->add_option("--real-limit", o->real_limit, "Real data: use only the first N scans of each recording (0 = all)")
      ->check(docksim::non_negative_integer());
  auto real_names = std::make_shared<std::string>();
  sub->add_option("--real-recordings", *real_names, "Real data: comma-separated recording names (default: all)");
  sub->add_flag("--reflective-clutter", o->reflective_clutter,
                "real: give every return an LD06 intensity and paste reflective objects (taped signs, safety vests, "
                "chrome legs) into the scans; the profiles must carry reflector stripes, read with intensity usable");
  sub->add_flag("--stripe-hypotheses", o->overrides.stripe_hypotheses,
                "reflectors, real with --reflective-clutter: the estimators also try the scan's bright runs as the "
                "stripes ([estimator] stripe_hypotheses)");
  sub->add_option("--reflective-objects", o->reflective_objects,
                  "real, with --reflective-clutter: at most this many objects per window (0: intensities only)")
      ->check(CLI::Range(0, 10));
  sub->add_option("--min-evidence-nats", o->overrides.min_evidence_nats,
                  "Every section: the estimators' min_evidence_nats instead of the default (3.4), to measure the "
                  "trade-off between detection and false docks")
      ->check(CLI::Range(-100.0, 100.0));
  sub->add_option("--max-candidates", o->overrides.max_candidates,
                  "Every section and --cost: the estimators' max_candidates instead of the default (12), to measure "
                  "what the global search's cost trades against detection")
      ->check(CLI::Range(1, 64));
  sub->add_option("--composite-n", o->composite_per_cell,
                  "Composite scenes per (recording, profile, placement), at most one per scan")
      ->check(CLI::PositiveNumber);
  sub->add_option("--trials", o->trials, "Scenes per (profile, lidar, sigma) in the accuracy grid")->check(CLI::PositiveNumber);
  sub->add_option("--target-trials", o->target_trials, "Scenes in the target zone")->check(CLI::PositiveNumber);
  sub->add_option("--fp-scenes", o->fp_scenes, "Dock-less scenes per clutter kind")->check(CLI::PositiveNumber);
  sub->add_option("--filter-runs", o->filter_runs, "1 s filtered runs")->check(CLI::PositiveNumber);
  sub->add_option("--clutter", o->clutter, "Clutter level of docking scenes (0-3)")->check(CLI::Range(0, 3));
  sub->add_option("--seed", o->seed, "Seed: same seed, same scenes, same figures")
      ->check(docksim::non_negative_integer());
  sub->add_flag("--json", o->json_out, "Print one JSON document instead of tables");
  sub->add_flag("--cost", o->cost, "Measure cost per scan instead (use with callgrind for instruction counts)");
  sub->add_flag("--copies", o->cost_copies,
                "Cost: also count the scan bytes the docking loop copies per scan (runs one Dockcore scan, so leave "
                "it out under callgrind)");
  sub->add_option("--points", o->points, "Cost: points per scan (full turn)")->check(CLI::Range(16, 4096));
  sub->add_option("--scans", o->scans, "Cost: scans to run")->check(CLI::PositiveNumber);
  sub->add_option("--detector", o->cost_detector,
                  "Cost: all | estimator | estimator-tracking | breakpoint | vmarker (one detector for callgrind)")
      ->check(CLI::IsMember({"all", "estimator", "estimator-tracking", "breakpoint", "vmarker"}));
  sub->callback([o, gen, refl, profiles, lidars, sigmas, sections, real_names]() {
    o->profiles = split_csv(*profiles);
    o->real_recordings = split_csv(*real_names);
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
    if (!std::isnan(o->overrides.min_evidence_nats))
      j["overrides"]["min_evidence_nats"] = o->overrides.min_evidence_nats;
    if (o->overrides.max_candidates > 0) j["overrides"]["max_candidates"] = o->overrides.max_candidates;
    if (o->cost) {
      j["cost"] = run_cost(*o);
    } else {
      const std::vector<std::string> secs = split_csv(*sections);
      for (const std::string& s : secs) {
        if (s != "accuracy" && s != "targets" && s != "fp" && s != "generated" && s != "reflectors" && s != "real" &&
            s != "composite") {
          throw CLI::ValidationError(
              "--sections",
              "unknown section " + s + " (accuracy, targets, fp, generated, reflectors, real, composite)");
        }
      }
      auto has = [&secs](const char* s) { return std::find(secs.begin(), secs.end(), s) != secs.end(); };
      if (has("accuracy")) j["accuracy"] = run_accuracy(*o);
      if (has("targets")) j["targets"] = run_targets(*o);
      if (has("fp")) j["false_positives"] = run_false_positives(*o);
      if (has("generated")) {
        gen->seed = o->seed;
        gen->overrides = o->overrides;
        j["generated"] = run_generated(*gen);
      }
      if (has("reflectors")) {
        refl->seed = o->seed;
        refl->jobs = gen->jobs;
        refl->profiles = gen->profiles;
        refl->overrides = o->overrides;
        j["reflectors"] = run_reflectors(*refl);
      }
      if (has("real") || has("composite")) {
        const std::unique_ptr<RealData> data = load_real_data(*o);
        if (has("real")) j["real"] = run_real_fp(*o, *data);
        if (has("composite")) j["composite"] = run_real_composite(*o, *data);
      }
    }
    if (o->json_out) {
      std::printf("%s\n", j.dump().c_str());
    } else {
      if (j.contains("overrides") && j["overrides"].contains("min_evidence_nats")) {
        std::printf("every estimator: min_evidence_nats = %.2f nats (--min-evidence-nats; default %.2f)\n",
                    j["overrides"]["min_evidence_nats"].get<double>(),
                    static_cast<double>(dockcore::EstimatorParams{}.min_evidence_nats));
      }
      if (j.contains("overrides") && j["overrides"].contains("max_candidates")) {
        std::printf("every estimator: max_candidates = %d (--max-candidates; default %d)\n",
                    j["overrides"]["max_candidates"].get<int>(), int{dockcore::EstimatorParams{}.max_candidates});
      }
      print_text(j);
      if (j.contains("generated")) print_generated(j["generated"]);
      if (j.contains("reflectors")) print_reflectors(j["reflectors"]);
    }
  });
}

}  // namespace docksim_cli
