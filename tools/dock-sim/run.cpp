// `dock-sim run`: one closed-loop docking of a scenario (timeline, outcome, SVG).
// `dock-sim montecarlo`: many seeded starts for one or all controllers, the same starts for each; comparison table.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "dockcore/task/faults.hpp"
#include "docksim/cli_checks.hpp"
#include "docksim/scenario.hpp"
#include "docksim/sim_run.hpp"
#include "docksim/svg.hpp"
#include "frame_camera.hpp"
#include "mc_stats.hpp"

namespace docksim_cli {
namespace {

using dockcore::Pose2;
using dockcore::Real;
using dockcore::Vec2;
using docksim::SvgStyle;

std::vector<Vec2> profile_world(const docksim::Scenario& sc) {
  std::vector<Vec2> pts;
  for (std::size_t i = 0; i < sc.profile.vertex_count; ++i)
    pts.push_back(sc.dock_pose.transform(sc.profile.vertices_m[i]));
  return pts;
}

/// Canvas fitted to the dock, the given poses and a margin; world segments near them are drawn.
docksim::SvgCanvas make_canvas(const docksim::Scenario& sc, const std::vector<Pose2>& poses, const std::string& title) {
  docksim::SvgBounds b;
  for (const Vec2& p : profile_world(sc)) b.add(p);
  for (const Pose2& p : poses) b.add(p.x_m, p.y_m);
  // Objects beside the dock (furniture) are part of its picture.
  const Vec2 dock_at(sc.dock_pose.x_m, sc.dock_pose.y_m);
  for (const auto& x : sc.boxes) {
    if ((x.centre - dock_at).norm() < 1.5) b.add(x.centre);
  }
  for (const auto& x : sc.circles) {
    if ((x.centre - dock_at).norm() < 1.5) b.add(x.centre);
  }
  b.pad(0.5);
  const double span = std::max(b.x_max - b.x_min, b.y_max - b.y_min);
  docksim::SvgCanvas c(b, std::min(400.0, 800.0 / span), 20);
  c.title(title);
  c.grid(span > 4 ? 1.0 : 0.25);
  const docksim::World world = docksim::scenario_world(sc, false);
  const SvgStyle ws = SvgStyle::line("#9a9a9a", 1.5);
  for (const auto& s : world.segments) c.line(s.a, s.b, ws);
  Vec2 glass_a, glass_b;
  const bool glass = sc.wall_glass && docksim::dock_wall(sc, &glass_a, &glass_b);
  const SvgStyle gs = SvgStyle::line("#7fc7e8", 2, "6,3");
  if (glass) c.line(glass_a, glass_b, gs);
  c.polyline(profile_world(sc), SvgStyle::line("#2ca02c", 3));
  c.legend("world", ws);
  if (glass) c.legend("glass wall (the lidar sees through)", gs);
  c.legend_text(std::string("detector told: ") + dockcore::to_string(sc.profile.mounting.kind) +
                (sc.profile.mounting.kind == dockcore::DockMountKind::kWall
                     ? fmt(" %.0f-", static_cast<double>(sc.profile.mounting.wall_gap_min_m) * 1e3) +
                           fmt("%.0f mm", static_cast<double>(sc.profile.mounting.wall_gap_max_m) * 1e3)
                     : std::string()));
  c.legend("dock", SvgStyle::line("#2ca02c", 3));
  return c;
}

bool write_svg(const docksim::SvgCanvas& c, const std::string& path, const char* who) {
  std::string error;
  if (!c.write(path, &error)) {
    std::cerr << "dock-sim " << who << ": " << error << "\n";
    return false;
  }
  return true;
}

// ---------------------------------------------------------------------------------------------------------------------
constexpr const char* kCameraRenderHelp =
    "Render the scenario's camera frames (the dock's AprilTag, [dock.tag]) and run them through the tag detector, "
    "fusing the tag poses with the lidar: robot.camera.render = true";

struct RunOptions {
  std::string scenario;
  std::string controller;  // empty: the scenario's
  std::uint64_t seed = 0;
  bool seed_set = false;  // false: the scenario's
  std::string svg;
  bool json = false;
  bool trace = false;
  std::vector<double> start;   // distance m, bearing deg, heading deg; empty: drawn from the seed
  bool camera_render = false;  // --camera-render
};

void draw_run(const docksim::Scenario& sc, const docksim::SimRun& r, const std::string& path) {
  std::vector<Pose2> poses;
  for (const auto& s : r.trajectory) poses.push_back(s.pose);
  poses.push_back(r.start.robot_world);
  const docksim::SimOutcome& o = r.outcome;
  docksim::SvgCanvas c = make_canvas(sc, poses,
                                     sc.name + " / " + r.controller + " / seed " + std::to_string(r.seed) +
                                         (o.charging_confirmed ? " / charging" : " / NOT charging"));
  c.dots(r.last_scan_world, 1.5, SvgStyle::filled("#1f77b4"));
  const std::vector<Vec2> outline = docksim::footprint_outline(sc.chassis);
  const SvgStyle ghost = SvgStyle::line("#ff7f0e", 0.7);
  double next_t = 0;
  for (const auto& s : r.trajectory) {
    if (s.t_s >= next_t) {
      c.outline(outline, s.pose, ghost);
      next_t = s.t_s + 2.0;
    }
  }
  std::vector<Vec2> path_pts;
  for (const auto& s : r.trajectory) path_pts.emplace_back(s.pose.x_m, s.pose.y_m);
  c.polyline(path_pts, SvgStyle::line("#d62728", 2));
  c.outline(outline, r.start.robot_world, SvgStyle::line("black", 1.5, "5,3"));
  c.pose(r.start.robot_world, 0.15, SvgStyle::line("black", 1.5));
  c.outline(outline, r.final_pose, SvgStyle::line("black", 2));
  c.legend("last scan", SvgStyle::filled("#1f77b4"), docksim::SvgLegendMark::kDot);
  c.legend("robot centre path", SvgStyle::line("#d62728", 2));
  c.legend("robot every 2 s", ghost);
  c.legend("start (dashed) / end", SvgStyle::line("black", 1.5));
  if (o.charging_confirmed) c.legend_text("charging after " + fmt("%.2f s", o.time_to_charging_s));
  c.legend_text("lateral " + fmt("%+.1f mm", o.lateral_m * 1e3));
  c.legend_text("yaw " + fmt("%+.2f deg", o.yaw_rad * kRadToDeg));
  write_svg(c, path, "run");
}

nlohmann::ordered_json outcome_json(const docksim::SimRun& r) {
  const docksim::SimOutcome& o = r.outcome;
  nlohmann::ordered_json j;
  j["controller"] = r.controller;
  j["seed"] = r.seed;
  j["start"] = {{"distance_m", r6(r.start.distance_m)},
                {"bearing_deg", r6(r.start.bearing_rad * kRadToDeg)},
                {"heading_deg", r6(r.start.heading_rad * kRadToDeg)}};
  j["charging_confirmed"] = o.charging_confirmed;
  j["time_to_charging_s"] =
      o.charging_confirmed ? nlohmann::ordered_json(r6(o.time_to_charging_s)) : nlohmann::ordered_json();
  j["lateral_m"] = r6(o.lateral_m);
  j["longitudinal_m"] = r6(o.longitudinal_m);
  j["yaw_deg"] = r6(o.yaw_rad * kRadToDeg);
  j["path_length_m"] = r6(o.path_length_m);
  j["reversals"] = o.reversals;
  j["inplace_turns_45"] = o.inplace_turns_45;
  j["retries"] = o.retries;
  j["mount_calibration"] = {{"swings", o.calibrations},
                            {"last_status", dockcore::to_string(o.last_calibration.status)},
                            {"last_lateral_error_m", r6(static_cast<double>(o.last_calibration.lateral_error_m))},
                            {"mount_in_use",
                             {{"x_m", r6(static_cast<double>(o.lidar_mount_in_use.x_m))},
                              {"y_m", r6(static_cast<double>(o.lidar_mount_in_use.y_m))}}}};
  j["min_clearance_m"] =
      std::isfinite(o.min_clearance_m) ? nlohmann::ordered_json(r6(o.min_clearance_m)) : nlohmann::ordered_json();
  nlohmann::ordered_json f = nlohmann::ordered_json::object();
  for (const auto& kv : o.faults) f[std::to_string(kv.first)] = kv.second;
  j["faults"] = f;
  j["final_state"] = dockcore::to_string(o.final_state);
  j["timed_out"] = o.timed_out;
  j["end_time_s"] = r6(o.end_time_s);
  if (!std::isnan(o.seed_success_t_s)) {
    j["seed_success"] = {
        {"t_s", r6(o.seed_success_t_s)}, {"z_err_m", r6(o.seed_success_z_err_m)}, {"x_m", r6(o.seed_success_x_m)}};
  }
  if (o.camera_rendered) {
    j["camera"] = {{"frames", o.camera_frames},
                   {"detections", o.camera_detections},
                   {"tags_fused", o.tags_fused},
                   {"tags_refused", o.tags_refused}};
  }
  return j;
}

int run_one(const RunOptions& opt) {
  docksim::Scenario sc;
  try {
    sc = docksim::load_scenario_file(opt.scenario);
  } catch (const docksim::ScenarioError& e) {
    std::cerr << "dock-sim run: " << e.what() << "\n";
    return 2;
  }
  const std::string ctl = opt.controller.empty() ? sc.controller : opt.controller;
  if (!docksim::is_controller_name(ctl)) {
    std::cerr << "dock-sim run: unknown controller '" << ctl << "' (seed000, seed004, seed003, smooth)\n";
    return 2;
  }
  const std::uint64_t seed = opt.seed_set ? opt.seed : sc.seed;
  docksim::SimOptions so;
  std::string camera_error;
  if (!docksim_cli::use_rendered_camera(sc, opt.camera_render, so, camera_error)) {
    std::cerr << "dock-sim run: " << opt.scenario << ": " << camera_error << "\n";
    return 2;
  }
  docksim::StartPose fixed;
  if (opt.start.size() == 3) {
    fixed = docksim::start_from(sc, opt.start[0], opt.start[1] / kRadToDeg, opt.start[2] / kRadToDeg);
    so.start = &fixed;
  }
  const docksim::SimRun r = docksim::run_docking(sc, ctl, seed, so);
  const docksim::SimOutcome& o = r.outcome;

  if (opt.json) {
    nlohmann::ordered_json j = outcome_json(r);
    j["scenario"] = sc.name;
    nlohmann::ordered_json tl = nlohmann::ordered_json::array();
    for (const auto& e : r.timeline) {
      tl.push_back({{"t_s", r6(e.t_s)}, {"kind", docksim::to_string(e.kind)}, {"code", e.code}, {"text", e.text}});
    }
    j["timeline"] = tl;
    j["lidar_intensity"] = dockcore::to_string(o.intensity);
    j["intensity_scans_judged"] = o.intensity_scans_judged;
    j["intensity_scans_flat"] = o.intensity_scans_flat;
    std::cout << j.dump() << "\n";
  } else {
    std::printf("scenario %s, controller %s, seed %llu\n", sc.name.c_str(), ctl.c_str(),
                static_cast<unsigned long long>(seed));
    std::printf(
        "start: distance %.3f m, bearing %+.1f deg, heading %+.1f deg (robot at x %.3f y %.3f yaw %+.1f deg, dock "
        "frame)\n",
        r.start.distance_m, r.start.bearing_rad * kRadToDeg, r.start.heading_rad * kRadToDeg,
        static_cast<double>(r.start.robot_in_dock.x_m), static_cast<double>(r.start.robot_in_dock.y_m),
        static_cast<double>(r.start.robot_in_dock.yaw_rad) * kRadToDeg);
    std::printf("timeline:\n");
    for (const auto& e : r.timeline)
      std::printf("  %8.2f s  %-7s %s\n", e.t_s, docksim::to_string(e.kind), e.text.c_str());
    std::printf("outcome: %s", o.charging_confirmed ? "CHARGING" : (o.timed_out ? "TIMEOUT" : "FAILED"));
    if (o.charging_confirmed) std::printf(" after %.2f s", o.time_to_charging_s);
    std::printf(" (final state %s)\n", dockcore::to_string(o.final_state));
    std::printf("  pads: lateral %+.1f mm, longitudinal %+.1f mm (negative = pressed), yaw %+.2f deg\n",
                o.lateral_m * 1e3, o.longitudinal_m * 1e3, o.yaw_rad * kRadToDeg);
    std::printf("  path %.2f m, reversals %d, in-place turns > 45 deg %d (largest %.0f deg), retries %d\n",
                o.path_length_m, o.reversals, o.inplace_turns_45, o.max_inplace_turn_rad * kRadToDeg, o.retries);
    if (std::isfinite(o.min_clearance_m)) std::printf("  minimum obstacle clearance %.3f m\n", o.min_clearance_m);
    if (o.calibrations > 0) {
      const dockcore::MountCalibrationResult& c = o.last_calibration;
      std::printf(
          "  mount calibration: %u swing(s), the last %s (%u detections, sweep %.0f deg, rms %.1f mm, lidar "
          "%+.1f mm sideways); mount in use x %+.4f y %+.4f m (configured %+.4f %+.4f, true %+.4f %+.4f)\n",
          o.calibrations, dockcore::to_string(c.status), c.detections, static_cast<double>(c.sweep_rad) * kRadToDeg,
          static_cast<double>(c.rms_m) * 1e3, static_cast<double>(c.lateral_error_m) * 1e3,
          static_cast<double>(o.lidar_mount_in_use.x_m), static_cast<double>(o.lidar_mount_in_use.y_m),
          static_cast<double>(sc.lidar_mount.x_m), static_cast<double>(sc.lidar_mount.y_m),
          static_cast<double>(sc.true_lidar_mount().x_m), static_cast<double>(sc.true_lidar_mount().y_m));
    }
    std::printf("  lidar intensity %s (%s: %u of %u judged scans flat)\n", dockcore::to_string(o.intensity),
                docksim::to_string(sc.lidar.intensity_output), o.intensity_scans_flat, o.intensity_scans_judged);
    std::printf("  detector: %u scans, dock found in %u; candidates refused:", o.detector.scans, o.detector.found);
    bool any_refused = false;
    for (std::size_t k = 1; k < static_cast<std::size_t>(dockcore::RejectReason::kCount); ++k) {
      if (o.detector.rejected_by[k] == 0) continue;
      std::printf(" %s %u", dockcore::to_string(static_cast<dockcore::RejectReason>(k)), o.detector.rejected_by[k]);
      any_refused = true;
    }
    std::printf("%s\n", any_refused ? "" : " none");
    for (const auto& kv : o.faults) {
      std::printf("  fault %d %s x%d\n", kv.first, dockcore::to_string(static_cast<dockcore::FaultCode>(kv.first)),
                  kv.second);
    }
  }
  if (opt.trace) {
    std::printf("trace: t_s x_m y_m yaw_deg vx_cmd_mps state (true pose, world)\n");
    for (const auto& s : r.trajectory) {
      std::printf("  %7.2f %8.4f %8.4f %8.2f %+7.3f %s\n", s.t_s, static_cast<double>(s.pose.x_m),
                  static_cast<double>(s.pose.y_m), static_cast<double>(s.pose.yaw_rad) * kRadToDeg, s.vx_cmd_mps,
                  dockcore::to_string(static_cast<dockcore::TaskState>(s.state)));
    }
  }
  if (!opt.svg.empty()) draw_run(sc, r, opt.svg);
  return o.charging_confirmed ? 0 : 1;
}

// ---------------------------------------------------------------------------------------------------------------------
struct McOptions {
  std::string scenario;
  int trials = 100;
  std::string controller;  // empty: the scenario's; "all"
  std::uint64_t seed = 0;
  bool seed_set = false;
  int jobs = 1;
  bool json = false;
  std::string svg;
  bool camera_render = false;  // --camera-render
};

std::string triple(const std::vector<double>& v, const char* f) {
  if (v.empty()) return "-";
  return fmt(f, pct(v, 50)) + "/" + fmt(f, pct(v, 95)) + "/" + fmt(f, *std::max_element(v.begin(), v.end()));
}

std::string faults_str(const std::map<int, int>& f) {
  std::string s;
  for (const auto& kv : f) s += (s.empty() ? "" : " ") + std::to_string(kv.first) + "x" + std::to_string(kv.second);
  return s.empty() ? "-" : s;
}

void print_table(const std::vector<Summary>& sums) {
  std::printf("%-8s %8s %16s %16s %16s %12s %8s %10s %12s %10s %10s  %s\n", "ctrl", "success", "lat mm p50/95/max",
              "lon mm p50/95/max", "yaw deg p50/95/max", "t s p50/p95", "path m", "reversals", "inplace>45", "retries",
              "clearance", "faults");
  for (const auto& s : sums) {
    const std::string rate = fmt("%.1f%%", 100.0 * s.successes / std::max(1, s.trials));
    const std::string t =
        s.time_s.empty() ? "-" : fmt("%.1f", pct(s.time_s, 50)) + "/" + fmt("%.1f", pct(s.time_s, 95));
    auto total_runs = [](long total, long runs) { return std::to_string(total) + " (" + std::to_string(runs) + ")"; };
    const std::string rev = total_runs(s.reversals, s.runs_with_reversals);
    const std::string inp = total_runs(s.inplace, s.runs_with_inplace);
    const std::string ret = total_runs(s.retries, s.runs_with_retries);
    const std::string clr = std::isfinite(s.min_clearance_m) ? fmt("%.3f", s.min_clearance_m) : "-";
    std::printf("%-8s %8s %16s %16s %16s %12s %8s %10s %12s %10s %10s  %s\n", s.name.c_str(), rate.c_str(),
                triple(s.lat_mm, "%.1f").c_str(), triple(s.lon_mm, "%.1f").c_str(), triple(s.yaw_deg, "%.2f").c_str(),
                t.c_str(), fmt("%.2f", pct(s.path_m, 50)).c_str(), rev.c_str(), inp.c_str(), ret.c_str(), clr.c_str(),
                faults_str(s.faults).c_str());
  }
  for (const auto& s : sums) {
    if (s.seed_t.empty()) continue;
    double mt = 0, mz = 0, mx = 0, sz = 0, sx = 0;
    const double n = static_cast<double>(s.seed_t.size());
    for (std::size_t i = 0; i < s.seed_t.size(); ++i) {
      mt += s.seed_t[i] / n;
      mz += s.seed_z[i] / n;
      mx += s.seed_x[i] / n;
    }
    for (std::size_t i = 0; i < s.seed_t.size(); ++i) {
      sz += (s.seed_z[i] - mz) * (s.seed_z[i] - mz) / n;
      sx += (s.seed_x[i] - mx) * (s.seed_x[i] - mx) / n;
    }
    double az = 0, ax = 0;
    for (std::size_t i = 0; i < s.seed_t.size(); ++i) {
      az = std::max(az, std::fabs(s.seed_z[i]));
      ax = std::max(ax, std::fabs(s.seed_x[i]));
    }
    std::printf(
        "%s own success test held in %zu/%d runs: mean time %.1f s; at that moment depth error mean %+.1f cm "
        "sd %.1f cm max|.| %.1f cm, lateral mean %+.1f cm sd %.1f cm max|.| %.1f cm\n",
        s.name.c_str(), s.seed_t.size(), s.trials, mt, mz * 100, std::sqrt(sz) * 100, az * 100, mx * 100,
        std::sqrt(sx) * 100, ax * 100);
  }
  std::printf(
      "errors and times over successful runs; path = median; reversals / in-place turns: total (runs with any);"
      " clearance = minimum over all runs\n");
}

std::string svg_path_for(const std::string& base, const std::string& ctl, bool many) {
  if (!many) return base;
  const std::string ext = ".svg";
  if (base.size() > ext.size() && base.compare(base.size() - ext.size(), ext.size(), ext) == 0) {
    return base.substr(0, base.size() - ext.size()) + "-" + ctl + ext;
  }
  return base + "-" + ctl + ext;
}

/// Colour from green (fast) through yellow to red (slow), t in [0, 1].
std::string heat(double t) {
  t = std::clamp(t, 0.0, 1.0);
  const int r = static_cast<int>(std::lround(255 * std::min(1.0, 2 * t)));
  const int g = static_cast<int>(std::lround(200 * std::min(1.0, 2 * (1 - t))));
  char buf[16];
  std::snprintf(buf, sizeof buf, "#%02x%02x30", r, g);
  return buf;
}

void draw_mc(const docksim::Scenario& sc, const std::string& ctl, const std::vector<docksim::SimRun>& runs,
             const Summary& s, const std::string& path) {
  std::vector<Pose2> poses;
  for (const auto& r : runs) poses.push_back(r.start.robot_world);
  docksim::SvgCanvas c =
      make_canvas(sc, poses, sc.name + " / " + ctl + " / " + std::to_string(runs.size()) + " trials");
  for (const auto& r : runs) {
    std::vector<Vec2> pts;
    for (const auto& t : r.trajectory) pts.emplace_back(t.pose.x_m, t.pose.y_m);
    SvgStyle st = SvgStyle::line(r.outcome.charging_confirmed ? "#1f77b4" : "#d62728", 0.6);
    st.opacity = r.outcome.charging_confirmed ? 0.35 : 0.9;
    c.polyline(pts, st);
  }
  double tmax = 1;
  for (const auto& r : runs) {
    if (r.outcome.charging_confirmed) tmax = std::max(tmax, r.outcome.time_to_charging_s);
  }
  const double tlo = s.time_s.empty() ? 0 : pct(s.time_s, 5), thi = s.time_s.empty() ? 1 : pct(s.time_s, 95);
  for (const auto& r : runs) {
    const Vec2 p(r.start.robot_world.x_m, r.start.robot_world.y_m);
    if (r.outcome.charging_confirmed) {
      c.circle(p, 0.02, SvgStyle::filled(heat((r.outcome.time_to_charging_s - tlo) / std::max(1e-6, thi - tlo))));
    } else {
      c.line(p + Vec2(-0.03, -0.03), p + Vec2(0.03, 0.03), SvgStyle::line("black", 2));
      c.line(p + Vec2(-0.03, 0.03), p + Vec2(0.03, -0.03), SvgStyle::line("black", 2));
    }
  }
  c.legend("trajectory (charging)", SvgStyle::line("#1f77b4", 1));
  c.legend("trajectory (failed)", SvgStyle::line("#d62728", 1));
  c.legend("start, fast (" + fmt("%.1f s", tlo) + ")", SvgStyle::filled(heat(0)), docksim::SvgLegendMark::kDot);
  c.legend("start, slow (" + fmt("%.1f s", thi) + ")", SvgStyle::filled(heat(1)), docksim::SvgLegendMark::kDot);
  c.legend("start, failed", SvgStyle::line("black", 2));
  c.legend_text("success " + fmt("%.1f%%", 100.0 * s.successes / std::max(1, s.trials)));
  write_svg(c, path, "montecarlo");
}

int run_mc(const McOptions& opt) {
  docksim::Scenario sc;
  try {
    sc = docksim::load_scenario_file(opt.scenario);
  } catch (const docksim::ScenarioError& e) {
    std::cerr << "dock-sim montecarlo: " << e.what() << "\n";
    return 2;
  }
  std::vector<std::string> ctls;
  if (opt.controller == "all") {
    ctls = docksim::controller_names();
  } else {
    ctls.push_back(opt.controller.empty() ? sc.controller : opt.controller);
    if (!docksim::is_controller_name(ctls[0])) {
      std::cerr << "dock-sim montecarlo: unknown controller '" << ctls[0]
                << "' (seed000, seed004, seed003, smooth, all)\n";
      return 2;
    }
  }
  if (opt.trials < 1 || opt.jobs < 1) {
    std::cerr << "dock-sim montecarlo: --trials and --jobs must be >= 1\n";
    return 2;
  }
  const std::uint64_t base = opt.seed_set ? opt.seed : sc.seed;
  const std::size_t n = static_cast<std::size_t>(opt.trials);
  const std::size_t total = n * ctls.size();
  std::vector<docksim::SimRun> runs(total);
  docksim::SimOptions so;
  std::string camera_error;
  if (!docksim_cli::use_rendered_camera(sc, opt.camera_render, so, camera_error)) {
    std::cerr << "dock-sim montecarlo: " << opt.scenario << ": " << camera_error << "\n";
    return 2;
  }
  so.record_trajectory = !opt.svg.empty();
  so.trajectory_period_s = 0.25;
  so.keep_last_scan = false;
  run_trials(total, opt.jobs, [&](std::size_t i) {
    // Trial-major order: every controller gets trial t's seed (same start, same noise streams).
    const std::size_t ci = i % ctls.size(), t = i / ctls.size();
    runs[ci * n + t] = docksim::run_docking(sc, ctls[ci], docksim::trial_seed(base, t), so);
  });

  std::vector<Summary> sums;
  for (std::size_t ci = 0; ci < ctls.size(); ++ci) {
    const std::vector<docksim::SimRun> mine(runs.begin() + static_cast<long>(ci * n),
                                            runs.begin() + static_cast<long>((ci + 1) * n));
    sums.push_back(summarise(ctls[ci], mine));
    if (!opt.svg.empty()) draw_mc(sc, ctls[ci], mine, sums.back(), svg_path_for(opt.svg, ctls[ci], ctls.size() > 1));
  }

  if (opt.json) {
    nlohmann::ordered_json j;
    j["scenario"] = sc.name;
    j["trials"] = opt.trials;
    j["seed"] = base;
    nlohmann::ordered_json arr = nlohmann::ordered_json::array();
    for (std::size_t ci = 0; ci < ctls.size(); ++ci) {
      const Summary& s = sums[ci];
      auto stats = [](const std::vector<double>& v) {
        if (v.empty()) return nlohmann::ordered_json();
        return nlohmann::ordered_json{
            {"p50", r6(pct(v, 50))}, {"p95", r6(pct(v, 95))}, {"max", r6(*std::max_element(v.begin(), v.end()))}};
      };
      nlohmann::ordered_json c;
      c["controller"] = s.name;
      c["success_rate"] = r6(static_cast<double>(s.successes) / s.trials);
      c["lateral_mm"] = stats(s.lat_mm);
      c["longitudinal_mm"] = stats(s.lon_mm);
      c["yaw_deg"] = stats(s.yaw_deg);
      c["time_to_charging_s"] = stats(s.time_s);
      c["path_length_m"] = stats(s.path_m);
      c["reversals"] = s.reversals;
      c["runs_with_reversals"] = s.runs_with_reversals;
      c["inplace_turns_45"] = s.inplace;
      c["runs_with_inplace_turns"] = s.runs_with_inplace;
      c["retries"] = s.retries;
      c["runs_with_retries"] = s.runs_with_retries;
      c["min_clearance_m"] =
          std::isfinite(s.min_clearance_m) ? nlohmann::ordered_json(r6(s.min_clearance_m)) : nlohmann::ordered_json();
      nlohmann::ordered_json f = nlohmann::ordered_json::object();
      for (const auto& kv : s.faults) f[std::to_string(kv.first)] = kv.second;
      c["faults"] = f;
      c["timeouts"] = s.timeouts;
      nlohmann::ordered_json tr = nlohmann::ordered_json::array();
      for (std::size_t t = 0; t < n; ++t) tr.push_back(outcome_json(runs[ci * n + t]));
      c["runs"] = tr;
      arr.push_back(c);
    }
    j["controllers"] = arr;
    std::cout << j.dump() << "\n";
  } else {
    std::printf("scenario %s: %d trials per controller, base seed %llu\n", sc.name.c_str(), opt.trials,
                static_cast<unsigned long long>(base));
    print_table(sums);
  }
  return 0;
}

}  // namespace

void register_run(CLI::App& app) {
  auto o = std::make_shared<RunOptions>();
  CLI::App* sub = app.add_subcommand(
      "run",
      "Simulate one closed-loop docking of a scenario: print the timeline of task states, controller phases, faults "
      "and events, and the outcome; optionally draw it as SVG. Exit 0 when charging was confirmed, 1 when not, 2 for "
      "bad arguments or a bad scenario file.");
  sub->add_option("scenario", o->scenario, "Scenario TOML file (docs/scenarios.md)")->required();
  sub->add_option("--controller", o->controller, "seed000, seed004, seed003 or smooth (default: the scenario's)");
  CLI::Option* seed =
      sub->add_option("--seed", o->seed, "Seed: start pose and every noise stream (default: the scenario's)")
          ->check(docksim::non_negative_integer());
  sub->add_option("--svg", o->svg, "Write trajectory, robot outline, dock and last scan as SVG to this file");
  sub->add_flag("--json", o->json, "Print one JSON object (outcome and timeline) instead of text");
  sub->add_option("--start", o->start,
                  "Fixed start: DISTANCE_M BEARING_DEG HEADING_DEG (default: drawn from the "
                  "scenario's envelope with the seed)")
      ->expected(3);
  sub->add_flag("--trace", o->trace, "Also print the trajectory (every 50 ms: true pose, commanded vx, task state)");
  sub->add_flag("--camera-render", o->camera_render, kCameraRenderHelp);
  sub->callback([o, seed]() {
    o->seed_set = seed->count() > 0;
    const int rc = run_one(*o);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

void register_montecarlo(CLI::App& app) {
  auto o = std::make_shared<McOptions>();
  CLI::App* sub = app.add_subcommand(
      "montecarlo",
      "Run a scenario from N seeded starts drawn from its start envelope, the same starts and noise for every "
      "controller; print a comparison table (or JSON). Results do not depend on --jobs. Exit 0, or 2 for bad "
      "arguments or a bad scenario file.");
  sub->add_option("scenario", o->scenario, "Scenario TOML file (docs/scenarios.md)")->required();
  sub->add_option("--trials", o->trials, "Starts per controller")->capture_default_str();
  sub->add_option("--controller", o->controller, "seed000, seed004, seed003, smooth or all (default: the scenario's)");
  CLI::Option* seed =
      sub->add_option("--seed", o->seed, "Base seed (default: the scenario's)")->check(docksim::non_negative_integer());
  sub->add_option("--jobs", o->jobs, "Worker threads")->capture_default_str();
  sub->add_flag("--json", o->json, "Print JSON (summary and per-run outcomes) instead of the table");
  sub->add_flag("--camera-render", o->camera_render, kCameraRenderHelp);
  sub->add_option("--svg", o->svg,
                  "Draw all trajectories and the success/time map over the start envelope (one file per controller: "
                  "NAME-<controller>.svg when several)");
  sub->callback([o, seed]() {
    o->seed_set = seed->count() > 0;
    const int rc = run_mc(*o);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace docksim_cli
