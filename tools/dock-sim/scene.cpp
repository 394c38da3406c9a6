// `dock-sim scene`: builds one simulated docking scene, scans it, runs every detector, prints the ground truth and
// each detector's error and draws the scene as SVG. `dock-sim profile`: prints / draws a dock profile.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "angles.hpp"
#include "commands.hpp"
#include "detectors.hpp"
#include "docksim/cli_checks.hpp"
#include "docksim/lidar_sim.hpp"
#include "docksim/profile_file.hpp"
#include "docksim/rng.hpp"
#include "docksim/scan_io.hpp"
#include "docksim/scenes.hpp"
#include "docksim/svg.hpp"

namespace docksim_cli {
namespace {

using dockcore::Pose2;
using dockcore::Real;
using dockcore::Vec2;
using docksim::SvgStyle;

const char* const kTrueColour = "#2ca02c";
const char* const kScanColour = "#1f77b4";
const char* const kWorldColour = "#9a9a9a";

const char* detector_colour(Detector d) {
  switch (d) {
    case Detector::kEstimator: return "#d62728";
    case Detector::kBreakpoint: return "#9467bd";
    case Detector::kVMarker: return "#ff7f0e";
  }
  return "black";
}

std::string fmtd(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), f, v);
  return buf;
}

std::vector<Vec2> profile_points(const dockcore::DockProfile& p) {
  return std::vector<Vec2>(p.vertices_m, p.vertices_m + p.vertex_count);
}

/// Error of an estimate against the truth; position error also in the true dock frame.
struct PoseError {
  double x_m = 0, y_m = 0, yaw_rad = 0, longitudinal_m = 0, lateral_m = 0;
};

PoseError pose_error(const Pose2& est, const Pose2& truth) {
  PoseError e;
  e.x_m = static_cast<double>(est.x_m - truth.x_m);
  e.y_m = static_cast<double>(est.y_m - truth.y_m);
  e.yaw_rad = static_cast<double>(dockcore::wrap_angle(est.yaw_rad - truth.yaw_rad));
  const double c = std::cos(static_cast<double>(truth.yaw_rad));
  const double s = std::sin(static_cast<double>(truth.yaw_rad));
  e.longitudinal_m = c * e.x_m + s * e.y_m;  // along the dock's x (out of its face)
  e.lateral_m = -s * e.x_m + c * e.y_m;      // along the dock's y
  return e;
}

struct SceneOptions {
  std::string profile = "plate-v";
  std::string lidar = "ld06";
  double distance_m = 1.0;
  double bearing_deg = 20.0;
  double yaw_deg = 10.0;
  double sigma_m = -1;  // < 0: the lidar model's own
  int clutter = 1;
  int look_alikes = 0;
  std::uint64_t seed = 1;
  std::string svg;
  bool json = false;
  int scans = 1;
  std::string record;
  double view_m = 0;  // 0: fit lidar and dock
};

/// "a/b/sample.jsonl" -> "a/b/sample.truth.json".
std::string truth_path_for(const std::string& record) {
  std::string base = record;
  const std::size_t slash = base.find_last_of('/');
  const std::size_t dot = base.find_last_of('.');
  if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) base.resize(dot);
  return base + ".truth.json";
}

void draw_scene(const SceneOptions& o, const docksim::World& world, const dockcore::DockProfile& profile,
                const Pose2& truth, const dockcore::LaserScan& scan, const std::vector<DetectorResult>& results,
                const std::string& title, const std::vector<std::string>& error_rows, const std::string& path) {
  docksim::SvgBounds b;
  b.add(0, 0);
  if (o.view_m > 0) {
    b.add(-o.view_m, -o.view_m);
    b.add(o.view_m, o.view_m);
  } else {
    for (std::size_t i = 0; i < profile.vertex_count; ++i) b.add(truth.transform(profile.vertices_m[i]));
    b.pad(0.6);
  }
  const double span = std::max(b.x_max - b.x_min, b.y_max - b.y_min);
  const double px_per_m = std::min(600.0, 860.0 / span);
  docksim::SvgCanvas c(b, px_per_m, 20);
  c.title(title);
  c.grid(span > 4 ? 1.0 : 0.25);

  const SvgStyle world_style = SvgStyle::line(kWorldColour, 1.5);
  for (const docksim::Segment& s : world.segments) c.line(s.a, s.b, world_style);

  std::vector<Vec2> pts;
  for (std::size_t i = 0; i < scan.count; ++i) {
    const Real r = scan.ranges_m[i];
    if (!dockcore::is_valid_range(r)) continue;
    const Real a = scan.angle_min_rad + static_cast<Real>(i) * scan.angle_increment_rad;
    pts.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  c.dots(pts, 1.8, SvgStyle::filled(kScanColour));

  const SvgStyle true_style = SvgStyle::line(kTrueColour, 2.5, "6,4");
  const double arrow_m = 0.15;
  c.pose(Pose2{0, 0, 0}, arrow_m, SvgStyle::line("black", 1.5));
  c.text_px(Vec2(0, 0), 6, 16, "lidar", 12, "black");

  c.legend("world (walls, clutter)", world_style);
  c.legend("scan points", SvgStyle::filled(kScanColour), docksim::SvgLegendMark::kDot);
  c.legend("true dock", true_style);
  c.legend("lidar", SvgStyle::line("black", 1.5), docksim::SvgLegendMark::kArrow);
  for (const DetectorResult& r : results) {
    const std::string colour = detector_colour(r.detector);
    const std::string name = detector_name(r.detector);
    if (!r.applicable) continue;
    if (!r.found) {
      c.legend(name + ": not found (" + r.status + ")", SvgStyle::line(colour, 2.0), docksim::SvgLegendMark::kNone);
      continue;
    }
    if (r.has_yaw) {
      c.outline(profile_points(profile), r.pose, SvgStyle::line(colour, 2.0), false);
      c.pose(r.pose, arrow_m, SvgStyle::line(colour, 1.5));
      c.legend(name + " fit", SvgStyle::line(colour, 2.0), docksim::SvgLegendMark::kLine);
    } else {
      c.circle(Vec2(r.pose.x_m, r.pose.y_m), 0.012, SvgStyle::line(colour, 2.0));
      c.legend(name + " position (no yaw)", SvgStyle::line(colour, 2.0), docksim::SvgLegendMark::kDot);
    }
  }
  // The truth goes on top, dashed, so a fit lying exactly under it still shows between the dashes.
  c.outline(profile_points(profile), truth, true_style, false);
  c.pose(truth, arrow_m, SvgStyle::line(kTrueColour, 1.5, "4,3"));
  c.legend_text("");
  for (const std::string& row : error_rows) c.legend_text(row);
  c.scale_bar(span > 4 ? 1.0 : 0.2);
  std::string error;
  if (!c.write(path, &error)) throw std::runtime_error(error);
}

int run_scene(const SceneOptions& o) {
  dockcore::DockProfile profile;
  docksim::LidarModel model;
  try {
    profile = docksim::resolve_profile(o.profile);
  } catch (const std::exception& e) {
    std::cerr << "dock-sim scene: " << e.what() << "\n";
    return 2;
  }
  if (!docksim::lidar_model(o.lidar, &model)) {
    std::string names;
    for (const std::string& n : docksim::lidar_model_names()) names += (names.empty() ? "" : ", ") + n;
    std::cerr << "dock-sim scene: unknown lidar '" << o.lidar << "' (" << names << ")\n";
    return 2;
  }
  if (!(o.distance_m > 0) || !std::isfinite(o.bearing_deg) || !std::isfinite(o.yaw_deg) || o.clutter < 0 ||
      o.look_alikes < 0 || o.scans < 1 || !(o.view_m >= 0) || !std::isfinite(o.sigma_m)) {
    std::cerr << "dock-sim scene: --distance must be > 0, --clutter/--look-alikes >= 0, --scans >= 1, angles finite\n";
    return 2;
  }
  if (o.sigma_m >= 0) {
    model.sigma_const_m = o.sigma_m;
  }
  const double sigma_at_dock =
      std::sqrt(model.sigma_const_m * model.sigma_const_m + std::pow(model.sigma_prop * o.distance_m, 2.0));

  // The robot's lidar sits at the world origin facing +x, so lidar, robot and world frames coincide.
  const Pose2 lidar_pose{0, 0, 0};
  const Pose2 truth = docksim::dock_pose_from_lidar(o.distance_m, o.bearing_deg * kDeg, o.yaw_deg * kDeg);
  docksim::SceneSpec spec;
  spec.profile = profile;
  spec.dock_pose_in_world = truth;
  spec.lidar_pose_in_world = lidar_pose;
  spec.clutter_level = o.clutter;
  spec.look_alikes = o.look_alikes;
  docksim::Rng rng(o.seed);
  std::vector<docksim::SceneObject> objects;
  const docksim::World world = docksim::build_scene(spec, rng, &objects);

  // The estimator is told the lidar's noise, as a deployment would configure it for its sensor.
  dockcore::EstimatorParams params;
  params.range_sigma_m = static_cast<Real>(std::max(sigma_at_dock, 0.005));
  std::unique_ptr<DetectorSet> set;
  try {
    set = std::make_unique<DetectorSet>(profile, params, parse_detectors("all"));
  } catch (const std::exception& e) {
    std::cerr << "dock-sim scene: " << e.what() << "\n";
    return 2;
  }

  auto scan = std::make_unique<dockcore::LaserScan>();
  auto first_scan = std::make_unique<dockcore::LaserScan>();
  std::vector<DetectorResult> first;
  std::vector<docksim::RecordedScan> recorded;
  std::vector<int> found_count(3, 0);
  std::vector<double> worst_pos_m(3, 0.0), worst_yaw_rad(3, 0.0);
  const auto period_us = static_cast<std::uint64_t>(std::llround(1e6 / model.rate_hz));
  for (int k = 0; k < o.scans; ++k) {
    docksim::simulate_scan(world, lidar_pose, model, rng, scan.get(), static_cast<std::uint64_t>(k) * period_us);
    std::vector<DetectorResult> results = set->run(scan->view(), Pose2{0, 0, 0});
    for (std::size_t i = 0; i < results.size(); ++i) {
      if (!results[i].found) continue;
      ++found_count[i];
      const PoseError e = pose_error(results[i].pose, truth);
      worst_pos_m[i] = std::max(worst_pos_m[i], std::hypot(e.x_m, e.y_m));
      if (results[i].has_yaw) worst_yaw_rad[i] = std::max(worst_yaw_rad[i], std::fabs(e.yaw_rad));
    }
    if (k == 0) {
      first = results;
      *first_scan = *scan;
    }
    if (!o.record.empty()) recorded.push_back(docksim::RecordedScan::from_view(scan->view()));
  }

  if (!o.record.empty()) {
    std::string error;
    if (!docksim::write_scan_file(o.record, recorded, &error)) {
      std::cerr << "dock-sim scene: " << error << "\n";
      return 2;
    }
    nlohmann::ordered_json t;
    t["scans"] = o.record.substr(o.record.find_last_of('/') + 1);
    t["profile"] = profile.name;
    t["lidar"] = model.name;
    t["sigma_m"] = round6(model.sigma_const_m);
    t["distance_m"] = o.distance_m;
    t["bearing_deg"] = o.bearing_deg;
    t["yaw_deg"] = o.yaw_deg;
    t["clutter"] = o.clutter;
    t["look_alikes"] = o.look_alikes;
    t["seed"] = o.seed;
    t["count"] = o.scans;
    t["dock_pose_in_lidar"] = {{"x_m", round6(truth.x_m)}, {"y_m", round6(truth.y_m)}, {"yaw_rad", round6(truth.yaw_rad)}};
    std::ofstream tf(truth_path_for(o.record));
    tf << t.dump(2) << "\n";
    if (!tf) {
      std::cerr << "dock-sim scene: cannot write " << truth_path_for(o.record) << "\n";
      return 2;
    }
  }

  // Figures per detector for scan 0.
  std::vector<std::string> error_rows;
  error_rows.push_back(
      fmtd("truth  x %.3f m", truth.x_m) + fmtd("  y %.3f m", truth.y_m) + fmtd("  yaw %.1f°", truth.yaw_rad / kDeg));
  error_rows.push_back("errors      long mm  lat mm  yaw °");
  nlohmann::ordered_json jdet = nlohmann::ordered_json::array();
  for (const DetectorResult& r : first) {
    nlohmann::ordered_json j = result_json(r);
    if (r.found) {
      const PoseError e = pose_error(r.pose, truth);
      j["error"] = {{"x_m", round6(e.x_m)},
                    {"y_m", round6(e.y_m)},
                    {"yaw_rad", r.has_yaw ? nlohmann::ordered_json(round6(e.yaw_rad)) : nlohmann::ordered_json()},
                    {"longitudinal_m", round6(e.longitudinal_m)},
                    {"lateral_m", round6(e.lateral_m)}};
      char row[96];
      std::snprintf(row, sizeof(row), "%-10s %8.1f %7.1f %6s", detector_name(r.detector), e.longitudinal_m * 1e3,
                    e.lateral_m * 1e3, r.has_yaw ? fmtd("%.2f", e.yaw_rad / kDeg).c_str() : "-");
      error_rows.push_back(row);
    } else if (r.applicable) {
      error_rows.push_back(std::string(detector_name(r.detector)) + ": not found");
    }
    jdet.push_back(j);
  }

  const std::string title = std::string("dock-sim scene: ") + profile.name + ", " + model.name +
                            fmtd(", %.2f m", o.distance_m) + fmtd(", bearing %.0f°", o.bearing_deg) +
                            fmtd(", yaw %.0f°", o.yaw_deg) + fmtd(", σ %.0f mm", model.sigma_const_m * 1e3) +
                            ", clutter " + std::to_string(o.clutter) + ", seed " + std::to_string(o.seed);
  if (!o.svg.empty()) {
    try {
      draw_scene(o, world, profile, truth, *first_scan, first, title, error_rows, o.svg);
    } catch (const std::exception& e) {
      std::cerr << "dock-sim scene: " << e.what() << "\n";
      return 2;
    }
  }

  std::size_t valid = 0;
  for (std::size_t i = 0; i < first_scan->count; ++i) valid += dockcore::is_valid_range(first_scan->ranges_m[i]) ? 1 : 0;

  if (o.json) {
    nlohmann::ordered_json j;
    j["scene"] = {{"profile", profile.name},
                  {"lidar", model.name},
                  {"sigma_m", round6(model.sigma_const_m)},
                  {"distance_m", o.distance_m},
                  {"bearing_rad", round6(o.bearing_deg * kDeg)},
                  {"yaw_rad", round6(o.yaw_deg * kDeg)},
                  {"clutter", o.clutter},
                  {"look_alikes", o.look_alikes},
                  {"seed", o.seed},
                  {"objects", objects.size()},
                  {"beams", first_scan->count},
                  {"returns", valid}};
    j["truth"] = {{"x_m", round6(truth.x_m)}, {"y_m", round6(truth.y_m)}, {"yaw_rad", round6(truth.yaw_rad)}};
    j["detectors"] = jdet;
    if (o.scans > 1) {
      nlohmann::ordered_json s = nlohmann::ordered_json::array();
      for (std::size_t i = 0; i < first.size(); ++i) {
        s.push_back({{"detector", detector_name(first[i].detector)},
                     {"found", found_count[i]},
                     {"scans", o.scans},
                     {"max_position_error_m", round6(worst_pos_m[i])},
                     {"max_yaw_error_rad", round6(worst_yaw_rad[i])}});
      }
      j["summary"] = s;
    }
    if (!o.svg.empty()) j["svg"] = o.svg;
    std::cout << j.dump() << "\n";
  } else {
    std::printf("%s\n", title.c_str());
    std::printf("scene: %zu objects (dock and wall included), %zu beams, %zu returns; estimator range sigma %.1f mm\n",
                objects.size(), first_scan->count, valid, static_cast<double>(params.range_sigma_m) * 1e3);
    std::printf("truth (lidar frame): x %.4f m  y %.4f m  yaw %.2f°\n\n", static_cast<double>(truth.x_m),
                static_cast<double>(truth.y_m), static_cast<double>(truth.yaw_rad) / kDeg);
    std::printf("%-11s %-6s %9s %9s %9s %8s %8s %8s %9s %8s  %s\n", "detector", "found", "x_m", "y_m", "yaw_deg",
                "ex_mm", "ey_mm", "eyaw_deg", "elong_mm", "elat_mm", "status / quality");
    for (const DetectorResult& r : first) {
      const char* name = detector_name(r.detector);
      if (!r.applicable) {
        std::printf("%-11s %-6s (%s)\n", name, "n/a", r.reason.c_str());
        continue;
      }
      if (!r.found) {
        std::printf("%-11s %-6s %s\n", name, "no", r.status.c_str());
        continue;
      }
      const PoseError e = pose_error(r.pose, truth);
      std::string q;
      if (r.detector == Detector::kEstimator) {
        q = fmtd("rms %.1f mm", r.quality["rms_m"].get<double>() * 1e3) +
            ", inliers " + std::to_string(r.quality["inliers"].get<int>()) + "/" +
            std::to_string(r.quality["expected"].get<int>()) + fmtd(", σx %.1f mm", r.quality["sigma_x_m"].get<double>() * 1e3) +
            fmtd(" σy %.1f mm", r.quality["sigma_y_m"].get<double>() * 1e3) +
            fmtd(" σyaw %.2f°", r.quality["sigma_yaw_rad"].get<double>() / kDeg);
      } else if (r.detector == Detector::kVMarker) {
        q = fmtd("score %.3f", r.quality["score"].get<double>());
      } else {
        q = "mutations " + std::to_string(r.quality["mutations"].get<int>());
      }
      std::printf("%-11s %-6s %9.4f %9.4f %9s %8.1f %8.1f %8s %9.1f %8.1f  %s\n", name, "yes",
                  static_cast<double>(r.pose.x_m), static_cast<double>(r.pose.y_m),
                  r.has_yaw ? fmtd("%.2f", static_cast<double>(r.pose.yaw_rad) / kDeg).c_str() : "-", e.x_m * 1e3,
                  e.y_m * 1e3, r.has_yaw ? fmtd("%.2f", e.yaw_rad / kDeg).c_str() : "-", e.longitudinal_m * 1e3,
                  e.lateral_m * 1e3, q.c_str());
    }
    if (o.scans > 1) {
      std::printf("\nover %d scans:\n", o.scans);
      for (std::size_t i = 0; i < first.size(); ++i) {
        if (!first[i].applicable) continue;
        std::printf("%-11s found %d/%d, worst position error %.1f mm", detector_name(first[i].detector),
                    found_count[i], o.scans, worst_pos_m[i] * 1e3);
        if (first[i].has_yaw) std::printf(", worst yaw error %.2f°", worst_yaw_rad[i] / kDeg);
        std::printf("\n");
      }
    }
    if (!o.record.empty()) {
      std::printf("\nrecorded %d scan(s) to %s, truth in %s\n", o.scans, o.record.c_str(),
                  truth_path_for(o.record).c_str());
    }
    if (!o.svg.empty()) std::printf("\nSVG written to %s\n", o.svg.c_str());
  }
  // Exit 1 when the product detector missed the dock in the first scan, so scripts (tools/demo) can tell.
  return first.empty() || first[0].found ? 0 : 1;
}

// --- dock-sim profile ---

struct ProfileOptions {
  std::string name = "plate-v";
  std::string svg;
  std::string layout;
  bool toml = false;
};

/// Writes the tape layout of `p`'s reflector stripes at 1:1 (millimetres, for printing at 100 %): one bar per taped
/// segment, as long as the segment, seen from the front, its first vertex on the left (a segment's outward normal is
/// (dy, -dx), so its direction runs to the right of someone facing it). Tape is black; each edge is dimensioned
/// from the segment's first vertex.
void write_tape_layout(const dockcore::DockProfile& p, const std::string& path) {
  constexpr double kMarginMm = 15, kBarMm = 30, kBandMm = 75;
  double longest_mm = 0;
  std::vector<std::size_t> taped;
  for (std::size_t i = 0; i < p.segment_count(); ++i) {
    bool has = false;
    for (std::size_t q = 0; q < p.reflector_count; ++q) has = has || p.reflectors[q].segment == i;
    if (!has) continue;
    taped.push_back(i);
    longest_mm = std::max(longest_mm, static_cast<double>((p.vertices_m[i + 1] - p.vertices_m[i]).norm()) * 1e3);
  }
  const double w_mm = std::max(longest_mm + 2 * kMarginMm, 120.0);
  const double h_mm = 22 + kBandMm * static_cast<double>(taped.size());
  std::string svg;
  char buf[512];
  std::snprintf(
      buf, sizeof buf,
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.1fmm\" height=\"%.1fmm\" viewBox=\"0 0 %.1f %.1f\" "
      "font-family=\"sans-serif\">\n<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
      w_mm, h_mm, w_mm, h_mm);
  svg += buf;
  std::snprintf(buf, sizeof buf,
                "<text x=\"%.1f\" y=\"8\" font-size=\"4.5\">Tape layout of \"%s\" at 1:1: print at 100 %%</text>\n",
                kMarginMm, p.name);
  svg += buf;
  std::snprintf(buf, sizeof buf,
                "<text x=\"%.1f\" y=\"14\" font-size=\"3\">Seen from the front, each bar runs from its segment's "
                "first vertex (left) to the next. Black: tape; edges in mm from the first vertex.</text>\n",
                kMarginMm);
  svg += buf;
  double y = 22;
  for (const std::size_t i : taped) {
    const Vec2 a = p.vertices_m[i], b = p.vertices_m[i + 1];
    const double len_mm = static_cast<double>((b - a).norm()) * 1e3;
    std::snprintf(buf, sizeof buf,
                  "<text x=\"%.1f\" y=\"%.1f\" font-size=\"4\">segment %zu: vertex %zu (%.1f, %.1f) mm to vertex %zu "
                  "(%.1f, %.1f) mm, %.1f mm long</text>\n",
                  kMarginMm, y + 6, i, i, static_cast<double>(a.x()) * 1e3, static_cast<double>(a.y()) * 1e3, i + 1,
                  static_cast<double>(b.x()) * 1e3, static_cast<double>(b.y()) * 1e3, len_mm);
    svg += buf;
    const double bar_y = y + 16;
    std::snprintf(buf, sizeof buf,
                  "<rect x=\"%.2f\" y=\"%.2f\" width=\"%.2f\" height=\"%.1f\" fill=\"none\" stroke=\"#888\" "
                  "stroke-width=\"0.3\"/>\n",
                  kMarginMm, bar_y, len_mm, kBarMm);
    svg += buf;
    for (std::size_t q = 0; q < p.reflector_count; ++q) {
      const dockcore::ReflectorStripe& st = p.reflectors[q];
      if (st.segment != i) continue;
      const double from_mm = static_cast<double>(st.from_m) * 1e3, to_mm = static_cast<double>(st.to_m) * 1e3;
      std::snprintf(buf, sizeof buf, "<rect x=\"%.2f\" y=\"%.2f\" width=\"%.2f\" height=\"%.1f\" fill=\"black\"/>\n",
                    kMarginMm + from_mm, bar_y, to_mm - from_mm, kBarMm);
      svg += buf;
      for (const double e : {from_mm, to_mm}) {
        std::snprintf(buf, sizeof buf,
                      "<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" y2=\"%.2f\" stroke=\"#d62728\" stroke-width=\"0.3\"/>"
                      "<text x=\"%.2f\" y=\"%.2f\" font-size=\"3.2\" text-anchor=\"middle\">%.1f</text>\n",
                      kMarginMm + e, bar_y - 3, kMarginMm + e, bar_y + kBarMm + 3, kMarginMm + e, bar_y + kBarMm + 7,
                      e);
        svg += buf;
      }
    }
    std::snprintf(buf, sizeof buf,
                  "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\" stroke-width=\"0.5\"/>"
                  "<text x=\"%.1f\" y=\"%.1f\" font-size=\"3\">100 mm</text>\n",
                  kMarginMm, bar_y + kBarMm + 12, kMarginMm + 100, bar_y + kBarMm + 12, kMarginMm + 102,
                  bar_y + kBarMm + 13);
    svg += buf;
    y += kBandMm;
  }
  svg += "</svg>\n";
  std::ofstream f(path);
  f << svg;
  if (!f) throw std::runtime_error("cannot write " + path);
}

void draw_profile(const dockcore::DockProfile& p, const std::string& path) {
  docksim::SvgBounds b;
  b.add(0, 0);
  for (std::size_t i = 0; i < p.vertex_count; ++i) b.add(p.vertices_m[i]);
  b.add(0.08, 0);  // room for the x axis arrow
  b.pad(0.06);
  docksim::SvgCanvas c(b, 1500, 20);
  double x_min = 0;
  for (std::size_t i = 0; i < p.vertex_count; ++i) x_min = std::min(x_min, static_cast<double>(p.vertices_m[i].x()));
  c.title(std::string("dock profile \"") + p.name + "\"" + fmtd(": width %.0f mm", p.width_m() * 1e3) +
          fmtd(", depth %.0f mm", -x_min * 1e3) + ", " + std::to_string(p.vertex_count) + " vertices");
  c.grid(0.05);
  c.polyline(profile_points(p), SvgStyle::line("#333333", 3.0));
  for (std::size_t q = 0; q < p.reflector_count; ++q) {
    const dockcore::ReflectorStripe& st = p.reflectors[q];
    const Vec2 from = p.vertices_m[st.segment];
    const Vec2 d = (p.vertices_m[st.segment + 1] - from).normalized();
    c.line(from + d * st.from_m, from + d * st.to_m, SvgStyle::line("#ff7f0e", 7.0));
  }
  for (std::size_t i = 0; i < p.segment_count(); ++i) {
    const Vec2 mid = (p.vertices_m[i] + p.vertices_m[i + 1]) * static_cast<Real>(0.5);
    c.arrow(mid, mid + p.normal(i) * static_cast<Real>(0.025), SvgStyle::line("#1f77b4", 1.2), 6);
  }
  std::vector<Vec2> vs = profile_points(p);
  c.dots(vs, 3.5, SvgStyle::filled("#333333"));
  for (std::size_t i = 0; i < p.vertex_count; ++i) {
    const Vec2 v = p.vertices_m[i];
    // Labels sit off the vertex along the mean outward normal of its segments, away from the outline.
    Vec2 n = Vec2::Zero();
    if (i > 0) n += p.normal(i - 1);
    if (i + 1 < p.vertex_count) n += p.normal(i);
    if (n.norm() > static_cast<Real>(1e-9)) n.normalize();
    const double dx = 12 * static_cast<double>(n.x());
    const double dy = -12 * static_cast<double>(n.y()) + 4;  // screen y is down; +4 centres the baseline
    c.text_px(v, dx, dy,
              std::to_string(i) + " (" + fmtd("%.0f", static_cast<double>(v.x()) * 1e3) + ", " +
                  fmtd("%.0f", static_cast<double>(v.y()) * 1e3) + ")",
              11, "#333333", n.x() < static_cast<Real>(-0.3) ? docksim::SvgAnchor::kEnd : docksim::SvgAnchor::kStart);
  }
  c.arrow(Vec2(0, 0), Vec2(static_cast<Real>(0.06), 0), SvgStyle::line("#d62728", 2.0), 9);
  c.arrow(Vec2(0, 0), Vec2(0, static_cast<Real>(0.06)), SvgStyle::line("#2ca02c", 2.0), 9);
  c.text_px(Vec2(static_cast<Real>(0.06), 0), 4, 14, "x", 13, "#d62728");
  c.text_px(Vec2(0, static_cast<Real>(0.06)), 6, 0, "y", 13, "#2ca02c");
  c.circle(Vec2(0, 0), 0.006, SvgStyle::filled("#d62728"));
  c.scale_bar(0.1);
  c.legend("dock outline (lidar-visible surface)", SvgStyle::line("#333333", 3.0));
  if (p.reflector_count > 0) c.legend("reflector tape", SvgStyle::line("#ff7f0e", 7.0));
  c.legend("outward normal (dy, -dx)", SvgStyle::line("#1f77b4", 1.2), docksim::SvgLegendMark::kArrow);
  c.legend("dock frame x (out of the face)", SvgStyle::line("#d62728", 2.0), docksim::SvgLegendMark::kArrow);
  c.legend("dock frame y", SvgStyle::line("#2ca02c", 2.0), docksim::SvgLegendMark::kArrow);
  c.legend("origin: charging contacts' centre", SvgStyle::filled("#d62728"), docksim::SvgLegendMark::kDot);
  c.legend_text("labels: index (x, y) in mm");
  std::string error;
  if (!c.write(path, &error)) throw std::runtime_error(error);
}

int run_profile(const ProfileOptions& o) {
  dockcore::DockProfile p;
  try {
    p = docksim::resolve_profile(o.name);
  } catch (const std::exception& e) {
    std::cerr << "dock-sim profile: " << e.what() << "\n";
    return 2;
  }
  if (o.toml) {
    std::cout << docksim::profile_to_toml(p);
  } else {
    double x_min = 0;
    for (std::size_t i = 0; i < p.vertex_count; ++i) x_min = std::min(x_min, static_cast<double>(p.vertices_m[i].x()));
    std::printf("profile %s: %zu vertices, width %.1f mm, depth %.1f mm, outline length %.1f mm\n", p.name,
                p.vertex_count, static_cast<double>(p.width_m()) * 1e3, -x_min * 1e3,
                static_cast<double>(p.length_m()) * 1e3);
    std::printf("%5s %9s %9s   %s\n", "i", "x_mm", "y_mm", "segment i->i+1: length_mm, outward normal");
    for (std::size_t i = 0; i < p.vertex_count; ++i) {
      std::printf("%5zu %9.1f %9.1f", i, static_cast<double>(p.vertices_m[i].x()) * 1e3,
                  static_cast<double>(p.vertices_m[i].y()) * 1e3);
      if (i + 1 < p.vertex_count) {
        const Vec2 n = p.normal(i);
        std::printf("   %.1f, (%.3f, %.3f)", static_cast<double>((p.vertices_m[i + 1] - p.vertices_m[i]).norm()) * 1e3,
                    static_cast<double>(n.x()) + 0.0, static_cast<double>(n.y()) + 0.0);  // no "-0.000"
      }
      std::printf("\n");
    }
    for (std::size_t q = 0; q < p.reflector_count; ++q) {
      const dockcore::ReflectorStripe& st = p.reflectors[q];
      std::printf("reflector %zu: segment %u, %.1f-%.1f mm from vertex %u\n", q, static_cast<unsigned>(st.segment),
                  static_cast<double>(st.from_m) * 1e3, static_cast<double>(st.to_m) * 1e3,
                  static_cast<unsigned>(st.segment));
    }
  }
  if (!o.layout.empty()) {
    if (p.reflector_count == 0) {
      std::cerr << "dock-sim profile: --layout: profile " << p.name << " has no reflector stripes\n";
      return 2;
    }
    try {
      write_tape_layout(p, o.layout);
    } catch (const std::exception& e) {
      std::cerr << "dock-sim profile: " << e.what() << "\n";
      return 2;
    }
    if (!o.toml) std::printf("tape layout (1:1) written to %s\n", o.layout.c_str());
  }
  if (!o.svg.empty()) {
    try {
      draw_profile(p, o.svg);
    } catch (const std::exception& e) {
      std::cerr << "dock-sim profile: " << e.what() << "\n";
      return 2;
    }
    if (!o.toml) std::printf("SVG written to %s\n", o.svg.c_str());
  }
  return 0;
}

}  // namespace

void register_scene(CLI::App& app) {
  auto o = std::make_shared<SceneOptions>();
  CLI::App* sub = app.add_subcommand(
      "scene",
      "Simulate one docking scene (dock against a wall plus clutter), scan it, run every detector and report each "
      "one's pose error against the truth; optionally draw it as SVG. Exit 0 when the estimator found the dock, 1 "
      "when it did not, 2 for bad arguments.");
  sub->add_option("--profile", o->profile, "Dock profile: breakpoint, v-marker, plate-v or a .toml file")
      ->capture_default_str();
  sub->add_option("--lidar", o->lidar, "Lidar model: ld06, rplidar-a1, industrial")->capture_default_str();
  sub->add_option("--distance", o->distance_m, "Distance lidar -> dock origin (m)")->capture_default_str();
  sub->add_option("--bearing", o->bearing_deg, "Bearing of the dock in the lidar frame (deg, CCW)")
      ->capture_default_str();
  sub->add_option("--yaw", o->yaw_deg, "Dock rotation from facing the lidar head-on (deg, CCW)")
      ->capture_default_str();
  sub->add_option("--sigma", o->sigma_m, "Range noise 1-sigma (m); default: the lidar model's (LD06: 0.010)");
  sub->add_option("--clutter", o->clutter, "Clutter level 0-3 (3, 6, 12 objects)")
      ->capture_default_str()
      ->check(CLI::Range(0, 3));
  sub->add_option("--look-alikes", o->look_alikes, "Dock look-alikes added to the clutter")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--seed", o->seed, "Random seed (scene and noise)")
      ->capture_default_str()
      ->check(docksim::non_negative_integer());
  sub->add_option("--svg", o->svg, "Write the scene as SVG to this file");
  sub->add_option("--view", o->view_m, "SVG: show +-this many metres around the lidar (default: fit lidar and dock)");
  sub->add_flag("--json", o->json, "Print one JSON object instead of the table");
  sub->add_option("--scans", o->scans, "Scans to simulate (noise differs); table and SVG show the first")
      ->capture_default_str();
  sub->add_option("--record", o->record,
                  "Write the scans as JSON lines to this file and the truth to <file without extension>.truth.json");
  sub->callback([o]() {
    const int rc = run_scene(*o);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });

  auto p = std::make_shared<ProfileOptions>();
  CLI::App* prof = app.add_subcommand("profile", "Print a dock profile's vertices and dimensions; draw it as SVG.");
  prof->add_option("--name", p->name, "breakpoint, v-marker, plate-v or a .toml file")->capture_default_str();
  prof->add_option("--svg", p->svg, "Write a dimensioned drawing to this file");
  prof->add_flag("--toml", p->toml, "Print the profile in the TOML profile format instead of the table");
  prof->add_option("--layout", p->layout,
                   "Write the reflector stripes' tape layout at 1:1 (SVG in millimetres: print at 100 %) to this file");
  prof->callback([p]() {
    const int rc = run_profile(*p);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace docksim_cli
