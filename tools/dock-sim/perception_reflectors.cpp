// `dock-sim perception --sections reflectors`: DockPoseEstimator reading a dock's reflector stripes as its code, over
// worlds drawn by docksim::WorldGenerator in reflector mode (LD06 intensity, a 3-region code on the dock's longest
// segment, reflective clutter, tape look-alikes), with the intensity usable and, on the same scans, not (geometry
// only); and the readable range of a code per lidar and region width. Figures are printed, never asserted. See
// docs/performance.md ("Reflector docks").
#include "perception_reflectors.hpp"

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "dockcore/perception/dock_pose_estimator.hpp"
#include "docksim/world_gen.hpp"
#include "mc_stats.hpp"
#include "perception_gen_common.hpp"
#include "perception_stats.hpp"

namespace docksim_cli {

using namespace genbench;

namespace {

using dockcore::Pose2;
using dockcore::Real;

// The estimator on the same scans with the intensity usable (the stripes read) and not (geometry only). Both are told
// the dock's mounting as the world has it.
constexpr int kCases = 2;
const char* const kCaseNames[kCases] = {"intensity", "geometry"};
constexpr double kDetectionTarget = 0.995;
constexpr double kFpConfirmTarget = 0.0001;
constexpr double kReadTarget = 0.99;
constexpr double kAlpha = 0.05;  // One-sided 95 % bounds.
constexpr int kBearingBins = 4;
const double kBearingEdgesDeg[kBearingBins + 1] = {0, 15, 30, 45, 60};
// Readable-range table: lidars, region widths, and what head-on-ish means.
const char* const kReadLidars[] = {"ld06", "industrial"};
const double kReadRegionsM[] = {0.05, 0.075, 0.10};
constexpr double kHeadOnRad = 30 * kDeg;
constexpr int kMinReadBinScenes = 50;  // A bin with fewer read attempts decides nothing.
// Incidence on the taped segment (its midpoint seen from the true lidar), for the code-read table.
constexpr int kIncidenceBins = 4;
const double kIncidenceEdgesDeg[kIncidenceBins + 1] = {0, 30, 45, 60, 90};
// The dock face's reflectivity (drawn 0.5-0.95): a white face near the lidar reads as bright as tape.
constexpr int kFaceBins = 3;
const double kFaceEdges[kFaceBins + 1] = {0.5, 0.7, 0.9, 0.95};
// Scan streams (scan_seed), apart from the generated section's 0-2.
constexpr std::uint64_t kDockStream = 10, kFreeStream = 11, kReadStream = 12;

/// What became of the dock in a docking scene, for one case.
enum class Code : std::uint8_t {
  kRight,      ///< Found at the dock: the right id.
  kUnread,     ///< The dock's pose refused as code_unread.
  kWrongCode,  ///< The dock's pose refused as wrong_code (its own code misread).
  kOtherMiss,  ///< Refused for a geometric reason, or no candidate at the dock.
  kElsewhere,  ///< Another pose accepted.
};

std::string range_name(int b) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f-%.1f m", kRangeEdges[b], kRangeEdges[b + 1]);
  return buf;
}

docksim::WorldGenParams reflector_params(int profiles) {
  docksim::WorldGenParams p;
  p.reflectors = true;
  p.lidars = {"ld06"};
  p.random_profiles = profiles;
  return p;
}

/// Estimator c (c < cases) told the scene's profile with its stripes and its mounting; intensity usable for case 0.
void configure(Worker& w, const docksim::GenScene& s, int cases, const ReflectorOptions& o) {
  dockcore::DockProfile p = s.profile;
  p.mounting = s.told_mounting;
  for (int c = 0; c < cases; ++c) {
    dockcore::DockPoseEstimator& e = *w.est[static_cast<std::size_t>(c)];
    e.configure(p, scene_params(s, o.overrides));
    e.set_intensity_usable(c == 0);
  }
}

/// Why the scene is left out ("" when it is not): check_profile, then a profile with no segment for the code.
std::string excluded_why(const docksim::GenScene& s, double region_m) {
  const std::string why =
      exclusion(s.profile, s.lidar.angle_increment_rad, static_cast<double>(scene_params(s).max_range_m));
  if (!why.empty() || s.code_pattern != 0) return why;
  char buf[64];
  if (region_m > 0) {
    std::snprintf(buf, sizeof buf, "no segment >= %.3f m for the code", 3 * region_m);
  } else {
    std::snprintf(buf, sizeof buf, "no segment >= %.2f m for the code", docksim::kCodeMinSegmentM);
  }
  return buf;
}

/// Incidence of the ray from the true lidar to the taped segment's midpoint on that segment, rad (0 = head on);
/// NaN without a code. O(1).
double code_incidence_rad(const docksim::GenScene& s) {
  if (s.code_segment < 0) return std::nan("");
  const std::size_t k = static_cast<std::size_t>(s.code_segment);
  const dockcore::Vec2 a = s.dock_in_world.transform(s.profile.vertices_m[k]);
  const dockcore::Vec2 b = s.dock_in_world.transform(s.profile.vertices_m[k + 1]);
  const Pose2 l = s.lidar_in_world(0);
  const double mx = 0.5 * static_cast<double>(a.x() + b.x()) - static_cast<double>(l.x_m);
  const double my = 0.5 * static_cast<double>(a.y() + b.y()) - static_cast<double>(l.y_m);
  const double ex = static_cast<double>(b.x() - a.x()), ey = static_cast<double>(b.y() - a.y());
  const double c = std::fabs(mx * ey - my * ex) / (std::hypot(mx, my) * std::hypot(ex, ey));
  return std::acos(std::min(1.0, c));
}

Code code_of(const dockcore::DockEstimate& e, const Pose2& truth_sensor, const Pose2& mount_inv) {
  if (e.found) return is_correct(errors_of(truth_sensor, mount_inv.compose(e.pose))) ? Code::kRight : Code::kElsewhere;
  if (e.status != dockcore::EstimateStatus::kNotVerified) return Code::kOtherMiss;
  if (!is_correct(errors_of(truth_sensor, mount_inv.compose(e.refused_pose)))) return Code::kOtherMiss;
  if (e.reject == dockcore::RejectReason::kCodeUnread) return Code::kUnread;
  if (e.reject == dockcore::RejectReason::kWrongCode) return Code::kWrongCode;
  return Code::kOtherMiss;
}

struct DockRecord {
  std::string excluded;
  int range_bin = 0, bearing_bin = 0, incidence_bin = 0, face_bin = 0;
  double incidence_rad = 0;  // On the taped segment.
  bool env[3] = {};          // distance, bearing, yaw within the envelope
  bool low_noise = false;
  Code code[kCases] = {};
  std::string miss[kCases];
};

struct FreeRecord {
  std::string excluded;
  std::uint64_t index = 0;  // The dock-less scene's index (WorldGenerator::draw), to re-generate it.
  int look_alike = 0;
  unsigned reflective = 0;   // Bit k: a ReflectiveClass k object was placed.
  int hits[kCases] = {};     // Scans with a detection.
  int at_look[kCases] = {};  // Of which at the look-alike's place.
  bool confirmed[kCases] = {}, confirmed_at_look[kCases] = {};
  std::vector<std::string> elsewhere;  // Intensity case: what each detection away from the look-alike lay on.
};

/// What a detection's dock origin (world) lies on: the first object other than the walls whose bounding circle,
/// widened by 5 cm, holds it (clutter, reflective objects, the look-alike), else "walls or nothing". O(objects).
std::string object_at(const docksim::GenScene& s, const Pose2& dock_in_world) {
  for (const docksim::GenObject& o : s.objects) {
    if (o.kind == "wall" || o.kind == "second-wall" || o.kind == "room-wall" || o.kind == "skirting") continue;
    const double d = std::hypot(static_cast<double>(o.centre_m.x() - dock_in_world.x_m),
                                static_cast<double>(o.centre_m.y() - dock_in_world.y_m));
    if (d <= o.radius_m + 0.05) return o.kind;
  }
  return "walls or nothing";
}

DockRecord run_dock(const docksim::WorldGenerator& g, std::uint64_t i, Worker& w, int cases, std::uint64_t stream,
                    const ReflectorOptions& o) {
  const docksim::GenScene s = g.draw(i, true, docksim::ScenePath::kSingle);
  DockRecord r;
  r.range_bin = edge_bin(s.distance_m, kRangeEdges, kRangeBins);
  r.bearing_bin = edge_bin(std::fabs(s.bearing_rad) / kDeg, kBearingEdgesDeg, kBearingBins);
  r.env[0] = s.distance_m <= kEnvDistanceM;
  r.env[1] = std::fabs(s.bearing_rad) <= kEnvBearingRad;
  r.env[2] = std::fabs(s.dock_yaw_rad) <= kEnvYawRad;
  r.low_noise = s.sigma_at(s.distance_m) <= 0.010;
  r.excluded = excluded_why(s, g.params().code_region_m);
  r.incidence_rad = code_incidence_rad(s);
  r.incidence_bin = edge_bin(r.incidence_rad / kDeg, kIncidenceEdgesDeg, kIncidenceBins);
  r.face_bin = edge_bin(s.dock_reflectivity, kFaceEdges, kFaceBins);
  if (!r.excluded.empty()) return r;
  docksim::Rng rng(scan_seed(g.seed(), stream, i));
  w.simulate(s, 0, rng, 0);
  configure(w, s, cases, o);
  const Pose2 truth_sensor = s.dock_in_sensor(0), mount_inv = s.lidar_mount.inverse();
  for (int c = 0; c < cases; ++c) {
    const dockcore::DockEstimate e = w.est[static_cast<std::size_t>(c)]->estimate(w.scan->view(), s.lidar_mount);
    r.code[c] = code_of(e, truth_sensor, mount_inv);
    if (r.code[c] != Code::kRight) r.miss[c] = miss_cause(e, truth_sensor, mount_inv);
  }
  return r;
}

FreeRecord run_free(const docksim::WorldGenerator& g, std::uint64_t i, Worker& w, const ReflectorOptions& o) {
  const docksim::GenScene s = g.draw(i, false, docksim::ScenePath::kConfirm);
  FreeRecord r;
  r.index = i;
  r.look_alike = static_cast<int>(s.look_alike);
  for (const docksim::ReflectiveClass k : s.reflective) r.reflective |= 1u << static_cast<unsigned>(k);
  r.excluded = excluded_why(s, 0);
  if (!r.excluded.empty()) return r;
  configure(w, s, kCases, o);
  docksim::Rng rng(scan_seed(g.seed(), kFreeStream, i));
  const Pose2 mount_inv = s.lidar_mount.inverse();
  Confirmation conf[kCases];
  bool first_at_look[kCases] = {};
  for (int k = 0; k < kConfirmScans; ++k) {
    w.simulate(s, static_cast<std::size_t>(k), rng, static_cast<std::uint64_t>(k) * kScanPeriodUs);
    for (int c = 0; c < kCases; ++c) {
      const dockcore::DockEstimate e = w.est[static_cast<std::size_t>(c)]->estimate(w.scan->view(), s.lidar_mount);
      conf[c].add(k, e, s.robot_path[static_cast<std::size_t>(k)]);
      if (!e.found) continue;
      // The look-alike stands where the dock would: a detection there is the look-alike taken for the dock.
      const bool at = is_correct(errors_of(s.dock_in_sensor(static_cast<std::size_t>(k)), mount_inv.compose(e.pose)));
      r.at_look[c] += at ? 1 : 0;
      if (k == 0) first_at_look[c] = at;
      if (c == 0 && !at) r.elsewhere.push_back(object_at(s, s.robot_path[static_cast<std::size_t>(k)].compose(e.pose)));
    }
  }
  for (int c = 0; c < kCases; ++c) {
    r.hits[c] = conf[c].hits;
    r.confirmed[c] = conf[c].confirmed();
    r.confirmed_at_look[c] = r.confirmed[c] && first_at_look[c];
  }
  return r;
}

// ---------------------------------------------------------------- aggregation

/// A Rate's JSON with its one-sided 95 % Clopper–Pearson upper bound.
json with_upper(const Rate& r) {
  json j = r.to_json();
  j["upper95"] = r.n ? json(clopper_pearson_upper(r.n, r.k, kAlpha)) : json(nullptr);
  return j;
}

struct FpCell {
  Rate scan, confirm, scan_at, confirm_at;
  void add(const FreeRecord& r, int c) {
    for (int k = 0; k < kConfirmScans; ++k) {
      scan.add(k < r.hits[c]);
      scan_at.add(k < r.at_look[c]);
    }
    confirm.add(r.confirmed[c]);
    confirm_at.add(r.confirmed_at_look[c]);
  }
  json to_json() const {
    return json{{"fp_per_scan", with_upper(scan)},
                {"fp_per_confirmation", with_upper(confirm)},
                {"at_look_alike_per_scan", with_upper(scan_at)},
                {"at_look_alike_per_confirmation", with_upper(confirm_at)}};
  }
};

std::map<std::string, int> count_excluded(const std::vector<DockRecord>& docks) {
  std::map<std::string, int> m;
  for (const auto& r : docks)
    if (!r.excluded.empty()) ++m[r.excluded];
  return m;
}

/// Code outcomes of the intensity case over `rows`' scenes: counts and the read rate (right id among the dock's poses
/// that reached the code's decision: right, code_unread, wrong_code).
json code_outcomes(const std::vector<const DockRecord*>& rows) {
  int n = 0, count[5] = {};
  Rate read;
  for (const DockRecord* r : rows) {
    ++n;
    const Code c = r->code[0];
    ++count[static_cast<int>(c)];
    if (c == Code::kRight || c == Code::kUnread || c == Code::kWrongCode) read.add(c == Code::kRight);
  }
  return json{{"n", n},
              {"right_id", count[static_cast<int>(Code::kRight)]},
              {"code_unread_at_dock", count[static_cast<int>(Code::kUnread)]},
              {"wrong_code_at_dock", count[static_cast<int>(Code::kWrongCode)]},
              {"other_miss", count[static_cast<int>(Code::kOtherMiss)]},
              {"found_elsewhere", count[static_cast<int>(Code::kElsewhere)]},
              {"read", read.to_json()}};
}

/// The readable-range rows: per lidar and region width, the read rate per range bin over head-on-ish docking scenes
/// (|bearing| and |dock yaw| drawn within kHeadOnRad, and the taped segment seen within kHeadOnRad of its normal),
/// and the farthest bin with kMinReadBinScenes or more read attempts that reads >= kReadTarget.
json run_read_range(const ReflectorOptions& o) {
  json rows = json::array();
  for (const char* lidar : kReadLidars) {
    for (const double region_m : kReadRegionsM) {
      docksim::WorldGenParams p = reflector_params(o.profiles);
      p.lidars = {lidar};
      p.code_region_m = region_m;
      p.bearing_max_rad = kHeadOnRad;
      p.dock_yaw_max_rad = kHeadOnRad;
      const docksim::WorldGenerator gen(p, o.seed);
      std::vector<DockRecord> docks(static_cast<std::size_t>(o.read_range_scenes));
      char label[64];
      std::snprintf(label, sizeof label, "read range %s %.1f cm", lidar, 100 * region_m);
      run_scenes(docks.size(), o.jobs, 1, label,
                 [&](std::size_t i, Worker& w) { docks[i] = run_dock(gen, i, w, 1, kReadStream, o); });
      json bins = json::array();
      json farthest = nullptr;
      for (int b = 0; b < kRangeBins; ++b) {
        std::vector<const DockRecord*> in;
        for (const auto& r : docks)
          if (r.excluded.empty() && r.range_bin == b && r.incidence_rad <= kHeadOnRad) in.push_back(&r);
        json c = code_outcomes(in);
        c["bin"] = range_name(b);
        const json& rd = c["read"];
        if (rd["n"].get<int>() >= kMinReadBinScenes && rd["rate"].get<double>() >= kReadTarget)
          farthest = range_name(b);
        bins.push_back(c);
      }
      rows.push_back(json{{"lidar", lidar},
                          {"region_m", region_m},
                          {"scenes", o.read_range_scenes},
                          {"excluded", count_excluded(docks)},
                          {"farthest_bin_read_ge_99", farthest},
                          {"bins", bins}});
    }
  }
  return rows;
}

}  // namespace

json run_reflectors(const ReflectorOptions& o) {
  const docksim::WorldGenParams params = reflector_params(o.profiles);
  const docksim::WorldGenerator gen(params, o.seed);
  const std::size_t n_dock = static_cast<std::size_t>(o.scenes);
  const std::size_t n_free = static_cast<std::size_t>(o.fp_scenes < 0 ? o.scenes : o.fp_scenes);
  std::vector<DockRecord> docks(n_dock);
  std::vector<FreeRecord> frees(n_free);
  run_scenes(n_dock + n_free, o.jobs, kCases, "reflector worlds", [&](std::size_t i, Worker& w) {
    if (i < n_dock) {
      docks[i] = run_dock(gen, i, w, kCases, kDockStream, o);
    } else {
      frees[i - n_dock] = run_free(gen, i - n_dock, w, o);
    }
  });

  json out;
  out["config"] = {{"seed", o.seed},
                   {"docking_scenes", n_dock},
                   {"dockless_scenes", n_free},
                   {"dockless_scans_per_scene", kConfirmScans},
                   {"random_profiles", o.profiles},
                   {"lidar", "ld06"},
                   {"mounting", "told"},
                   {"stripe_hypotheses", o.overrides.stripe_hypotheses},
                   {"envelope", {{"distance_m", kEnvDistanceM}, {"bearing_deg", 45}, {"dock_yaw_deg", 30}}},
                   {"correct_within", {{"pos_m", kCorrectPosM}, {"yaw_deg", 10}}},
                   {"confirm_within", {{"pos_m", kAgreePosM}, {"yaw_deg", 5}}}};
  {
    std::map<std::string, int> ex_free;
    for (const auto& r : frees)
      if (!r.excluded.empty()) ++ex_free[r.excluded];
    out["excluded"] = {{"docking", count_excluded(docks)}, {"dockless", ex_free}};
  }
  auto in_env = [](const DockRecord& r, bool range, bool bearing) {
    return r.excluded.empty() && (range || r.env[0]) && (bearing || r.env[1]) && r.env[2];
  };
  {
    json det;
    for (int c = 0; c < kCases; ++c) {
      Rate all, low;
      for (const auto& r : docks) {
        if (!in_env(r, false, false)) continue;
        all.add(r.code[c] == Code::kRight);
        if (r.low_noise) low.add(r.code[c] == Code::kRight);
      }
      det[kCaseNames[c]] = {{"all", all.to_json()}, {"sigma_le_10mm", low.to_json()}};
    }
    out["detection"] = det;
  }
  // One row per bin of a factor: detection per case and the code outcomes, over the envelope's scenes with the
  // factor's own condition (range, bearing) replaced by its bin.
  auto table = [&](int bins, bool free_range, bool free_bearing, const auto& name_of, const auto& bin_of) {
    json rows = json::array();
    for (int b = 0; b < bins; ++b) {
      json row;
      row["bin"] = name_of(b);
      std::vector<const DockRecord*> in;
      for (const auto& r : docks)
        if (in_env(r, free_range, free_bearing) && bin_of(r) == b) in.push_back(&r);
      for (int c = 0; c < kCases; ++c) {
        Rate d;
        for (const DockRecord* r : in) d.add(r->code[c] == Code::kRight);
        row[kCaseNames[c]] = d.to_json();
      }
      row["code"] = code_outcomes(in);
      rows.push_back(row);
    }
    return rows;
  };
  out["by_range"] = table(
      kRangeBins, true, false, [](int b) { return range_name(b); }, [](const DockRecord& r) { return r.range_bin; });
  out["by_bearing"] = table(
      kBearingBins, false, true,
      [](int b) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "|b| %.0f-%.0f°", kBearingEdgesDeg[b], kBearingEdgesDeg[b + 1]);
        return std::string(buf);
      },
      [](const DockRecord& r) { return r.bearing_bin; });
  // Code outcomes in the envelope by the incidence on the taped segment and by the face's reflectivity.
  out["by_incidence"] = table(
      kIncidenceBins, false, false,
      [](int b) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "inc %.0f-%.0f°", kIncidenceEdgesDeg[b], kIncidenceEdgesDeg[b + 1]);
        return std::string(buf);
      },
      [](const DockRecord& r) { return r.incidence_bin; });
  out["by_face_reflectivity"] = table(
      kFaceBins, false, false,
      [](int b) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "face %.2f-%.2f", kFaceEdges[b], kFaceEdges[b + 1]);
        return std::string(buf);
      },
      [](const DockRecord& r) { return r.face_bin; });
  {  // Misses in the envelope by cause, intensity case, most frequent first.
    std::map<std::string, int> count;
    int n = 0;
    for (const auto& r : docks) {
      if (!in_env(r, false, false)) continue;
      ++n;
      if (r.code[0] != Code::kRight) ++count[r.miss[0]];
    }
    std::vector<std::pair<int, std::string>> v;
    for (const auto& [why, m] : count) v.emplace_back(m, why);
    std::stable_sort(v.begin(), v.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    json rows = json::array();
    for (const auto& [m, why] : v) rows.push_back(json{{"cause", why}, {"misses", m}});
    out["misses"] = {{"scenes", n}, {"causes", rows}};
  }
  {
    json overall, looks = json::array(), refl = json::array();
    for (int c = 0; c < kCases; ++c) {
      FpCell cell;
      for (const auto& r : frees)
        if (r.excluded.empty()) cell.add(r, c);
      overall[kCaseNames[c]] = cell.to_json();
    }
    for (int k = 0; k < static_cast<int>(docksim::LookAlike::kCount); ++k) {
      json row;
      row["look_alike"] = docksim::to_string(static_cast<docksim::LookAlike>(k));
      for (int c = 0; c < kCases; ++c) {
        FpCell cell;
        for (const auto& r : frees)
          if (r.excluded.empty() && r.look_alike == k) cell.add(r, c);
        row[kCaseNames[c]] = cell.to_json();
      }
      looks.push_back(row);
    }
    // By reflective clutter: scenes with none, and scenes holding at least one object of each kind.
    for (int k = -1; k < static_cast<int>(docksim::ReflectiveClass::kCount); ++k) {
      json row;
      row["reflective"] = k < 0 ? "none" : docksim::to_string(static_cast<docksim::ReflectiveClass>(k));
      for (int c = 0; c < kCases; ++c) {
        FpCell cell;
        for (const auto& r : frees) {
          if (!r.excluded.empty()) continue;
          if (k < 0 ? r.reflective == 0 : (r.reflective >> static_cast<unsigned>(k)) & 1u) cell.add(r, c);
        }
        row[kCaseNames[c]] = cell.to_json();
      }
      refl.push_back(row);
    }
    out["false_positives"] = overall;
    std::map<std::string, int> on;
    for (const auto& r : frees)
      if (r.excluded.empty())
        for (const std::string& k : r.elsewhere) ++on[k];
    out["detections_elsewhere_by_object"] = on;
    out["look_alikes"] = looks;
    out["reflective_clutter"] = refl;
  }
  {  // Confident wrong id: the same shape with another code, or untaped, accepted where it stands.
    json cw;
    for (int c = 0; c < kCases; ++c) {
      FpCell cell;
      // Intensity case: the dock-less scenes with a scan accepted at the look-alike, to re-generate them (geometry
      // alone takes most; for it the list stays empty).
      json scenes = json::array();
      json confirmed = json::array();  // of which confirmed over three scans at the look-alike
      for (const auto& r : frees) {
        if (!r.excluded.empty()) continue;
        const auto la = static_cast<docksim::LookAlike>(r.look_alike);
        if (la != docksim::LookAlike::kOtherCode && la != docksim::LookAlike::kUntaped) continue;
        cell.add(r, c);
        if (c == 0 && r.at_look[c] > 0) scenes.push_back(r.index);
        if (c == 0 && r.confirmed_at_look[c]) confirmed.push_back(r.index);
      }
      const json j = cell.to_json();
      cw[kCaseNames[c]] = {{"per_scan", j["at_look_alike_per_scan"]},
                           {"per_confirmation", j["at_look_alike_per_confirmation"]},
                           {"scene_indices", scenes},
                           {"confirmed_scene_indices", confirmed}};
    }
    out["confident_wrong_id"] = cw;
  }
  if (o.read_range) out["read_range"] = run_read_range(o);

  json t = json::array();
  auto add = [&](const char* what, const char* bound, json measured, json met) {
    t.push_back(json{{"target", what}, {"bound", bound}, {"measured", std::move(measured)}, {"met", std::move(met)}});
  };
  const json& det = out["detection"]["intensity"]["all"];
  add("detection, d ≤ 2.0 m, |bearing| ≤ 45°, |dock yaw| ≤ 30°, intensity usable", "≥ 99.5 %", det,
      det["rate"].is_null() ? json(nullptr) : json(det["rate"].get<double>() >= kDetectionTarget));
  const json& cwc = out["confident_wrong_id"]["intensity"]["per_scan"];
  add("confident wrong id: other-code or untaped look-alike accepted, per scan", "never", cwc,
      json(cwc["hits"].get<int>() == 0));
  const json& fpc = out["false_positives"]["intensity"]["fp_per_confirmation"];
  add("false confirmations per 3-scan confirmation on dock-less scenes", "≤ 0.01 %", fpc,
      fpc["rate"].is_null() ? json(nullptr) : json(fpc["rate"].get<double>() <= kFpConfirmTarget));
  out["targets"] = t;
  return out;
}

// ---------------------------------------------------------------- printing

namespace {

std::string hits_of(const json& r, const char* f = "%.2f %%") {
  return std::to_string(r["hits"].get<int>()) + " / " + std::to_string(r["n"].get<int>()) + " = " + pct(r["rate"], f);
}
std::string upper_of(const json& r) {
  return pct(r["upper95"], "%.3f %%");
}

}  // namespace

void print_reflectors(const json& j) {
  const json& cfg = j["config"];
  std::printf(
      "\n== Reflector docks (seed %llu): %d docking scenes, %d dock-less scenes x %d scans, %d random profiles, LD06\n",
      static_cast<unsigned long long>(cfg["seed"].get<std::uint64_t>()), cfg["docking_scenes"].get<int>(),
      cfg["dockless_scenes"].get<int>(), cfg["dockless_scans_per_scene"].get<int>(), cfg["random_profiles"].get<int>());
  if (cfg.value("stripe_hypotheses", false)) std::printf("[estimator] stripe_hypotheses = true\n");
  std::printf(
      "intensity = stripes read (set_intensity_usable(true)); geometry = the same scans, intensity not usable. The\n"
      "profile's mounting is told. det = found within 0.10 m / 10° of the truth (sensor frame) in the envelope\n"
      "d ≤ 2.0 m, |bearing| ≤ 45°, |dock yaw| ≤ 30° (in the range and bearing tables the bin replaces its own\n"
      "condition). read = right id among the dock's poses that reached the code decision (right, code_unread,\n"
      "wrong_code). ub95 = one-sided 95 %% Clopper-Pearson upper bound.\n");
  for (const char* what : {"docking", "dockless"}) {
    std::string line = std::string("excluded, ") + what + ":";
    if (j["excluded"][what].empty()) line += " none";
    for (const auto& [why, n] : j["excluded"][what].items())
      line += " " + why + " " + std::to_string(n.get<int>()) + ";";
    std::printf("%s\n", line.c_str());
  }
  std::printf("\n-- detection in the envelope\n");
  for (int c = 0; c < kCases; ++c) {
    const json& d = j["detection"][kCaseNames[c]];
    std::printf("%-9s all σ %s, σ ≤ 10 mm %s\n", kCaseNames[c], rate_n(d["all"], "%.2f %%").c_str(),
                rate_n(d["sigma_le_10mm"], "%.2f %%").c_str());
  }
  const std::vector<Column> rc = {
      {"bin", 12, false},    {"det intensity (n)", 18, true}, {"det geometry (n)", 18, true}, {"right id", 8, true},
      {"unread", 6, true},   {"wrong code", 10, true},        {"other miss", 10, true},       {"elsewhere", 9, true},
      {"read (n)", 16, true}};
  auto code_row = [&](const json& row) {
    const json& c = row["code"];
    print_row(rc,
              {row["bin"].get<std::string>(), rate_n(row["intensity"], "%.2f %%"), rate_n(row["geometry"], "%.2f %%"),
               std::to_string(c["right_id"].get<int>()), std::to_string(c["code_unread_at_dock"].get<int>()),
               std::to_string(c["wrong_code_at_dock"].get<int>()), std::to_string(c["other_miss"].get<int>()),
               std::to_string(c["found_elsewhere"].get<int>()), rate_n(c["read"], "%.2f %%")});
  };
  std::printf("\n-- by range (|bearing| ≤ 45°, |dock yaw| ≤ 30°); code outcomes of the intensity case, scenes\n");
  print_header(rc);
  for (const auto& row : j["by_range"]) code_row(row);
  std::printf("\n-- by bearing (d ≤ 2.0 m, |dock yaw| ≤ 30°)\n");
  print_header(rc);
  for (const auto& row : j["by_bearing"]) code_row(row);

  std::printf("\n-- by incidence on the taped segment (in the envelope; the simulated tape is bright to 60°)\n");
  print_header(rc);
  for (const auto& row : j["by_incidence"]) code_row(row);
  std::printf(
      "\n-- by the dock face's reflectivity (in the envelope; reflector_min_intensity 235 of 255 = 0.92 head on)\n");
  print_header(rc);
  for (const auto& row : j["by_face_reflectivity"]) code_row(row);

  std::printf("\n-- misses in the envelope by cause, intensity case (%d scenes)\n", j["misses"]["scenes"].get<int>());
  const int nm = j["misses"]["scenes"].get<int>();
  for (const auto& row : j["misses"]["causes"])
    std::printf("  %6.2f %%  %5d  %s\n", nm ? 100.0 * row["misses"].get<int>() / nm : 0.0, row["misses"].get<int>(),
                row["cause"].get<std::string>().c_str());

  std::printf(
      "\n-- confident wrong id: other-code or untaped look-alike accepted where it stands (dock-less scenes)\n");
  for (int c = 0; c < kCases; ++c) {
    const json& x = j["confident_wrong_id"][kCaseNames[c]];
    std::printf("%-9s per scan %s (ub95 %s), per confirmation %s (ub95 %s)\n", kCaseNames[c],
                hits_of(x["per_scan"]).c_str(), upper_of(x["per_scan"]).c_str(), hits_of(x["per_confirmation"]).c_str(),
                upper_of(x["per_confirmation"]).c_str());
    auto print_indices = [&x](const char* key, const char* what) {
      if (x[key].empty()) return;
      std::string idx;
      for (const json& i : x[key]) idx += (idx.empty() ? "" : " ") + std::to_string(i.get<std::uint64_t>());
      std::printf("%-9s %s: %s\n", "", what, idx.c_str());
    };
    print_indices("scene_indices", "dock-less scenes (index)");
    print_indices("confirmed_scene_indices", "of which confirmed");
  }

  const std::vector<Column> fc = {{"", 12, false},
                                  {"case", 9, false},
                                  {"FP/scan (n)", 17, true},
                                  {"ub95", 8, true},
                                  {"FP/confirm (n)", 17, true},
                                  {"ub95", 8, true},
                                  {"at look/scan", 12, true},
                                  {"at look/confirm", 15, true}};
  auto fp_rows = [&](const std::string& name, const json& row) {
    for (int c = 0; c < kCases; ++c) {
      const json& x = row[kCaseNames[c]];
      print_row(fc, {c == 0 ? name : "", kCaseNames[c], rate_n(x["fp_per_scan"], "%.3f %%"), upper_of(x["fp_per_scan"]),
                     rate_n(x["fp_per_confirmation"], "%.3f %%"), upper_of(x["fp_per_confirmation"]),
                     std::to_string(x["at_look_alike_per_scan"]["hits"].get<int>()),
                     std::to_string(x["at_look_alike_per_confirmation"]["hits"].get<int>())});
    }
  };
  std::printf("\n-- false positives on dock-less scenes (at look = detections where the look-alike stands)\n");
  print_header(fc);
  fp_rows("all", j["false_positives"]);
  {
    std::string line = "intensity usable, single-scan detections away from the look-alike, by what they lay on:";
    if (j["detections_elsewhere_by_object"].empty()) line += " none";
    for (const auto& [what, n] : j["detections_elsewhere_by_object"].items())
      line += " " + what + " " + std::to_string(n.get<int>()) + ";";
    std::printf("%s\n", line.c_str());
  }
  std::printf("\n-- by look-alike\n");
  print_header(fc);
  for (const auto& row : j["look_alikes"]) fp_rows(row["look_alike"].get<std::string>(), row);
  std::printf("\n-- by reflective clutter (scenes holding at least one such object)\n");
  print_header(fc);
  for (const auto& row : j["reflective_clutter"]) fp_rows(row["reflective"].get<std::string>(), row);

  if (j.contains("read_range")) {
    std::printf(
        "\n-- readable range: read rate by range bin, |bearing| ≤ 30°, |dock yaw| ≤ 30°, the taped segment seen "
        "within\n"
        "   30° of its normal; code regions of the given width centred on the longest segment; farthest = the "
        "farthest\n"
        "   bin reading ≥ 99 %% (≥ %d read attempts)\n",
        kMinReadBinScenes);
    std::vector<Column> rr = {{"lidar", 10, false}, {"region", 7, true}};
    for (int b = 0; b < kRangeBins; ++b) rr.push_back({"", 15, true});
    rr.push_back({"farthest", 10, true});
    std::vector<std::string> head = {"lidar", "region"};
    for (int b = 0; b < kRangeBins; ++b) head.push_back(range_name(b));
    head.emplace_back("farthest");
    print_row(rr, head);
    for (const auto& row : j["read_range"]) {
      char w[16];
      std::snprintf(w, sizeof w, "%.1f cm", 100 * row["region_m"].get<double>());
      std::vector<std::string> cells = {row["lidar"].get<std::string>(), w};
      for (const auto& b : row["bins"]) cells.push_back(rate_n(b["read"], "%.1f %%"));
      cells.push_back(row["farthest_bin_read_ge_99"].is_null() ? "none"
                                                               : row["farthest_bin_read_ge_99"].get<std::string>());
      print_row(rr, cells);
    }
  }

  std::printf("\n== Targets, reflector docks\n");
  const std::vector<Column> tc = {
      {"target", 74, false}, {"bound", 9, false}, {"measured", 26, false}, {"met", 3, false}};
  print_header(tc);
  for (const auto& t : j["targets"]) {
    std::string m = hits_of(t["measured"], "%.3f %%");
    if (t["measured"].contains("upper95")) m += " (ub95 " + upper_of(t["measured"]) + ")";
    print_row(tc, {t["target"].get<std::string>(), t["bound"].get<std::string>(), m,
                   t["met"].is_null()     ? "n/a"
                   : t["met"].get<bool>() ? "yes"
                                          : "NO"});
  }
}

}  // namespace docksim_cli
