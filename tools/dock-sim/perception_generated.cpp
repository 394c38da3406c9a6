// `dock-sim perception --sections generated`: DockPoseEstimator (and DockPoseFilter) over worlds drawn by
// docksim::WorldGenerator, binned by every factor the generator draws, beside the perception targets. Figures are
// printed, never asserted. See docs/performance.md ("Generalisation over generated worlds").
#include "perception_generated.hpp"

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "dockcore/perception/dock_pose_estimator.hpp"
#include "dockcore/perception/dock_pose_filter.hpp"
#include "dockcore/perception/profile_check.hpp"
#include "docksim/crlb.hpp"
#include "docksim/sim_run.hpp"
#include "docksim/world_gen.hpp"
#include "perception_gen_common.hpp"
#include "perception_stats.hpp"

namespace docksim_cli {

using namespace genbench;

namespace {

using dockcore::Pose2;
using dockcore::Real;
using json = nlohmann::ordered_json;

// The two ways the estimator is configured: the profile's mounting as the world has it, and left unknown.
constexpr int kCases = 2;
const char* const kCaseNames[kCases] = {"told", "unknown"};
constexpr int kApproachScans = 10;
// Odometry between scans of a filtered approach: 1 % scale error, 0.5 mm lateral and 0.1° per step (1 σ).
constexpr double kOdomScaleSigma = 0.01, kOdomLateralSigmaM = 0.0005, kOdomYawSigmaRad = 0.1 * kDeg;
// Bins with fewer in-envelope scenes than this are not used to pick the worst bin of a target.
constexpr int kMinBinScenes = 20;
// Detections whose lateral error lies beyond this many σ of the CRLB form the tail the report describes.
constexpr double kTailSigmas = 3.0;

enum Factor {
  kProfile,
  kMounting,
  kClutter,
  kLidar,
  kNoise,
  kRange,
  kBearing,
  kDockYaw,
  kMixedPixels,
  kDropouts,
  kFactorCount
};
const char* const kFactorNames[kFactorCount] = {"profile", "mounting", "clutter",  "lidar",        "noise",
                                                "range",   "bearing",  "dock-yaw", "mixed-pixels", "dropouts"};
const double kBearingEdgesDeg[] = {0, 15, 30, 45, 60};
const double kYawEdgesDeg[] = {0, 15, 30, 45};
// Thirds of a factor's range (mixed-pixel probability, dropouts as a share of their maximum).
const double kThirds[] = {0, 1.0 / 3, 2.0 / 3, 1};

std::vector<std::string> bin_names(Factor f, const docksim::WorldGenParams& p) {
  std::vector<std::string> out;
  char buf[48];
  switch (f) {
    case kProfile:
      for (std::size_t i = 0; dockcore::kBuiltinProfileNames[i] != nullptr; ++i)
        out.push_back(dockcore::kBuiltinProfileNames[i]);
      out.insert(out.end(), {"random 2-3 vertices", "random 4-5 vertices", "random 6-8 vertices"});
      break;
    case kMounting:
      for (int i = 0; i < static_cast<int>(docksim::MountClass::kCount); ++i)
        out.push_back(docksim::to_string(static_cast<docksim::MountClass>(i)));
      break;
    case kClutter:
      for (int i = 0; i < static_cast<int>(docksim::ClutterClass::kCount); ++i)
        out.push_back(docksim::to_string(static_cast<docksim::ClutterClass>(i)));
      break;
    case kLidar:
      out = p.lidars;
      break;
    case kNoise:
      out = {"σ ≤ 10 mm", "σ 10-15 mm", "σ 15-20 mm", "σ > 20 mm"};
      break;
    case kRange:
      for (int i = 0; i < 5; ++i) {
        std::snprintf(buf, sizeof buf, "%.1f-%.1f m", kRangeEdges[i], kRangeEdges[i + 1]);
        out.push_back(buf);
      }
      break;
    case kBearing:
      for (int i = 0; i < 4; ++i) {
        std::snprintf(buf, sizeof buf, "|b| %.0f-%.0f°", kBearingEdgesDeg[i], kBearingEdgesDeg[i + 1]);
        out.push_back(buf);
      }
      break;
    case kDockYaw:
      for (int i = 0; i < 3; ++i) {
        std::snprintf(buf, sizeof buf, "|yaw| %.0f-%.0f°", kYawEdgesDeg[i], kYawEdgesDeg[i + 1]);
        out.push_back(buf);
      }
      break;
    case kMixedPixels:
      out = {"p 0-0.33", "p 0.33-0.67", "p 0.67-1"};
      break;
    case kDropouts:
      for (int i = 0; i < 3; ++i) {
        std::snprintf(buf, sizeof buf, "%.1f-%.1f %%", 100 * p.dropout_max * i / 3, 100 * p.dropout_max * (i + 1) / 3);
        out.push_back(buf);
      }
      break;
    default:
      break;
  }
  return out;
}

// Range noise at the dock, the figure the noise bins and the σ rows of the targets use.
double sigma_at_dock(const docksim::GenScene& s) {
  return s.sigma_at(s.distance_m);
}

// 0: σ ≤ 10 mm, 1: 10-20 mm, 2: above.
int noise_class(const docksim::GenScene& s) {
  const double sg = sigma_at_dock(s);
  return sg <= 0.010 ? 0 : sg <= 0.020 ? 1 : 2;
}

int bin_of(Factor f, const docksim::GenScene& s, const docksim::WorldGenParams& p) {
  switch (f) {
    case kProfile: {
      if (s.builtin) {
        for (int i = 0; dockcore::kBuiltinProfileNames[i] != nullptr; ++i) {
          if (std::string(s.profile.name) == dockcore::kBuiltinProfileNames[i]) return i;
        }
        return 0;
      }
      const int builtins = 3;
      return builtins + (s.profile.vertex_count <= 3 ? 0 : s.profile.vertex_count <= 5 ? 1 : 2);
    }
    case kMounting:
      return static_cast<int>(s.mount);
    case kClutter:
      return static_cast<int>(s.clutter);
    case kLidar:
      for (std::size_t i = 0; i < p.lidars.size(); ++i) {
        if (p.lidars[i] == s.lidar.name) return static_cast<int>(i);
      }
      return 0;
    case kNoise: {
      const double sg = sigma_at_dock(s);
      return sg <= 0.010 ? 0 : sg <= 0.015 ? 1 : sg <= 0.020 ? 2 : 3;
    }
    case kRange:
      return edge_bin(s.distance_m, kRangeEdges, 5);
    case kBearing:
      return edge_bin(std::fabs(s.bearing_rad) / kDeg, kBearingEdgesDeg, 4);
    case kDockYaw:
      return edge_bin(std::fabs(s.dock_yaw_rad) / kDeg, kYawEdgesDeg, 3);
    case kMixedPixels:  // the chance that a beam straddling a depth edge reads in between, drawn per scene
      return edge_bin(s.lidar.mixed_pixel_prob, kThirds, 3);
    case kDropouts:
      return p.dropout_max > 0 ? edge_bin(s.lidar.dropout_prob / p.dropout_max, kThirds, 3) : 0;
    default:
      return 0;
  }
}

/// The estimator's configuration in case c. The user configures the lidar's noise as its σ at 1 m. Told: the
/// profile's mounting is the world's. Unknown: mounting kUnknown. The parameters are the same in both.
dockcore::DockProfile profile_for_case(const docksim::GenScene& s, int c) {
  dockcore::DockProfile p = s.profile;
  p.mounting = c == 0 ? s.told_mounting : dockcore::DockMounting{};
  return p;
}

struct Outcome {
  bool found = false, correct = false;
  Errors sensor, robot;
  double lat_over_crlb = std::nan("");
  double lat_beams = std::nan("");  // |lateral error| in beam spacings at the dock's range
  std::string miss;  // when not a correct detection: why (miss_cause)
};

struct DockRecord {
  std::string excluded;
  int bins[kFactorCount] = {};
  int random_index = -1;
  bool env[3] = {};  // distance, bearing, yaw within the envelope
  int noise = 0;
  double distance_m = 0;
  Outcome c[kCases];
};

struct FreeRecord {
  std::string excluded;
  int bins[kFactorCount] = {};
  int look_alike = 0;
  int hits[kCases] = {};
  bool confirmed[kCases] = {};
};

struct FilterRecord {
  std::string excluded;
  int noise = 0;
  bool initialised[kCases] = {};
  Errors sensor[kCases];
};

/// The worker's estimator c for case c.
void configure(Worker& w, const docksim::GenScene& s, const docksim::EstimatorOverrides& ov) {
  for (int c = 0; c < kCases; ++c)
    w.est[static_cast<std::size_t>(c)]->configure(profile_for_case(s, c), scene_params(s, ov));
}

double max_range_for(const docksim::GenScene& s) {
  return static_cast<double>(scene_params(s).max_range_m);
}

void fill_bins(const docksim::GenScene& s, const docksim::WorldGenParams& p, int* bins) {
  for (int f = 0; f < kFactorCount; ++f) bins[f] = bin_of(static_cast<Factor>(f), s, p);
}

DockRecord run_dock(const docksim::WorldGenerator& g, std::uint64_t i, Worker& w,
                    const docksim::EstimatorOverrides& ov) {
  const docksim::GenScene s = g.draw(i, true, docksim::ScenePath::kSingle);
  DockRecord r;
  fill_bins(s, g.params(), r.bins);
  r.random_index = s.random_index;
  r.env[0] = s.distance_m <= kEnvDistanceM;
  r.env[1] = std::fabs(s.bearing_rad) <= kEnvBearingRad;
  r.env[2] = std::fabs(s.dock_yaw_rad) <= kEnvYawRad;
  r.noise = noise_class(s);
  r.distance_m = s.distance_m;
  r.excluded = exclusion(s.profile, s.lidar.angle_increment_rad, max_range_for(s));
  if (!r.excluded.empty()) return r;
  docksim::Rng rng(scan_seed(g.seed(), 0, i));
  w.simulate(s, 0, rng, 0);
  const Pose2 truth_sensor = s.dock_in_sensor(0), truth_robot = s.dock_in_robot(0);
  const std::size_t beams = std::min(s.lidar.beams, dockcore::kMaxScanPoints);
  const docksim::Crlb bound = docksim::dock_pose_crlb(s.profile, truth_sensor, s.lidar.angle_min_rad,
                                                      s.lidar.angle_increment_rad, beams, sigma_at_dock(s), 0);
  // Dropped beams carry no information: the bound's σ grows by 1/sqrt(1 - dropout).
  const double crlb_lat = bound.ok ? bound.sigma_lateral_m / std::sqrt(1.0 - s.lidar.dropout_prob) : std::nan("");
  configure(w, s, ov);
  const Pose2 mount_inv = s.lidar_mount.inverse();
  for (int c = 0; c < kCases; ++c) {
    const dockcore::DockEstimate e = w.est[static_cast<std::size_t>(c)]->estimate(w.scan->view(), s.lidar_mount);
    Outcome& o = r.c[c];
    o.found = e.found;
    if (e.found) {
      o.sensor = errors_of(truth_sensor, mount_inv.compose(e.pose));
      o.robot = errors_of(truth_robot, e.pose);
      o.correct = is_correct(o.sensor);
      if (crlb_lat > 0) o.lat_over_crlb = o.sensor.lat_m / crlb_lat;
      o.lat_beams = std::fabs(o.sensor.lat_m) / (s.distance_m * s.lidar.angle_increment_rad);
    }
    if (!o.correct) o.miss = miss_cause(e, truth_sensor, mount_inv);
  }
  return r;
}

FreeRecord run_free(const docksim::WorldGenerator& g, std::uint64_t i, Worker& w,
                    const docksim::EstimatorOverrides& ov) {
  const docksim::GenScene s = g.draw(i, false, docksim::ScenePath::kConfirm);
  FreeRecord r;
  fill_bins(s, g.params(), r.bins);
  r.look_alike = static_cast<int>(s.look_alike);
  r.excluded = exclusion(s.profile, s.lidar.angle_increment_rad, max_range_for(s));
  if (!r.excluded.empty()) return r;
  configure(w, s, ov);
  docksim::Rng rng(scan_seed(g.seed(), 1, i));
  Confirmation conf[kCases];
  for (int k = 0; k < kConfirmScans; ++k) {
    w.simulate(s, static_cast<std::size_t>(k), rng, static_cast<std::uint64_t>(k) * kScanPeriodUs);
    for (int c = 0; c < kCases; ++c) {
      const dockcore::DockEstimate e = w.est[static_cast<std::size_t>(c)]->estimate(w.scan->view(), s.lidar_mount);
      conf[c].add(k, e, s.robot_path[static_cast<std::size_t>(k)]);
    }
  }
  for (int c = 0; c < kCases; ++c) {
    r.hits[c] = conf[c].hits;
    r.confirmed[c] = conf[c].confirmed();
  }
  return r;
}

FilterRecord run_filter(const docksim::WorldGenerator& g, std::uint64_t i, Worker& w,
                        const docksim::EstimatorOverrides& ov) {
  const docksim::GenScene s = g.draw(i, true, docksim::ScenePath::kApproach);
  FilterRecord r;
  r.noise = noise_class(s);
  r.excluded = exclusion(s.profile, s.lidar.angle_increment_rad, max_range_for(s));
  if (!r.excluded.empty()) return r;
  configure(w, s, ov);
  docksim::Rng rng(scan_seed(g.seed(), 2, i));
  dockcore::DockPoseFilter filter[kCases];
  Pose2 odom{};
  const std::size_t last = s.robot_path.size() - 1;
  for (std::size_t k = 0; k <= last; ++k) {
    if (k > 0) {
      const Pose2 inc = s.robot_path[k - 1].inverse().compose(s.robot_path[k]);
      odom = odom.compose(Pose2{static_cast<Real>(static_cast<double>(inc.x_m) * (1 + kOdomScaleSigma * rng.normal())),
                                static_cast<Real>(static_cast<double>(inc.y_m) + kOdomLateralSigmaM * rng.normal()),
                                static_cast<Real>(static_cast<double>(inc.yaw_rad) + kOdomYawSigmaRad * rng.normal())});
    }
    const std::uint64_t stamp = static_cast<std::uint64_t>(k) * kScanPeriodUs;
    w.simulate(s, k, rng, stamp);
    for (int c = 0; c < kCases; ++c) {
      const bool have = filter[c].initialised();
      const Pose2 hint = have ? filter[c].dock_in_robot(odom) : Pose2{};
      const dockcore::DockEstimate e =
          w.est[static_cast<std::size_t>(c)]->estimate(w.scan->view(), s.lidar_mount, have ? &hint : nullptr);
      if (e.found) {
        filter[c].update(e.pose, e.covariance, odom, stamp);
      } else {
        filter[c].predict(odom);
      }
    }
  }
  const Pose2 mount_inv = s.lidar_mount.inverse();
  for (int c = 0; c < kCases; ++c) {
    r.initialised[c] = filter[c].initialised();
    if (r.initialised[c])
      r.sensor[c] = errors_of(s.dock_in_sensor(last), mount_inv.compose(filter[c].dock_in_robot(odom)));
  }
  return r;
}

// ---------------------------------------------------------------- aggregation

json maybe(double v, double scale, double digits) {
  if (std::isnan(v)) return nullptr;
  const double f = std::pow(10.0, digits);
  return std::round(v * scale * f) / f;
}

struct Cell {
  int scenes = 0;
  Rate det[2];  // in the envelope, σ ≤ 10 mm and 10-20 mm
  int found = 0, wrong = 0;
  std::vector<double> pos, yaw, pos_robot, lat_ratio;
  std::vector<double> tail_beams;  // lat_beams of the detections beyond kTailSigmas of the bound
  Rate fp_scan, fp_confirm;

  void add_dock(const DockRecord& r, int c, bool in_envelope) {
    ++scenes;
    const Outcome& o = r.c[c];
    if (in_envelope && r.noise < 2) det[r.noise].add(o.correct);
    if (!o.found) return;
    ++found;
    if (!o.correct) {
      ++wrong;  // Counted, not mixed into the accuracy figures: those describe detections of the dock.
      return;
    }
    pos.push_back(o.sensor.pos_m);
    yaw.push_back(o.sensor.yaw_rad);
    pos_robot.push_back(o.robot.pos_m);
    if (!std::isnan(o.lat_over_crlb)) lat_ratio.push_back(o.lat_over_crlb);
    if (std::fabs(o.lat_over_crlb) > kTailSigmas) tail_beams.push_back(o.lat_beams);
  }
  void add_free(const FreeRecord& r, int c) {
    for (int k = 0; k < kConfirmScans; ++k) fp_scan.add(k < r.hits[c]);
    fp_confirm.add(r.confirmed[c]);
  }
  json to_json() const {
    json j;
    j["scenes"] = scenes;
    j["detection_sigma_le_10mm"] = det[0].to_json();
    j["detection_sigma_10_20mm"] = det[1].to_json();
    j["found"] = found;
    j["wrong"] = wrong;
    j["wrong_rate"] = scenes ? json(static_cast<double>(wrong) / scenes) : json(nullptr);
    j["pos_p95_mm"] = maybe(percentile(pos, 0.95), 1000, 1);
    j["yaw_p95_deg"] = maybe(percentile(yaw, 0.95), 1 / kDeg, 2);
    j["pos_robot_frame_p95_mm"] = maybe(percentile(pos_robot, 0.95), 1000, 1);
    j["lateral_p95_over_crlb"] = maybe(percentile(lat_ratio, 0.95), 1, 2);
    j["fp_per_scan"] = fp_scan.to_json();
    j["fp_per_confirmation"] = fp_confirm.to_json();
    return j;
  }
};

// For the range, bearing and yaw factors the bin replaces that variable's envelope condition.
bool in_envelope(const DockRecord& r, int factor) {
  const bool d = factor == kRange || r.env[0];
  const bool b = factor == kBearing || r.env[1];
  const bool y = factor == kDockYaw || r.env[2];
  return d && b && y;
}

// Every detection counts here (wrong ones too): these rows are what the robot would act on.
json rate_cell(const std::vector<const Errors*>& errs, int n) {
  std::vector<double> pos, yaw;
  int wrong = 0;
  for (const Errors* e : errs) {
    pos.push_back(e->pos_m);
    yaw.push_back(e->yaw_rad);
    wrong += is_correct(*e) ? 0 : 1;
  }
  return json{{"n", n},
              {"found_rate", n ? json(static_cast<double>(errs.size()) / n) : json(nullptr)},
              {"wrong_rate", n ? json(static_cast<double>(wrong) / n) : json(nullptr)},
              {"pos_p95_mm", maybe(percentile(pos, 0.95), 1000, 1)},
              {"yaw_p95_deg", maybe(percentile(yaw, 0.95), 1 / kDeg, 2)}};
}

// The worst bin of a factor for a detection row (0: σ ≤ 10, 1: 10-20), among bins with >= kMinBinScenes.
json worst_bin(const json& factor_rows, const char* case_name, const char* key, double target) {
  json best = nullptr;
  double worst = 2;
  bool all_met = true;
  int used = 0;
  for (const auto& row : factor_rows) {
    const json& d = row[case_name][key];
    if (d["n"].get<int>() < kMinBinScenes || d["rate"].is_null()) continue;
    ++used;
    const double r = d["rate"].get<double>();
    if (r < target) all_met = false;
    if (r < worst) {
      worst = r;
      best = json{{"bin", row["bin"]}, {"rate", r}, {"n", d["n"]}};
    }
  }
  return json{{"worst", best}, {"bins", used}, {"met", used ? json(all_met) : json(nullptr)}};
}

json targets_for(const json& out, int c) {
  const char* cn = kCaseNames[c];
  json t = json::array();
  auto add = [&](const char* what, const char* target, json measured, json met) {
    t.push_back(json{{"target", what}, {"bound", target}, {"measured", std::move(measured)}, {"met", std::move(met)}});
  };
  for (const char* factor : {"mounting", "profile"}) {
    for (int row = 0; row < 2; ++row) {
      const char* key = row == 0 ? "detection_sigma_le_10mm" : "detection_sigma_10_20mm";
      const double bound = row == 0 ? 0.99 : 0.95;
      const json w = worst_bin(out["factors"][factor], cn, key, bound);
      const std::string what = std::string("detection, every ") + factor +
                               (std::string(factor) == "profile" ? " bin" : " class") +
                               (row == 0 ? ", σ ≤ 10 mm" : ", σ 10-20 mm");
      add(what.c_str(), row == 0 ? "≥ 99 %" : "≥ 95 %", w["worst"], w["met"]);
    }
  }
  const json& o = out["overall"][cn];
  const json& fpc = o["fp_per_confirmation"];
  add("false confirmations per 3-scan confirmation on dock-less scenes", "≤ 0.1 %", fpc,
      fpc["rate"].is_null() ? json(nullptr) : json(fpc["rate"].get<double>() <= 0.001));
  const json& near = out["near_single_scan"][cn]["sigma_le_10mm"];
  add("single-scan p95 position, d ≤ 0.6 m, σ ≤ 10 mm", "≤ 10 mm",
      json{{"pos_p95_mm", near["pos_p95_mm"]}, {"yaw_p95_deg", near["yaw_p95_deg"]}},
      near["pos_p95_mm"].is_null() ? json(nullptr) : json(near["pos_p95_mm"].get<double>() <= 10.0));
  const json& fl = out["filtered_1s"][cn]["sigma_le_10mm"];
  const bool fl_ok = !fl["pos_p95_mm"].is_null() && !fl["yaw_p95_deg"].is_null();
  add("after 1 s of filtering, d ≤ 1 m, σ ≤ 10 mm: p95 position / yaw", "≤ 5 mm / ≤ 1.0°",
      json{{"pos_p95_mm", fl["pos_p95_mm"]}, {"yaw_p95_deg", fl["yaw_p95_deg"]}},
      fl_ok ? json(fl["pos_p95_mm"].get<double>() <= 5.0 && fl["yaw_p95_deg"].get<double>() <= 1.0) : json(nullptr));
  add("lateral p95 / CRLB σ (all docking scenes)", "≤ 2.2", o["lateral_p95_over_crlb"],
      o["lateral_p95_over_crlb"].is_null() ? json(nullptr) : json(o["lateral_p95_over_crlb"].get<double>() <= 2.2));
  return t;
}

}  // namespace

json run_generated(const GeneratedOptions& o) {
  docksim::WorldGenParams params;
  params.random_profiles = o.profiles;
  const docksim::WorldGenerator gen(params, o.seed);
  const std::size_t n_dock = static_cast<std::size_t>(o.scenes);
  const std::size_t n_free = static_cast<std::size_t>(o.fp_scenes < 0 ? o.scenes : o.fp_scenes);
  const std::size_t n_filter = static_cast<std::size_t>(o.filter_runs < 0 ? o.scenes / 5 : o.filter_runs);
  std::vector<DockRecord> docks(n_dock);
  std::vector<FreeRecord> frees(n_free);
  std::vector<FilterRecord> filters(n_filter);

  run_scenes(n_dock + n_free + n_filter, o.jobs, kCases, "generated worlds", [&](std::size_t i, Worker& w) {
    if (i < n_dock) {
      docks[i] = run_dock(gen, i, w, o.overrides);
    } else if (i < n_dock + n_free) {
      frees[i - n_dock] = run_free(gen, i - n_dock, w, o.overrides);
    } else {
      filters[i - n_dock - n_free] = run_filter(gen, i - n_dock - n_free, w, o.overrides);
    }
  });

  json out;
  out["config"] = {{"seed", o.seed},
                   {"docking_scenes", n_dock},
                   {"dockless_scenes", n_free},
                   {"dockless_scans_per_scene", kConfirmScans},
                   {"filtered_runs", n_filter},
                   {"random_profiles", o.profiles},
                   {"envelope", {{"distance_m", kEnvDistanceM}, {"bearing_deg", 45}, {"dock_yaw_deg", 30}}},
                   {"correct_within", {{"pos_m", kCorrectPosM}, {"yaw_deg", 10}}},
                   {"confirm_within", {{"pos_m", kAgreePosM}, {"yaw_deg", 5}}}};

  // Exclusions by reason.
  json excl;
  auto count_excl = [](std::map<std::string, int>* m, const std::string& why) {
    if (!why.empty()) ++(*m)[why];
  };
  std::map<std::string, int> ex_dock, ex_free, ex_filter;
  for (const auto& r : docks) count_excl(&ex_dock, r.excluded);
  for (const auto& r : frees) count_excl(&ex_free, r.excluded);
  for (const auto& r : filters) count_excl(&ex_filter, r.excluded);
  excl["docking"] = ex_dock;
  excl["dockless"] = ex_free;
  excl["filtered"] = ex_filter;
  out["excluded"] = excl;

  // Per factor and overall.
  json factors;
  for (int f = 0; f < kFactorCount; ++f) {
    const std::vector<std::string> names = bin_names(static_cast<Factor>(f), params);
    std::vector<Cell> cells(names.size() * kCases);
    std::vector<int> excluded(names.size(), 0);
    for (const auto& r : docks) {
      const std::size_t b = static_cast<std::size_t>(r.bins[f]);
      if (!r.excluded.empty()) {
        ++excluded[b];
        continue;
      }
      for (int c = 0; c < kCases; ++c)
        cells[b * kCases + static_cast<std::size_t>(c)].add_dock(r, c, in_envelope(r, f));
    }
    for (const auto& r : frees) {
      if (!r.excluded.empty()) continue;
      const std::size_t b = static_cast<std::size_t>(r.bins[f]);
      for (int c = 0; c < kCases; ++c) cells[b * kCases + static_cast<std::size_t>(c)].add_free(r, c);
    }
    json rows = json::array();
    for (std::size_t b = 0; b < names.size(); ++b) {
      json row;
      row["bin"] = names[b];
      row["excluded"] = excluded[b];
      for (int c = 0; c < kCases; ++c) row[kCaseNames[c]] = cells[b * kCases + static_cast<std::size_t>(c)].to_json();
      rows.push_back(row);
    }
    factors[kFactorNames[f]] = rows;
  }
  out["factors"] = factors;
  {
    json overall;
    for (int c = 0; c < kCases; ++c) {
      Cell cell;
      for (const auto& r : docks)
        if (r.excluded.empty()) cell.add_dock(r, c, in_envelope(r, -1));
      for (const auto& r : frees)
        if (r.excluded.empty()) cell.add_free(r, c);
      overall[kCaseNames[c]] = cell.to_json();
      // The shape of the lateral error against the bound: a Gaussian estimator at the bound has its p50 / p90 / p95
      // / p99 of |error| / σ at 0.67 / 1.64 / 1.96 / 2.58; a core near those with a larger p95 is a heavy tail.
      json q;
      for (const double at : {0.5, 0.9, 0.95, 0.99}) {
        char key[8];
        std::snprintf(key, sizeof key, "p%.0f", 100 * at);
        q[key] = maybe(percentile(cell.lat_ratio, at), 1, 2);
      }
      overall[kCaseNames[c]]["lateral_over_crlb_quantiles"] = q;
      // The tail: how far along the face those detections lie off, in beams at the dock's range.
      overall[kCaseNames[c]]["lateral_tail"] = {
          {"beyond_sigmas", kTailSigmas},
          {"n", cell.tail_beams.size()},
          {"of", cell.lat_ratio.size()},
          {"median_beam_spacings", maybe(percentile(cell.tail_beams, 0.5), 1, 2)}};
    }
    out["overall"] = overall;
  }
  // Misses in the envelope at σ ≤ 20 mm by cause, most frequent first.
  {
    json misses;
    for (int c = 0; c < kCases; ++c) {
      std::map<std::string, int> count[2];
      int n[2] = {};
      for (const auto& r : docks) {
        if (!r.excluded.empty() || !in_envelope(r, -1) || r.noise > 1) continue;
        ++n[r.noise];
        if (!r.c[c].correct) ++count[r.noise][r.c[c].miss];
      }
      for (int k = 0; k < 2; ++k) {
        std::vector<std::pair<int, std::string>> v;
        for (const auto& [why, m] : count[k]) v.emplace_back(m, why);
        std::stable_sort(v.begin(), v.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
        json rows = json::array();
        for (const auto& [m, why] : v) rows.push_back(json{{"cause", why}, {"misses", m}});
        misses[kCaseNames[c]][k == 0 ? "sigma_le_10mm" : "sigma_10_20mm"] = json{{"scenes", n[k]}, {"causes", rows}};
      }
    }
    out["misses"] = misses;
  }
  // False positives by look-alike.
  {
    json rows = json::array();
    for (int k = 0; k < docksim::kPlainLookAlikes; ++k) {
      json row;
      row["look_alike"] = docksim::to_string(static_cast<docksim::LookAlike>(k));
      for (int c = 0; c < kCases; ++c) {
        Cell cell;
        for (const auto& r : frees)
          if (r.excluded.empty() && r.look_alike == k) cell.add_free(r, c);
        row[kCaseNames[c]] = {{"fp_per_scan", cell.fp_scan.to_json()},
                              {"fp_per_confirmation", cell.fp_confirm.to_json()}};
      }
      rows.push_back(row);
    }
    out["look_alikes"] = rows;
  }
  // Single scan near the dock, and 1 s of filtering.
  {
    json near, filt;
    for (int c = 0; c < kCases; ++c) {
      for (int row = 0; row < 2; ++row) {
        std::vector<const Errors*> errs;
        int n = 0;
        for (const auto& r : docks) {
          if (!r.excluded.empty() || r.distance_m > 0.6 || !r.env[1] || !r.env[2]) continue;
          if (row == 0 && r.noise != 0) continue;
          ++n;
          if (r.c[c].found) errs.push_back(&r.c[c].sensor);
        }
        near[kCaseNames[c]][row == 0 ? "sigma_le_10mm" : "all"] = rate_cell(errs, n);
        errs.clear();
        n = 0;
        for (const auto& r : filters) {
          if (!r.excluded.empty()) continue;
          if (row == 0 && r.noise != 0) continue;
          ++n;
          if (r.initialised[c]) errs.push_back(&r.sensor[c]);
        }
        filt[kCaseNames[c]][row == 0 ? "sigma_le_10mm" : "all"] = rate_cell(errs, n);
      }
    }
    out["near_single_scan"] = near;
    out["filtered_1s"] = filt;
  }
  // The random profiles: check_profile's verdict at LD06 spacing and the estimator's range, and how each fared.
  {
    json rows = json::array();
    const double ld06_spacing = 2 * dockcore::kPi / 450.0;
    for (std::size_t p = 0; p < gen.random_profiles().size(); ++p) {
      const dockcore::DockProfile& prof = gen.random_profiles()[p];
      json row;
      row["name"] = prof.name;
      json v = json::array();
      for (std::size_t k = 0; k < prof.vertex_count; ++k)
        v.push_back({std::round(static_cast<double>(prof.vertices_m[k].x()) * 1e4) / 1e4,
                     std::round(static_cast<double>(prof.vertices_m[k].y()) * 1e4) / 1e4});
      row["vertices"] = v;
      row["width_m"] = std::round(static_cast<double>(prof.width_m()) * 1e3) / 1e3;
      const std::string why = exclusion(prof, ld06_spacing, 2.5);
      row["check_ld06"] = why.empty() ? "ok" : why;
      for (int c = 0; c < kCases; ++c) {
        Rate det;
        int excluded = 0;
        for (const auto& r : docks) {
          if (r.random_index != static_cast<int>(p)) continue;
          if (!r.excluded.empty()) {
            ++excluded;
            continue;
          }
          if (in_envelope(r, -1) && r.noise < 2) det.add(r.c[c].correct);
        }
        row[kCaseNames[c]] = {{"detection_sigma_le_20mm", det.to_json()}, {"excluded_scenes", excluded}};
      }
      rows.push_back(row);
    }
    out["random_profiles"] = rows;
  }
  json targets;
  for (int c = 0; c < kCases; ++c) targets[kCaseNames[c]] = targets_for(out, c);
  out["targets"] = targets;
  return out;
}

// ---------------------------------------------------------------- printing

namespace {

const std::vector<Column> kFactorColumns = {
    {"bin", 20, false},           {"case", 7, false},        {"scenes", 6, true},          {"det σ≤10 (n)", 15, true},
    {"det σ10-20 (n)", 15, true}, {"wrong", 7, true},        {"pos95", 6, true},           {"yaw95", 6, true},
    {"pos95r", 6, true},          {"FP/scan (n)", 15, true}, {"FP/confirm (n)", 15, true}, {"lat95/CRLB", 10, true}};

std::vector<std::string> factor_cells(const std::string& bin, int c, const json& x) {
  return {bin,
          kCaseNames[c],
          std::to_string(x["scenes"].get<int>()),
          rate_n(x["detection_sigma_le_10mm"]),
          rate_n(x["detection_sigma_10_20mm"]),
          pct(x["wrong_rate"]),
          fmt(x["pos_p95_mm"], "%.1f"),
          fmt(x["yaw_p95_deg"], "%.2f"),
          fmt(x["pos_robot_frame_p95_mm"], "%.1f"),
          rate_n(x["fp_per_scan"], "%.2f %%"),
          rate_n(x["fp_per_confirmation"], "%.2f %%"),
          fmt(x["lateral_p95_over_crlb"], "%.2f")};
}

std::string measured_text(const json& m) {
  if (m.is_null()) return "-";
  if (m.is_number()) return fmt(m, "%.2f");
  if (m.contains("bin")) return "worst: " + m["bin"].get<std::string>() + " " + rate_n(m);
  if (m.contains("pos_p95_mm")) return fmt(m["pos_p95_mm"], "%.1f mm") + " / " + fmt(m["yaw_p95_deg"], "%.2f°");
  if (m.contains("hits")) {
    return std::to_string(m["hits"].get<int>()) + " / " + std::to_string(m["n"].get<int>()) + " = " +
           pct(m["rate"], "%.2f %%");
  }
  return m.dump();
}

}  // namespace

void print_generated(const json& j) {
  const json& cfg = j["config"];
  std::printf(
      "\n== Generated worlds (seed %llu): %d docking scenes, %d dock-less scenes x %d scans, %d filtered runs, "
      "%d random profiles\n",
      static_cast<unsigned long long>(cfg["seed"].get<std::uint64_t>()), cfg["docking_scenes"].get<int>(),
      cfg["dockless_scenes"].get<int>(), cfg["dockless_scans_per_scene"].get<int>(), cfg["filtered_runs"].get<int>(),
      cfg["random_profiles"].get<int>());
  std::printf(
      "told = the profile's mounting is the world's; unknown = left kUnknown. det = found within 0.10 m / 10° of the\n"
      "truth (sensor frame) in the envelope d ≤ 2.0 m, |bearing| ≤ 45°, |dock yaw| ≤ 30° (in the range, bearing and\n"
      "dock-yaw tables the bin replaces its own condition); (n) = scenes counted. wrong = found elsewhere, per scene.\n"
      "pos95 (mm) / yaw95 (°) / lat95/CRLB: over detections of the dock, sensor frame; pos95r: robot frame, with the\n"
      "unknown calibration error. FP: dock-less scenes, per scan and per 3-scan confirmation.\n");
  for (const char* what : {"docking", "dockless", "filtered"}) {
    std::string line = std::string("excluded by check_profile, ") + what + ":";
    if (j["excluded"][what].empty()) line += " none";
    for (const auto& [why, n] : j["excluded"][what].items())
      line += " " + why + " " + std::to_string(n.get<int>()) + ";";
    std::printf("%s\n", line.c_str());
  }
  for (const auto& [factor, rows] : j["factors"].items()) {
    std::printf("\n-- %s\n", factor.c_str());
    print_header(kFactorColumns);
    for (const auto& row : rows) {
      for (int c = 0; c < kCases; ++c)
        print_row(kFactorColumns, factor_cells(c == 0 ? row["bin"].get<std::string>() : "", c, row[kCaseNames[c]]));
    }
  }
  std::printf("\n-- overall\n");
  print_header(kFactorColumns);
  for (int c = 0; c < kCases; ++c) print_row(kFactorColumns, factor_cells("all", c, j["overall"][kCaseNames[c]]));
  std::printf("lateral |error| / CRLB σ, p50 / p90 / p95 / p99 (a Gaussian at the bound: 0.67 / 1.64 / 1.96 / 2.58):");
  for (int c = 0; c < kCases; ++c) {
    const json& q = j["overall"][kCaseNames[c]]["lateral_over_crlb_quantiles"];
    std::printf("%s %s %s / %s / %s / %s", c == 0 ? "" : ";", kCaseNames[c], fmt(q["p50"], "%.2f").c_str(),
                fmt(q["p90"], "%.2f").c_str(), fmt(q["p95"], "%.2f").c_str(), fmt(q["p99"], "%.2f").c_str());
  }
  std::printf("\n");
  for (int c = 0; c < kCases; ++c) {
    const json& t = j["overall"][kCaseNames[c]]["lateral_tail"];
    std::printf("%s: %d of %d detections beyond %.0f σ of the bound, off along the face by a median %s beam spacings\n",
                kCaseNames[c], t["n"].get<int>(), t["of"].get<int>(), t["beyond_sigmas"].get<double>(),
                fmt(t["median_beam_spacings"], "%.2f").c_str());
  }

  std::printf("\n-- misses in the envelope by cause (share of the scenes of that noise class)\n");
  for (int c = 0; c < kCases; ++c) {
    for (const char* k : {"sigma_le_10mm", "sigma_10_20mm"}) {
      const json& m = j["misses"][kCaseNames[c]][k];
      const int n = m["scenes"].get<int>();
      std::printf("%s, %s (%d scenes):\n", kCaseNames[c], std::string(k) == "sigma_le_10mm" ? "σ ≤ 10 mm" : "σ 10-20 mm",
                  n);
      for (const auto& row : m["causes"])
        std::printf("  %6.2f %%  %5d  %s\n", n ? 100.0 * row["misses"].get<int>() / n : 0.0, row["misses"].get<int>(),
                    row["cause"].get<std::string>().c_str());
    }
  }

  std::printf("\n-- false positives by look-alike (dock-less scenes)\n");
  const std::vector<Column> lc = {
      {"look-alike", 12, false}, {"case", 7, false}, {"FP/scan (n)", 16, true}, {"FP/confirm (n)", 16, true}};
  print_header(lc);
  for (const auto& row : j["look_alikes"]) {
    for (int c = 0; c < kCases; ++c) {
      const json& x = row[kCaseNames[c]];
      print_row(lc, {c == 0 ? row["look_alike"].get<std::string>() : "", kCaseNames[c],
                     rate_n(x["fp_per_scan"], "%.2f %%"), rate_n(x["fp_per_confirmation"], "%.2f %%")});
    }
  }

  std::printf(
      "\n-- single scan at d ≤ 0.6 m; after 1 s of filtering (10 scans at 10 Hz, approaching) at d ≤ 1 m;\n"
      "   |bearing| ≤ 45°, |dock yaw| ≤ 30°; every detection counts (wrong ones too)\n");
  const std::vector<Column> nc = {{"", 17, false},    {"case", 7, false}, {"noise", 10, false}, {"n", 6, true},
                                  {"found", 8, true}, {"wrong", 7, true}, {"pos95", 7, true},   {"yaw95", 6, true}};
  print_header(nc);
  for (const char* sec : {"near_single_scan", "filtered_1s"}) {
    for (int c = 0; c < kCases; ++c) {
      for (const char* row : {"sigma_le_10mm", "all"}) {
        const json& x = j[sec][kCaseNames[c]][row];
        print_row(nc, {std::string(sec) == "near_single_scan" ? "single scan" : "filtered 1 s", kCaseNames[c],
                       std::string(row) == "all" ? "all σ" : "σ ≤ 10 mm", std::to_string(x["n"].get<int>()),
                       pct(x["found_rate"]), pct(x["wrong_rate"]), fmt(x["pos_p95_mm"], "%.1f"),
                       fmt(x["yaw_p95_deg"], "%.2f")});
      }
    }
  }

  std::printf("\n-- random profiles that check_profile refuses (LD06 0.8°, 2.5 m); left out of every figure\n");
  int refused = 0;
  std::map<std::string, int> why_count;
  for (const auto& p : j["random_profiles"]) {
    if (p["check_ld06"] == "ok") continue;
    ++refused;
    ++why_count[p["check_ld06"].get<std::string>()];
    std::printf("%s %s %zu vertices, %.3f m wide  %s\n", pad(p["name"].get<std::string>(), 11).c_str(),
                pad(p["check_ld06"].get<std::string>(), 22).c_str(), p["vertices"].size(), p["width_m"].get<double>(),
                p["vertices"].dump().c_str());
  }
  std::string summary;
  for (const auto& [why, n] : why_count) summary += " " + why + " " + std::to_string(n) + ";";
  std::printf("%d of %zu refused:%s\n", refused, j["random_profiles"].size(), refused ? summary.c_str() : " none");

  std::vector<std::pair<double, const json*>> ranked;
  for (const auto& p : j["random_profiles"]) {
    const json& d = p["told"]["detection_sigma_le_20mm"];
    if (p["check_ld06"] == "ok" && d["n"].get<int>() >= 5 && !d["rate"].is_null())
      ranked.emplace_back(d["rate"].get<double>(), &p);
  }
  std::stable_sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::printf(
      "\n-- worst random profiles check_profile accepts at LD06 (detection in the envelope, σ ≤ 20 mm, ≥ 5 scenes)\n");
  for (std::size_t i = 0; i < std::min<std::size_t>(10, ranked.size()); ++i) {
    const json& p = *ranked[i].second;
    std::printf("%s told %s unknown %s  %s\n", pad(p["name"].get<std::string>(), 11).c_str(),
                pad(rate_n(p["told"]["detection_sigma_le_20mm"]), 13, true).c_str(),
                pad(rate_n(p["unknown"]["detection_sigma_le_20mm"]), 13, true).c_str(), p["vertices"].dump().c_str());
  }

  std::printf("\n== Targets on generated worlds\n");
  const std::vector<Column> tc = {
      {"target", 66, false}, {"bound", 16, false}, {"case", 7, false}, {"measured", 36, false}, {"met", 3, false}};
  print_header(tc);
  for (int c = 0; c < kCases; ++c) {
    for (const auto& t : j["targets"][kCaseNames[c]]) {
      print_row(tc, {t["target"].get<std::string>(), t["bound"].get<std::string>(), kCaseNames[c],
                     measured_text(t["measured"]),
                     t["met"].is_null()     ? "n/a"
                     : t["met"].get<bool>() ? "yes"
                                            : "NO"});
    }
  }
}

}  // namespace docksim_cli
