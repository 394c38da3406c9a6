// `dock-sim detect`: runs the dock detectors on recorded scans (JSON lines) and prints one JSON line per scan and
// detector. Also home of DetectorSet (detectors.hpp), which `scene` shares.
#include <algorithm>
#include <cmath>
#include <memory>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "commands.hpp"
#include "detectors.hpp"
#include "dockcore/laser_scan.hpp"
#include "docksim/profile_file.hpp"
#include "docksim/scan_io.hpp"

namespace docksim_cli {

using dockcore::Pose2;
using dockcore::Real;
using dockcore::Vec2;

const char* detector_name(Detector d) {
  switch (d) {
    case Detector::kEstimator: return "estimator";
    case Detector::kBreakpoint: return "breakpoint";
    case Detector::kVMarker: return "vmarker";
  }
  return "?";
}

std::vector<Detector> parse_detectors(const std::string& s) {
  if (s == "all") return {Detector::kEstimator, Detector::kBreakpoint, Detector::kVMarker};
  for (Detector d : {Detector::kEstimator, Detector::kBreakpoint, Detector::kVMarker}) {
    if (s == detector_name(d)) return {d};
  }
  throw std::invalid_argument("unknown detector '" + s + "' (all, estimator, breakpoint, vmarker)");
}

Pose2 parse_pose_csv(const std::string& s) {
  double v[3] = {0, 0, 0};
  std::size_t pos = 0;
  for (int i = 0; i < 3; ++i) {
    const std::size_t end = s.find(',', pos);
    if ((end == std::string::npos) != (i == 2)) break;
    const std::string part = s.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
    char* stop = nullptr;
    v[i] = std::strtod(part.c_str(), &stop);
    if (part.empty() || stop == part.c_str() || *stop != '\0' || !std::isfinite(v[i])) break;
    if (i == 2) return Pose2{static_cast<Real>(v[0]), static_cast<Real>(v[1]), dockcore::wrap_angle(static_cast<Real>(v[2]))};
    pos = end + 1;
  }
  throw std::invalid_argument("bad pose '" + s + "': expected x_m,y_m,yaw_rad (three finite numbers)");
}

double round6(double v) { return std::isfinite(v) ? std::round(v * 1e6) / 1e6 : v; }

DetectorSet::DetectorSet(const dockcore::DockProfile& profile, const dockcore::EstimatorParams& params,
                         const std::vector<Detector>& which)
    : profile_(profile),
      params_(params),
      which_(which),
      estimator_(std::make_unique<dockcore::DockPoseEstimator>()),
      breakpoint_(std::make_unique<dockcore::BreakpointDetector>()),
      points_(std::make_unique<dockcore::ScanPoints>()),
      segments_(std::make_unique<dockcore::LineSegments>()) {
  if (!estimator_->configure(profile_, params_)) {
    throw std::runtime_error(std::string("the estimator refuses profile '") + profile_.name + "'");
  }
  // The breakpoint detector looks for one dock's range-step pattern and ignores the profile: it applies to that dock.
  breakpoint_applicable_ = docksim::same_outline_as_builtin(profile_, "breakpoint");
  dockcore::VMarkerParams vp;
  vmarker_error_ = dockcore::vmarker_geometry_from_profile(profile_, vp.geometry);
  if (vmarker_error_ == dockcore::VMarkerError::kOk) vmarker_error_ = vmarker_.configure(vp);
}

DetectorSet::~DetectorSet() = default;

std::vector<DetectorResult> DetectorSet::run(const dockcore::ScanView& scan, const Pose2& mount) {
  std::vector<DetectorResult> out;
  for (Detector d : which_) {
    switch (d) {
      case Detector::kEstimator: out.push_back(run_estimator(scan, mount)); break;
      case Detector::kBreakpoint: out.push_back(run_breakpoint(scan, mount)); break;
      case Detector::kVMarker: out.push_back(run_vmarker(scan, mount)); break;
    }
  }
  return out;
}

DetectorResult DetectorSet::run_estimator(const dockcore::ScanView& scan, const Pose2& mount) {
  DetectorResult r;
  r.detector = Detector::kEstimator;
  const dockcore::DockEstimate e = estimator_->estimate(scan, mount);
  r.found = e.found;
  r.status = dockcore::to_string(e.status);
  r.pose = e.pose;
  auto& q = r.quality;
  q["status"] = r.status;
  q["rms_m"] = round6(e.rms_m);
  q["inliers"] = e.inliers;
  q["expected"] = e.expected;
  q["violations"] = e.violations;
  q["occluded"] = e.occluded;
  q["wall_seen"] = e.wall_seen;
  q["wall_looked"] = e.wall_looked;
  // The decision: each cue's log-likelihood ratio (nats) and their sum; for a miss, the best refused candidate's.
  q["evidence_nats"] = round6(e.evidence.total_nats);
  nlohmann::ordered_json cues = nlohmann::ordered_json::object();
  for (std::size_t c = 0; c < dockcore::kEvidenceCueCount; ++c) {
    cues[dockcore::to_string(static_cast<dockcore::EvidenceCue>(c))] = round6(e.evidence.cue_nats[c]);
  }
  q["cues"] = cues;
  const dockcore::DecisionFeatures& f = e.evidence.features;
  q["features"] = {{"hit", round6(f.hit)},         {"hit_sq", round6(f.hit_sq)},
                   {"dropped", round6(f.dropped)}, {"beyond", round6(f.beyond)},
                   {"front", round6(f.front)},     {"missing", round6(f.missing)},
                   {"continues", round6(f.continues)}, {"stops", round6(f.stops)},
                   {"wall_seen", round6(f.wall_seen)}, {"wall_missed", round6(f.wall_missed)},
                   {"constraint", round6(f.constraint)}};
  if (!e.found && e.reject != dockcore::RejectReason::kNone) q["reject"] = dockcore::to_string(e.reject);
  if (e.found) {
    q["sigma_x_m"] = round6(std::sqrt(std::max<double>(0, e.covariance(0, 0))));
    q["sigma_y_m"] = round6(std::sqrt(std::max<double>(0, e.covariance(1, 1))));
    q["sigma_yaw_rad"] = round6(std::sqrt(std::max<double>(0, e.covariance(2, 2))));
  } else {
    q["sigma_x_m"] = nullptr;
    q["sigma_y_m"] = nullptr;
    q["sigma_yaw_rad"] = nullptr;
  }
  q["candidates"] = e.candidates;
  q["verified"] = e.verified;
  return r;
}

DetectorResult DetectorSet::run_breakpoint(const dockcore::ScanView& scan, const Pose2& mount) {
  DetectorResult r;
  r.detector = Detector::kBreakpoint;
  r.has_yaw = false;
  if (!breakpoint_applicable_) {
    r.applicable = false;
    r.reason = "the breakpoint detector only finds the built-in \"breakpoint\" dock";
    r.status = "not applicable";
    return r;
  }
  // The seed's index thresholds were tuned for a 1° lidar (its header says to scale them): keep their angular size.
  dockcore::BreakpointParams bp;
  if (scan.angle_increment_rad > 0) {
    const double per_deg = static_cast<double>(dockcore::deg_to_rad(1)) / static_cast<double>(scan.angle_increment_rad);
    bp.neighbour_offset_idx = static_cast<std::uint16_t>(std::max(1.0, std::round(5.0 * per_deg)));
    bp.max_pair_spacing_idx = static_cast<std::uint16_t>(std::max(2.0, std::round(7.0 * per_deg)));
  }
  breakpoint_->set_params(bp);
  const dockcore::BreakpointDetection d = breakpoint_->detect(scan);
  r.status = dockcore::to_string(d.status);
  Vec2 p_lidar;
  r.found = d.found && d.dock_position_lidar(p_lidar);
  if (r.found) {
    const Vec2 p = mount.transform(p_lidar);
    r.pose = Pose2{p.x(), p.y(), 0};
  }
  auto& q = r.quality;
  q["status"] = r.status;
  q["centre_angle_rad"] = round6(d.centre_angle_rad);
  q["centre_range_m"] = round6(d.centre_range_m);
  q["left_angle_rad"] = round6(d.left_angle_rad);
  q["left_range_m"] = round6(d.left_range_m);
  q["right_angle_rad"] = round6(d.right_angle_rad);
  q["right_range_m"] = round6(d.right_range_m);
  q["mutations"] = d.mutation_count;
  return r;
}

DetectorResult DetectorSet::run_vmarker(const dockcore::ScanView& scan, const Pose2& mount) {
  DetectorResult r;
  r.detector = Detector::kVMarker;
  if (vmarker_error_ != dockcore::VMarkerError::kOk) {
    r.applicable = false;
    r.reason = dockcore::to_string(vmarker_error_);
    r.status = "not applicable";
    return r;
  }
  dockcore::scan_to_points(scan, mount, params_.min_range_m, params_.max_range_m, *points_);
  dockcore::extract_line_segments(*points_, scan, params_.segments, *segments_);
  const dockcore::VMarkerDetection d = vmarker_.detect(*segments_);
  r.found = d.found;
  r.status = dockcore::to_string(d.status);
  r.pose = d.dock_pose;
  auto& q = r.quality;
  q["status"] = r.status;
  q["score"] = round6(d.score);
  q["notch_angle_rad"] = round6(d.notch_angle_rad);
  q["arm_length_m"] = {round6(d.arm_length_m[0]), round6(d.arm_length_m[1])};
  q["candidates"] = d.candidates;
  return r;
}

nlohmann::ordered_json result_json(const DetectorResult& r, nlohmann::ordered_json j) {
  j["detector"] = detector_name(r.detector);
  if (!r.applicable) {
    j["applicable"] = false;
    j["reason"] = r.reason;
  }
  j["found"] = r.found;
  if (r.found) {
    j["x_m"] = round6(r.pose.x_m);
    j["y_m"] = round6(r.pose.y_m);
    if (r.has_yaw) {
      j["yaw_rad"] = round6(r.pose.yaw_rad);
    } else {
      j["yaw_rad"] = nullptr;
    }
  } else {
    j["x_m"] = nullptr;
    j["y_m"] = nullptr;
    j["yaw_rad"] = nullptr;
  }
  j["quality"] = r.applicable ? r.quality : nlohmann::ordered_json::object();
  return j;
}

namespace {

struct DetectOptions {
  std::string scans_path;
  std::string profile = "plate-v";
  std::string mount = "0,0,0";
  std::string detector = "all";
  double max_range_m = 3.0;
};

int run_detect(const DetectOptions& o) {
  dockcore::DockProfile profile;
  std::vector<Detector> which;
  Pose2 mount;
  try {
    profile = docksim::resolve_profile(o.profile);
    which = parse_detectors(o.detector);
    mount = parse_pose_csv(o.mount);
  } catch (const std::exception& e) {
    std::cerr << "dock-sim detect: " << e.what() << "\n";
    return 2;
  }
  if (o.scans_path.empty()) {
    std::cerr << "dock-sim detect: --scans FILE is required\n";
    return 2;
  }
  if (!(o.max_range_m > 0)) {
    std::cerr << "dock-sim detect: --max-range must be positive\n";
    return 2;
  }
  std::ifstream file;
  std::istream* in = &std::cin;
  if (o.scans_path != "-") {
    file.open(o.scans_path, std::ios::binary);
    if (!file) {
      std::cerr << "dock-sim detect: cannot open " << o.scans_path << "\n";
      return 2;
    }
    in = &file;
  }

  dockcore::EstimatorParams params;
  params.max_range_m = static_cast<Real>(o.max_range_m);
  std::unique_ptr<DetectorSet> set;
  try {
    set = std::make_unique<DetectorSet>(profile, params, which);
  } catch (const std::exception& e) {
    std::cerr << "dock-sim detect: " << e.what() << "\n";
    return 2;
  }

  docksim::ScanReader reader(*in);
  docksim::RecordedScan rec;
  auto scan = std::make_unique<dockcore::LaserScan>();
  std::string error;
  std::size_t scans = 0;
  std::size_t bad = 0;
  std::vector<std::size_t> found(which.size(), 0);
  std::vector<bool> applicable(which.size(), true);
  for (;;) {
    const docksim::ScanReader::Status st = reader.next(&rec, &error);
    if (st == docksim::ScanReader::Status::kEnd) break;
    if (st == docksim::ScanReader::Status::kError || !rec.to_laser_scan(scan.get())) {
      if (st != docksim::ScanReader::Status::kError) error = "line " + std::to_string(reader.line_number()) + ": too many ranges";
      std::cerr << (o.scans_path == "-" ? std::string("<stdin>") : o.scans_path) << ": " << error << " (skipped)\n";
      ++bad;
      continue;
    }
    const std::vector<DetectorResult> results = set->run(scan->view(), mount);
    for (std::size_t i = 0; i < results.size(); ++i) {
      nlohmann::ordered_json j;
      j["scan"] = scans;
      j["line"] = reader.line_number();
      j["stamp_us"] = rec.stamp_us;
      std::cout << result_json(results[i], std::move(j)).dump() << "\n";
      found[i] += results[i].found ? 1 : 0;
      applicable[i] = results[i].applicable;
    }
    ++scans;
  }
  if (in->bad()) {
    std::cerr << "dock-sim detect: read error on " << o.scans_path << "\n";
    return 2;
  }
  std::cout.flush();
  std::cerr << "dock-sim detect: " << scans << " scan(s), " << bad << " malformed line(s) skipped";
  for (std::size_t i = 0; i < which.size(); ++i) {
    std::cerr << "; " << detector_name(which[i]);
    if (applicable[i]) {
      std::cerr << " found " << found[i] << "/" << scans;
    } else {
      std::cerr << " n/a";
    }
  }
  std::cerr << "\n";
  return 0;
}

}  // namespace

void register_detect(CLI::App& app) {
  auto opt = std::make_shared<DetectOptions>();
  CLI::App* sub = app.add_subcommand(
      "detect",
      "Run the dock detectors on recorded scans (JSON lines, see tools/sim/include/docksim/scan_io.hpp) and print one "
      "JSON line per scan and detector. Malformed lines are reported on stderr and skipped. Exit 0 when the file "
      "was read, 2 for bad arguments, an unreadable file or a bad profile.");
  sub->add_option("--scans", opt->scans_path, "JSON-lines scan file ('-' = stdin)");
  sub->add_option("--profile", opt->profile, "Dock profile: breakpoint, v-marker, plate-v or a .toml file")
      ->capture_default_str();
  sub->add_option("--mount", opt->mount,
                  "Lidar pose on the robot as x_m,y_m,yaw_rad; poses are then in the robot frame (default: the "
                  "scan's frame)")
      ->capture_default_str();
  sub->add_option("--detector", opt->detector, "all, estimator, breakpoint or vmarker")->capture_default_str();
  sub->add_option("--max-range", opt->max_range_m, "Returns beyond this (m) are ignored by the estimator and vmarker")
      ->capture_default_str();
  sub->callback([opt]() {
    const int rc = run_detect(*opt);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace docksim_cli
