// `dock-sim certify`: a Monte Carlo over a family of robots. Every trial draws its own base, drive, odometry and lidar
// mounting from documented distributions (kFactors below; docs/scenarios.md, "dock-sim certify") on top of a base
// scenario, and docks from a start drawn from that scenario's envelope. It prints the success rate with its
// one-sided 95 % Clopper–Pearson lower bound (the reliability the run demonstrates), the errors at the contacts,
// every failure with the command that replays it alone, and the success rate by quartile of each factor (where it
// breaks); --svg draws the last as one strip per factor.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <toml++/toml.h>
#include <nlohmann/json.hpp>

#include "angles.hpp"
#include "commands.hpp"
#include "dockcore/task/faults.hpp"
#include "dockcore/task/task_manager.hpp"
#include "docksim/cli_checks.hpp"
#include "docksim/rng.hpp"
#include "docksim/scenario.hpp"
#include "docksim/sim_run.hpp"
#include "docksim/svg.hpp"
#include "mc_stats.hpp"

namespace docksim_cli {
namespace {

using dockcore::Vec2;

/// One randomised property of the robot: the TOML key it sets in the trial's scenario and its range. A discrete
/// factor (choices non-null) draws one of two choices with probability `p_second` of the second.
struct Factor {
  const char* table;
  const char* key;
  double lo, hi;
  const char* unit;
  const char* what;
  const char* first = nullptr;
  const char* second = nullptr;
  double p_second = 0;
};

// The family. Ranges follow the bases, drives, mounts and dock installations robot builders have (docs/scenarios.md
// lists them); the dock's profile, where it stands and the start envelope are the base scenario's. The "events"
// factors are no TOML keys: they make one [[events]] push and one occlusion, each timed on the task's ALIGN state.
// New factors go at the end: each factor keeps its place in the trial's stream, so earlier draws stay the same.
const Factor kFactors[] = {
    {"robot", "kinematics", 0, 1, "", "drive: differential or mecanum", "diff", "mecanum", 0.3},
    {"robot.footprint", "pads", 0, 1, "", "charging pads: front or rear (docking backwards)", "front", "rear", 0.5},
    {"robot", "wheel_radius_m", 0.04, 0.08, "m", "wheel radius"},
    {"robot", "wheel_base_m", 0.25, 0.40, "m", "track (differential)"},
    {"robot", "lx_m", 0.12, 0.20, "m", "half wheelbase (mecanum)"},
    {"robot", "ly_m", 0.12, 0.20, "m", "half track (mecanum)"},
    {"robot.motor", "latency_s", 0.0, 0.10, "s", "command latency"},
    {"robot.motor", "time_constant_s", 0.02, 0.25, "s", "motor time constant"},
    {"robot.motor", "deadband_radps", 0.0, 1.0, "rad/s", "wheel deadband (not told to dockcore)"},
    {"robot.odometry", "slip_sigma", 0.0, 0.03, "", "wheel slip, 1 sigma"},
    {"robot.odometry", "radius_error", -0.03, 0.03, "", "odometry wheel radius error"},
    {"robot.odometry", "radius_diff", -0.02, 0.02, "", "odometry left/right radius difference"},
    {"robot.odometry", "base_error", -0.03, 0.03, "", "odometry track error"},
    {"robot.lidar", "x_m", -0.12, 0.12, "m", "lidar mount x (configured)"},
    {"robot.lidar", "y_m", -0.05, 0.05, "m", "lidar mount y (configured)"},
    {"robot.lidar", "yaw_deg", -10.0, 10.0, "deg", "lidar mount yaw (configured)"},
    {"lidar", "rate_hz", 5.0, 15.0, "Hz", "lidar scan rate"},
    {"lidar", "latency_s", 0.0, 0.10, "s", "lidar latency"},
    {"robot.lidar", "error_x_m", -0.01, 0.01, "m", "lidar calibration error x (not told)"},
    {"robot.lidar", "error_y_m", -0.01, 0.01, "m", "lidar calibration error y (not told)"},
    {"robot.lidar", "error_yaw_deg", -1.0, 1.0, "deg", "lidar calibration error yaw (not told)"},
    {"dock", "wall", 0, 1, "", "behind the dock: a wall, or nothing (free-standing)", "wall", "none", 0.15},
    {"dock", "wall_glass", 0, 1, "", "the wall: opaque or glass (the lidar sees through)", "opaque", "glass", 0.15},
    {"dock", "wall_gap_m", 0.0, 0.10, "m", "gap between the dock's back and its wall"},
    {"events", "push", 0, 1, "", "a push in ALIGN (must end in fault 178/179)", "none", "push", 0.10},
    {"events", "push_t_s", 0.5, 2.0, "s", "push time after ALIGN began"},
    {"events", "push_side", 0, 1, "", "push to the dock's left or right (a turn: left is counter-clockwise)", "left",
     "right", 0.5},
    {"events", "push_kind", 0, 1, "", "a shove across the dock's axis or a turn on the spot", "shove", "turn", 0.5},
    {"events", "push_lateral_m", 0.4, 0.6, "m", "shove across the dock's axis"},
    {"events", "push_turn_deg", 35.0, 60.0, "deg", "turn on the spot"},
    {"events", "occlusion", 0, 1, "", "the dock hidden from the lidar in ALIGN (someone standing in front of it)",
     "none", "hidden", 0.20},
    {"events", "occlusion_t_s", 0.5, 5.0, "s", "occlusion start after ALIGN began"},
    {"events", "occlusion_s", 0.5, 3.0, "s", "occlusion length"},
    {"robot.motor", "deadband_diff_radps", -0.4, 0.4, "rad/s", "left minus right wheel deadband (not told)"},
    {"dock", "profile", 0, 1, "", "the dock's shape: the scenario's, or v-marker (seed 004's V)", "scenario's",
     "v-marker", 0.25},
    {"dock", "unseen_profile", 0, 1, "", "instead, a shape of its own (profiles/asym-step.toml beside the scenario)",
     "none", "asym-step", 0.15},
    {"dock", "clutter", 0, 1, "", "furniture beside the dock", "none", "furniture", 0.3},
    {"dock", "clutter_kind", 0, 1, "", "the furniture: a 0.4 m box or a round bin (r 0.15 m)", "box", "bin", 0.5},
    {"dock", "clutter_side", 0, 1, "", "the furniture to the dock's left (+y) or right", "left", "right", 0.5},
    {"dock", "clutter_gap_m", 0.2, 0.8, "m", "free space between the dock's side and the furniture"},
    {"events", "passer", 0, 1, "", "a passer-by walks across in front of the dock in ALIGN", "none", "passer", 0.2},
    {"events", "passer_t_s", 0.0, 6.0, "s", "passer-by start after ALIGN began"},
    {"events", "passer_side", 0, 1, "", "the passer-by comes from the dock's left or right", "left", "right", 0.5},
    {"events", "passer_x_m", 0.5, 1.5, "m", "where the passer-by crosses the dock's axis, in front of its face"},
    {"events", "passer_speed_mps", 0.5, 1.4, "m/s", "walking speed (stands while it would come near the robot)"},
    {"events", "passer_r_m", 0.15, 0.25, "m", "the passer-by's size (legs and bag as one disc)"},
};
/// A run whose robot came closer than this to an obstacle touched it, m.
constexpr double kTouchM = 0.001;
/// Where a passer-by starts and stops, m beside the dock's axis.
constexpr double kPasserReachM = 1.5;
constexpr std::size_t kFactorCount = sizeof(kFactors) / sizeof(kFactors[0]);
constexpr std::uint64_t kFamilySalt = 0x63657274696679ull;  // the family's own stream, apart from the run's noise

/// What --calibration-error-scale multiplies factor f by: `calibration_scale` for the lidar's calibration errors (the
/// robot.lidar error_* factors), 1 for every other factor.
double scale_of(const Factor& f, double calibration_scale) {
  const bool calibration = std::string(f.table) == "robot.lidar" && std::string(f.key).rfind("error_", 0) == 0;
  return calibration ? calibration_scale : 1.0;
}

/// Factor i as drawn at `calibration_scale`: its range times scale_of().
Factor drawn_factor(std::size_t i, double calibration_scale) {
  Factor f = kFactors[i];
  const double k = scale_of(f, calibration_scale);
  f.lo *= k;
  f.hi *= k;
  if (f.lo == 0) f.lo = 0;  // no -0 in the report
  return f;
}

/// Where v lies in a continuous factor's range, 0..1 (0.5 for a range scaled to nothing).
double in_range(const Factor& f, double v) {
  return f.hi > f.lo ? (v - f.lo) / (f.hi - f.lo) : 0.5;
}

/// Writes one CSV row per trial: its index, whether the outcome was right, charging confirmed, the cause when not
/// right, the pads' signed errors at the contacts (mm, mm, deg; empty when charging was not confirmed), time to
/// charging, reversals and retries, the mount calibration (swings, the last one's result, and the robot's centre as
/// the lidar sees it, signed mm beside the truth, through the configured mount and through the mount in use at the
/// end), then every factor's drawn value (empty when the trial did not draw it). What a user needs to see which
/// factors drive the contact errors, not only the failures. False when the file cannot be written.
bool write_trials_csv(const std::string& path, const std::vector<docksim::SimRun>& runs,
                      const std::vector<std::vector<double>>& values, const std::vector<bool>& ok,
                      const std::function<std::string(std::size_t)>& cause,
                      const std::vector<double>& centre_configured_m, const std::vector<double>& centre_in_use_m) {
  std::ofstream out(path, std::ios::binary);
  out << "trial,right,charging_confirmed,cause,lateral_mm,longitudinal_mm,yaw_deg,time_to_charging_s,reversals,retries,"
         "mount_swings,mount_calibration,centre_error_configured_mm,centre_error_in_use_mm";
  for (const Factor& f : kFactors) out << "," << f.table << "." << f.key;
  out << "\n";
  auto num = [](double v, const char* format) { return std::isfinite(v) ? fmt(format, v) : std::string(); };
  for (std::size_t t = 0; t < runs.size(); ++t) {
    const docksim::SimOutcome& oc = runs[t].outcome;
    const bool docked = oc.charging_confirmed;
    out << t << "," << (ok[t] ? 1 : 0) << "," << (docked ? 1 : 0) << "," << (ok[t] ? std::string() : cause(t)) << ","
        << (docked ? fmt("%.2f", oc.lateral_m * 1e3) : "") << ","
        << (docked ? fmt("%.2f", oc.longitudinal_m * 1e3) : "") << ","
        << (docked ? fmt("%.3f", oc.yaw_rad * kRadToDeg) : "") << "," << num(oc.time_to_charging_s, "%.2f") << ","
        << oc.reversals << "," << oc.retries << "," << oc.calibrations << ","
        << (oc.calibrations > 0 ? dockcore::to_string(oc.last_calibration.status) : "") << ","
        << fmt("%.2f", centre_configured_m[t] * 1e3) << "," << fmt("%.2f", centre_in_use_m[t] * 1e3);
    for (std::size_t i = 0; i < kFactorCount; ++i) out << "," << num(values[t][i], "%.6g");
    out << "\n";
  }
  return static_cast<bool>(out);
}

struct CertifyOptions {
  std::string scenario;
  std::string controller;
  int trials = 60;
  std::uint64_t seed = 0;
  bool seed_set = false;
  int jobs = 1;
  bool json = false;
  std::string svg;
  std::string csv;    // --csv: one row per trial
  int trial = -1;     // --trial: draw only this trial
  std::string write;  // --write: the drawn trial's scenario file
  double calibration_scale = 1;  // --calibration-error-scale: times the lidar calibration error's ranges
};

/// The table at a dotted path, created when missing.
toml::table& table_at(toml::table& root, const std::string& dotted) {
  toml::table* t = &root;
  std::size_t from = 0;
  while (from <= dotted.size()) {
    const std::size_t dot = dotted.find('.', from);
    const std::string part = dotted.substr(from, dot == std::string::npos ? std::string::npos : dot - from);
    if (!t->contains(part) || !(*t)[part].is_table()) t->insert_or_assign(part, toml::table{});
    t = (*t)[part].as_table();
    if (dot == std::string::npos) break;
    from = dot + 1;
  }
  return *t;
}

/// Appends `ev` to the world's [[events]], creating the array when missing.
void append_event(toml::table& w, toml::table ev) {
  if (!w.contains("events") || !w["events"].is_array()) w.insert_or_assign("events", toml::array{});
  w["events"].as_array()->push_back(std::move(ev));
}

/// Trial `index`'s world: the base scenario with every factor drawn, the lidar's calibration error (the
/// robot.lidar error_* factors) scaled by `calibration_scale`. `values` receives each factor's value (a discrete
/// factor: 0 or 1; a factor its drive does not have: NaN). Deterministic in (base_seed, index, calibration_scale);
/// the scale changes no other draw.
toml::table draw_world(const toml::table& base, const dockcore::Pose2& dock, const std::string& unseen_profile,
                       std::uint64_t base_seed, std::size_t index, double calibration_scale,
                       std::vector<double>* values) {
  const double dock_yaw_rad = static_cast<double>(dock.yaw_rad);
  toml::table w = base;
  docksim::Rng rng(docksim::trial_seed(base_seed ^ kFamilySalt, index));
  values->assign(kFactorCount, std::nan(""));
  bool mecanum = false, wall = true, push = false;
  double push_t_s = 0, push_side = 1;
  bool push_turn = false;
  bool occluded = false;
  double occlusion_t_s = 0;
  bool clutter = false, passer = false;
  toml::table furniture;
  double passer_t_s = 0, passer_side = 1, passer_x_m = 0, passer_speed_mps = 0;
  for (std::size_t i = 0; i < kFactorCount; ++i) {
    const Factor& f = kFactors[i];
    const double u = rng.uniform();  // drawn for every factor, used or not: each keeps its own place in the stream
    const std::string key = f.key;
    if (f.first != nullptr) {
      const bool second = u < f.p_second;
      if ((key == "wall_glass" && !wall) || ((key == "push_side" || key == "push_kind") && !push)) continue;
      if ((key == "clutter_kind" || key == "clutter_side") && !clutter) continue;
      if (key == "passer_side" && !passer) continue;
      if (key == "unseen_profile" && unseen_profile.empty()) continue;
      (*values)[i] = second ? 1 : 0;
      if (key == "kinematics") mecanum = second;
      if (key == "wall") {
        wall = !second;
        table_at(w, f.table).insert_or_assign(key, wall);
      } else if (key == "wall_glass") {
        table_at(w, f.table).insert_or_assign(key, second);
      } else if (key == "push") {
        push = second;
      } else if (key == "occlusion") {
        occluded = second;
      } else if (key == "push_side") {
        push_side = second ? -1 : 1;
      } else if (key == "push_kind") {
        push_turn = second;
      } else if (key == "profile") {
        if (second) table_at(w, "dock").insert_or_assign("profile", "v-marker");
      } else if (key == "unseen_profile") {
        if (second) table_at(w, "dock").insert_or_assign("profile", unseen_profile);
      } else if (key == "clutter") {
        clutter = second;
      } else if (key == "clutter_kind") {
        furniture.insert_or_assign("kind", second ? "bin" : "box");
      } else if (key == "clutter_side") {
        furniture.insert_or_assign("side", second ? "right" : "left");
      } else if (key == "passer") {
        passer = second;
      } else if (key == "passer_side") {
        passer_side = second ? -1 : 1;
      } else {
        table_at(w, f.table).insert_or_assign(key, std::string(second ? f.second : f.first));
      }
      continue;
    }
    if ((key == "wheel_base_m" && mecanum) || ((key == "lx_m" || key == "ly_m") && !mecanum)) continue;
    if (key == "wall_gap_m" && !wall) continue;
    if (key.rfind("push_", 0) == 0 && !push) continue;
    if (key.rfind("occlusion_", 0) == 0 && !occluded) continue;
    if (key.rfind("clutter_", 0) == 0 && !clutter) continue;
    if (key.rfind("passer_", 0) == 0 && !passer) continue;
    if ((key == "push_lateral_m" && push_turn) || (key == "push_turn_deg" && !push_turn)) continue;
    double v = (f.lo + (f.hi - f.lo) * u) * scale_of(f, calibration_scale);
    if (v == 0) v = 0;  // no -0 in a scenario file
    (*values)[i] = v;
    if (key == "push_t_s") {
      push_t_s = v;
    } else if (key == "clutter_gap_m") {
      furniture.insert_or_assign("gap_m", v);
      if (!w["dock"].is_table()) table_at(w, "dock");
      toml::table& d = table_at(w, "dock");
      if (!d.contains("furniture") || !d["furniture"].is_array()) d.insert_or_assign("furniture", toml::array{});
      d["furniture"].as_array()->push_back(furniture);
    } else if (key == "passer_t_s") {
      passer_t_s = v;
    } else if (key == "passer_x_m") {
      passer_x_m = v;
    } else if (key == "passer_speed_mps") {
      passer_speed_mps = v;
    } else if (key == "passer_r_m") {
      // From kPasserReachM to one side of the dock's axis, passer_x_m in front of its face, across to the other side.
      const double c = std::cos(dock_yaw_rad), sn = std::sin(dock_yaw_rad);
      const double from_y = passer_side * kPasserReachM;
      toml::table ev;
      ev.insert_or_assign("type", "obstacle");
      ev.insert_or_assign("in_state", "ALIGN");
      ev.insert_or_assign("t_s", passer_t_s);
      ev.insert_or_assign("x_m", static_cast<double>(dock.x_m) + c * passer_x_m - sn * from_y);
      ev.insert_or_assign("y_m", static_cast<double>(dock.y_m) + sn * passer_x_m + c * from_y);
      ev.insert_or_assign("r_m", v);
      ev.insert_or_assign("vx_mps", sn * passer_side * passer_speed_mps);
      ev.insert_or_assign("vy_mps", -c * passer_side * passer_speed_mps);
      ev.insert_or_assign("duration_s", 2 * kPasserReachM / passer_speed_mps);
      append_event(w, std::move(ev));
    } else if (key == "occlusion_t_s") {
      occlusion_t_s = v;
    } else if (key == "occlusion_s") {
      toml::table ev;
      ev.insert_or_assign("type", "occlude_dock");
      ev.insert_or_assign("in_state", "ALIGN");
      ev.insert_or_assign("t_s", occlusion_t_s);
      ev.insert_or_assign("duration_s", v);
      append_event(w, std::move(ev));
    } else if (key == "push_lateral_m" || key == "push_turn_deg") {
      // Each beyond what the push test tolerates (0.3 m, 30°) however the robot stands: a shove without a turn moves
      // the dock seen by the lidar by the shove, and a turn on the spot of 35° or more turns it by as much. A shove
      // with a turn can move the dock seen less than either (the turn about the robot undoing part of the shove).
      toml::table ev;
      ev.insert_or_assign("type", "push");
      ev.insert_or_assign("in_state", "ALIGN");
      ev.insert_or_assign("t_s", push_t_s);
      const double lateral_m = push_turn ? 0.0 : push_side * v;  // across the dock's axis, world frame
      ev.insert_or_assign("dx_m", -std::sin(dock_yaw_rad) * lateral_m);
      ev.insert_or_assign("dy_m", std::cos(dock_yaw_rad) * lateral_m);
      ev.insert_or_assign("dyaw_deg", push_turn ? push_side * v : 0.0);
      append_event(w, std::move(ev));
    } else {
      table_at(w, f.table).insert_or_assign(key, v);
    }
  }
  return w;
}

/// True when trial t's world has the push: its run is right when it ends in fault 178 or 179 (the push seen), not
/// when it docks.
bool pushed(const std::vector<double>& values) {
  for (std::size_t i = 0; i < kFactorCount; ++i) {
    if (std::string(kFactors[i].key) == "push") return values[i] > 0.5;
  }
  return false;
}

/// The fault a run ended in (the highest code raised), or 0 when it did not end in FAULT.
int final_fault(const docksim::SimRun& r) {
  const auto& o = r.outcome;
  return o.final_state == dockcore::TaskState::kFault && !o.faults.empty() ? o.faults.rbegin()->first : 0;
}

/// Whether trial's run is the right outcome: charging confirmed, or for a pushed robot, fault 178/179.
bool correct(const docksim::SimRun& r, bool was_pushed) {
  if (!was_pushed) return r.outcome.charging_confirmed;
  const int f = final_fault(r);
  return f == static_cast<int>(dockcore::FaultCode::kDistanceDeviation) ||
         f == static_cast<int>(dockcore::FaultCode::kAngleDeviation);
}

std::string toml_text(const toml::table& t) {
  std::ostringstream os;
  os << t << "\n";
  return os.str();
}

/// Why a run did not confirm charging: its fault's name, "timeout", or the state it ended in.
std::string cause_of(const docksim::SimRun& r) {
  const auto& o = r.outcome;
  if (const int f = final_fault(r))
    return std::to_string(f) + " " + dockcore::to_string(static_cast<dockcore::FaultCode>(f));
  if (o.timed_out) return "timeout";
  return std::string("ended in ") + dockcore::to_string(o.final_state);
}

void draw_envelope(const std::string& path, const std::string& title, const std::vector<std::vector<double>>& values,
                   const std::vector<bool>& ok, double calibration_scale) {
  docksim::SvgBounds b;
  b.add(-0.8, 0.2);
  b.add(1.05, -static_cast<double>(kFactorCount) * 0.25 - 0.1);
  docksim::SvgCanvas c(b, 420, 20);
  c.title(title);
  for (std::size_t i = 0; i < kFactorCount; ++i) {
    const Factor f = drawn_factor(i, calibration_scale);
    const double y = -static_cast<double>(i) * 0.25;
    c.line(Vec2(0, y), Vec2(1, y), docksim::SvgStyle::line("#cccccc", 1));
    const std::string range = f.first != nullptr ? std::string(f.first) + " | " + f.second
                                                 : fmt("%g", f.lo) + " to " + fmt("%g", f.hi) + " " + f.unit;
    c.text_px(Vec2(-0.02, y), 0, 4, std::string(f.table) + "." + f.key, 11, "black", docksim::SvgAnchor::kEnd);
    c.text_px(Vec2(1.02, y), 0, 4, range, 10, "#555555");
    for (std::size_t t = 0; t < values.size(); ++t) {
      const double v = values[t][i];
      if (std::isnan(v)) continue;
      const double x = f.first != nullptr ? (v > 0.5 ? 0.75 : 0.25) : in_range(f, v);
      // Successes jittered a little about the line, failures on it and on top, so a failure is never hidden.
      const double jitter = ok[t] ? 0.06 * (static_cast<double>((t * 7919) % 97) / 96.0 - 0.5) : 0;
      c.circle(Vec2(x, y + jitter), ok[t] ? 0.008 : 0.014, docksim::SvgStyle::filled(ok[t] ? "#1f77b4" : "#d62728"));
    }
  }
  c.legend("right outcome", docksim::SvgStyle::filled("#1f77b4"), docksim::SvgLegendMark::kDot);
  c.legend("failed", docksim::SvgStyle::filled("#d62728"), docksim::SvgLegendMark::kDot);
  std::string error;
  if (!c.write(path, &error)) std::cerr << "dock-sim certify: " << error << "\n";
}

int run_certify(const CertifyOptions& o) {
  docksim::Scenario base_sc;
  toml::table base;
  try {
    base_sc = docksim::load_scenario_file(o.scenario);
    base = toml::parse_file(o.scenario);
  } catch (const docksim::ScenarioError& e) {
    std::cerr << "dock-sim certify: " << e.what() << "\n";
    return 2;
  } catch (const toml::parse_error& e) {
    std::cerr << "dock-sim certify: " << o.scenario << ": " << e.description() << "\n";
    return 2;
  }
  const std::string ctl = o.controller.empty() ? base_sc.controller : o.controller;
  if (!docksim::is_controller_name(ctl)) {
    std::cerr << "dock-sim certify: unknown controller '" << ctl << "' (seed000, seed004, seed003, smooth)\n";
    return 2;
  }
  // A trial's robot depends on the seed and its index only, so --trial needs no --trials.
  if (o.trials < 1 || o.jobs < 1) {
    std::cerr << "dock-sim certify: --trials and --jobs must be >= 1\n";
    return 2;
  }
  if (!o.write.empty() && o.trial < 0) {
    std::cerr << "dock-sim certify: --write needs --trial\n";
    return 2;
  }
  const std::uint64_t seed = o.seed_set ? o.seed : base_sc.seed;
  const std::size_t n = static_cast<std::size_t>(o.trials);
  // The unseen shape is a profile file beside the base scenario (tools/scenarios/profiles); a base elsewhere without
  // it keeps its own shape in those trials.
  // Absolute, so that a trial's file written anywhere (--write) replays.
  std::error_code ec;
  const std::filesystem::path unseen_path =
      std::filesystem::absolute(std::filesystem::path(o.scenario).parent_path() / "profiles" / "asym-step.toml", ec);
  const std::string unseen_profile = !ec && std::filesystem::is_regular_file(unseen_path, ec)
                                         ? unseen_path.lexically_normal().string()
                                         : std::string();
  if (unseen_profile.empty()) {
    std::cerr << "dock-sim certify: no " << unseen_path.string()
              << ": the family's unseen dock shape (dock.unseen_profile) is left out; its trials keep the scenario's "
                 "dock\n";
  }
  auto load = [&](std::size_t t, std::vector<double>* values) {
    const toml::table w = draw_world(base, base_sc.dock_pose, unseen_profile, seed, t, o.calibration_scale, values);
    return docksim::parse_scenario_toml(toml_text(w), o.scenario + " (trial " + std::to_string(t) + ")");
  };

  if (o.trial >= 0) {  // one trial: its world, written for `dock-sim run`
    std::vector<double> values;
    const std::size_t t = static_cast<std::size_t>(o.trial);
    const std::string text =
        toml_text(draw_world(base, base_sc.dock_pose, unseen_profile, seed, t, o.calibration_scale, &values));
    if (!o.write.empty()) {
      std::ofstream out(o.write, std::ios::binary);
      out << "# dock-sim certify " << o.scenario << " --seed " << seed << ", trial " << t
          << "; replay: dock-sim run THIS_FILE --seed " << docksim::trial_seed(seed, t) << "\n"
          << text;
      if (!out) {
        std::cerr << "dock-sim certify: cannot write " << o.write << "\n";
        return 2;
      }
    } else {
      std::cout << text;
    }
    std::fprintf(stderr, "trial %zu: dock-sim run FILE --seed %llu --controller %s\n", t,
                 static_cast<unsigned long long>(docksim::trial_seed(seed, t)), ctl.c_str());
    return 0;
  }

  std::vector<docksim::SimRun> runs(n);
  std::vector<std::vector<double>> values(n);
  std::vector<std::string> errors(n);
  // Where each robot's lidar sees its centre sideways, against the truth, m: with the configured mount, and with the
  // mount in use at the end (moved by a calibration swing that measured, TaskParams::calibrate_mount).
  std::vector<double> centre_err_configured(n), centre_err_in_use(n);
  docksim::SimOptions so;
  so.keep_last_scan = false;
  run_trials(n, o.jobs, [&](std::size_t t) {
    try {
      const docksim::Scenario sc = load(t, &values[t]);
      runs[t] = docksim::run_docking(sc, ctl, docksim::trial_seed(seed, t), so);
      // The robot's centre across the lidar's line of sight, as a mount puts it (what the swing measures).
      const auto centre_y = [](const dockcore::Pose2& mount) {
        return static_cast<double>(mount.inverse_transform(dockcore::Vec2(0, 0)).y());
      };
      const double truth = centre_y(sc.true_lidar_mount());
      centre_err_configured[t] = centre_y(sc.lidar_mount) - truth;
      centre_err_in_use[t] = centre_y(runs[t].outcome.lidar_mount_in_use) - truth;
    } catch (const docksim::ScenarioError& e) {
      errors[t] = e.what();
    }
  });
  for (std::size_t t = 0; t < n; ++t) {
    if (!errors[t].empty()) {
      std::cerr << "dock-sim certify: the family drew a scenario the loader refuses: " << errors[t] << "\n";
      return 2;
    }
  }
  const Summary s = summarise(ctl, runs);
  std::vector<bool> ok(n);
  int successes = 0, pushes = 0, pushes_seen = 0, docked_unpushed = 0;
  for (std::size_t t = 0; t < n; ++t) {
    const bool p = pushed(values[t]);
    ok[t] = correct(runs[t], p);
    successes += ok[t] ? 1 : 0;
    pushes += p ? 1 : 0;
    pushes_seen += p && ok[t] ? 1 : 0;
    docked_unpushed += !p && ok[t] ? 1 : 0;
  }
  // Runs whose robot touched an obstacle (furniture, a passer-by, a world object): the family's bar is none.
  std::vector<std::size_t> touched;
  for (std::size_t t = 0; t < n; ++t) {
    if (runs[t].outcome.min_clearance_m < kTouchM) touched.push_back(t);
  }
  // The calibration swings: how many robots swung, what the swings said, and the sideways error they left.
  int swung = 0;
  std::map<std::string, int> swing_status;
  std::vector<double> swing_before_mm, swing_after_mm;
  for (std::size_t t = 0; t < n; ++t) {
    const docksim::SimOutcome& oc = runs[t].outcome;
    if (oc.calibrations == 0) continue;
    ++swung;
    ++swing_status[dockcore::to_string(oc.last_calibration.status)];
    if (oc.last_calibration.status != dockcore::MountCalibrationStatus::kOk) continue;
    swing_before_mm.push_back(std::fabs(centre_err_configured[t]) * 1e3);
    swing_after_mm.push_back(std::fabs(centre_err_in_use[t]) * 1e3);
  }
  const double rate = static_cast<double>(successes) / static_cast<double>(n);
  const double lower = clopper_pearson_lower(o.trials, successes, 0.05);

  // Success by quartile of each continuous factor (discrete: by choice), and the errors at the contacts of the
  // robots that docked there.
  struct Bin {
    int n = 0, ok = 0;
    std::vector<double> lat_mm, yaw_deg;
  };
  std::vector<std::vector<Bin>> bins(kFactorCount, std::vector<Bin>(4));
  for (std::size_t i = 0; i < kFactorCount; ++i) {
    const Factor f = drawn_factor(i, o.calibration_scale);
    for (std::size_t t = 0; t < n; ++t) {
      const double v = values[t][i];
      if (std::isnan(v)) continue;
      const std::size_t q = f.first != nullptr ? (v > 0.5 ? 1u : 0u)
                                               : std::min<std::size_t>(3, static_cast<std::size_t>(4 * in_range(f, v)));
      ++bins[i][q].n;
      bins[i][q].ok += ok[t] ? 1 : 0;
      const docksim::SimOutcome& oc = runs[t].outcome;
      if (oc.charging_confirmed) {
        bins[i][q].lat_mm.push_back(std::fabs(oc.lateral_m) * 1e3);
        bins[i][q].yaw_deg.push_back(std::fabs(oc.yaw_rad) * kRadToDeg);
      }
    }
  }
  auto cause = [&](std::size_t t) {
    if (pushed(values[t]) && runs[t].outcome.charging_confirmed) return std::string("docked, push not seen");
    return cause_of(runs[t]);
  };
  const std::string scale_arg =
      o.calibration_scale == 1.0 ? std::string() : " --calibration-error-scale " + fmt("%g", o.calibration_scale);
  auto replay = [&](std::size_t t) {
    return "dock-sim certify " + o.scenario + " --seed " + std::to_string(seed) + scale_arg + " --trial " +
           std::to_string(t) + " --write trial.toml && dock-sim run trial.toml --seed " +
           std::to_string(docksim::trial_seed(seed, t)) + " --controller " + ctl;
  };

  if (o.json) {
    nlohmann::ordered_json j;
    j["scenario"] = base_sc.name;
    j["controller"] = ctl;
    j["calibration_error_scale"] = o.calibration_scale;
    j["seed"] = seed;
    j["trials"] = o.trials;
    j["successes"] = successes;
    j["charging_confirmed"] = docked_unpushed;
    j["pushes"] = pushes;
    j["pushes_seen"] = pushes_seen;
    j["success_rate"] = rate;
    j["lower_bound_95"] = lower;
    auto stats = [](const std::vector<double>& v) {
      if (v.empty()) return nlohmann::ordered_json();
      return nlohmann::ordered_json{
          {"p50", pct(v, 50)}, {"p95", pct(v, 95)}, {"max", *std::max_element(v.begin(), v.end())}};
    };
    j["lateral_mm"] = stats(s.lat_mm);
    j["longitudinal_mm"] = stats(s.lon_mm);
    j["yaw_deg"] = stats(s.yaw_deg);
    j["time_to_charging_s"] = stats(s.time_s);
    j["reversals"] = s.reversals;
    j["retries"] = s.retries;
    nlohmann::ordered_json ss = nlohmann::ordered_json::object();
    for (const auto& kv : swing_status) ss[kv.first] = kv.second;
    j["mount_swings"] = {{"robots", swung},
                         {"by_status", ss},
                         {"centre_error_before_mm", stats(swing_before_mm)},
                         {"centre_error_after_mm", stats(swing_after_mm)}};
    j["min_clearance_m"] =
        std::isfinite(s.min_clearance_m) ? nlohmann::ordered_json(s.min_clearance_m) : nlohmann::ordered_json();
    j["obstacle_contacts"] = touched;
    nlohmann::ordered_json fails = nlohmann::ordered_json::array();
    for (std::size_t t = 0; t < n; ++t) {
      if (ok[t]) continue;
      fails.push_back({{"trial", t}, {"cause", cause(t)}, {"replay", replay(t)}});
    }
    j["failures"] = fails;
    nlohmann::ordered_json fac = nlohmann::ordered_json::array();
    for (std::size_t i = 0; i < kFactorCount; ++i) {
      nlohmann::ordered_json b = nlohmann::ordered_json::array();
      for (const Bin& x : bins[i]) {
        auto p95 = [](const std::vector<double>& v) {
          return v.empty() ? nlohmann::ordered_json() : nlohmann::ordered_json(pct(v, 95));
        };
        b.push_back(
            {{"trials", x.n}, {"successes", x.ok}, {"lateral_mm_p95", p95(x.lat_mm)}, {"yaw_deg_p95", p95(x.yaw_deg)}});
      }
      fac.push_back({{"factor", std::string(kFactors[i].table) + "." + kFactors[i].key}, {"bins", b}});
    }
    j["factors"] = fac;
    std::cout << j.dump() << "\n";
  } else {
    std::printf("certify %s, controller %s: %d trials, each its own robot drawn from the family (base seed %llu)\n",
                base_sc.name.c_str(), ctl.c_str(), o.trials, static_cast<unsigned long long>(seed));
    if (o.calibration_scale != 1.0) {
      std::printf("calibration error   x %g of the family's (--calibration-error-scale)\n", o.calibration_scale);
    }
    std::printf("right outcome       %d / %d = %.1f %% (charging confirmed, or fault 178/179 after a push)\n",
                successes, o.trials, 100 * rate);
    std::printf("charging confirmed  %d of the %d robots not pushed\n", docked_unpushed, o.trials - pushes);
    std::printf("pushed in ALIGN     %d, seen (fault 178/179) %d\n", pushes, pushes_seen);
    std::printf("demonstrated        success rate >= %.2f %% at 95 %% confidence (one-sided Clopper-Pearson)\n",
                100 * lower);
    auto triple = [](const std::vector<double>& v, const char* f) {
      if (v.empty()) return std::string("-");
      return fmt(f, pct(v, 50)) + " / " + fmt(f, pct(v, 95)) + " / " + fmt(f, *std::max_element(v.begin(), v.end()));
    };
    std::printf("at the contacts     lateral %s mm, longitudinal %s mm, yaw %s deg (p50 / p95 / max)\n",
                triple(s.lat_mm, "%.1f").c_str(), triple(s.lon_mm, "%.1f").c_str(), triple(s.yaw_deg, "%.2f").c_str());
    std::printf("time to charging    %s s (p50 / p95 / max)\n", triple(s.time_s, "%.1f").c_str());
    std::printf("reversals           %ld in %ld runs; retries %ld in %ld runs; minimum obstacle clearance %s\n",
                s.reversals, s.runs_with_reversals, s.retries, s.runs_with_retries,
                std::isfinite(s.min_clearance_m) ? fmt("%.3f m", s.min_clearance_m).c_str() : "- (no obstacle)");
    std::string by_status;
    for (const auto& kv : swing_status)
      by_status += (by_status.empty() ? "" : ", ") + kv.first + " " + std::to_string(kv.second);
    std::printf("mount swings        %d robots swung (%s)", swung, by_status.empty() ? "-" : by_status.c_str());
    if (!swing_after_mm.empty()) {
      std::printf("; their lidar's sideways error %s mm before, %s mm after (p50 / p95 / max)",
                  triple(swing_before_mm, "%.1f").c_str(), triple(swing_after_mm, "%.1f").c_str());
    }
    std::printf("\n");
    std::string trials_touched;
    for (const std::size_t t : touched) trials_touched += " " + std::to_string(t);
    std::printf("obstacle contacts   %zu runs%s\n", touched.size(),
                touched.empty() ? "" : (" (trials" + trials_touched + ")").c_str());
    std::printf("\nfailures (each replays alone):\n");
    int shown = 0;
    for (std::size_t t = 0; t < n; ++t) {
      if (ok[t]) continue;
      std::printf("  trial %-5zu %-24s %s\n", t, cause(t).c_str(), replay(t).c_str());
      ++shown;
    }
    if (shown == 0) std::printf("  none\n");
    // One row per factor, a cell per bin (its two choices, or the quartiles of its range).
    auto by_factor = [&](const char* title, const std::function<std::string(const Bin&)>& cell, bool ranges) {
      std::printf("%s", title);
      for (std::size_t i = 0; i < kFactorCount; ++i) {
        const Factor f = drawn_factor(i, o.calibration_scale);
        std::printf("  %-26s", (std::string(f.table) + "." + f.key).c_str());
        const std::size_t nb = f.first != nullptr ? 2 : 4;
        for (std::size_t q = 0; q < nb; ++q) std::printf("  %s", cell(bins[i][q]).c_str());
        if (!ranges) {
          std::printf("\n");
        } else if (f.first != nullptr) {
          std::printf("   %s | %s\n", f.first, f.second);
        } else {
          std::printf("   %g to %g %s\n", f.lo, f.hi, f.unit);
        }
      }
    };
    by_factor(
        "\nsuccess by quartile of each factor (discrete: by choice), % (trials)\n",
        [](const Bin& x) {
          char c[32];
          std::snprintf(c, sizeof c, "%6s (%3d)", x.n > 0 ? fmt("%.1f", 100.0 * x.ok / x.n).c_str() : "-", x.n);
          return std::string(c);
        },
        true);
    by_factor(
        "\nerrors at the contacts by quartile of each factor (discrete: by choice), p95 lateral mm / yaw deg of the "
        "robots that docked\n",
        [](const Bin& x) {
          char c[32];
          std::snprintf(c, sizeof c, "%12s",
                        x.lat_mm.empty()
                            ? "-"
                            : (fmt("%.1f", pct(x.lat_mm, 95)) + " / " + fmt("%.2f", pct(x.yaw_deg, 95))).c_str());
          return std::string(c);
        },
        false);
  }
  if (!o.csv.empty() && !write_trials_csv(o.csv, runs, values, ok, cause, centre_err_configured, centre_err_in_use)) {
    std::cerr << "dock-sim certify: cannot write " << o.csv << "\n";
    return 2;
  }
  if (!o.svg.empty()) {
    draw_envelope(
        o.svg, base_sc.name + " / " + ctl + " / " + std::to_string(n) + " robots: " + fmt("%.1f %% right", 100 * rate),
        values, ok, o.calibration_scale);
  }
  return 0;
}

}  // namespace

void register_certify(CLI::App& app) {
  auto o = std::make_shared<CertifyOptions>();
  CLI::App* sub = app.add_subcommand(
      "certify",
      "Monte Carlo over a family of robots: every trial draws its own drive, odometry, lidar rate and mounting "
      "(docs/scenarios.md) on the scenario's dock and start envelope; prints the success rate with its one-sided 95 % "
      "lower bound, errors, every failure with the command that replays it, and success by factor. Exit 0, or 2 for "
      "bad arguments or a bad scenario file.");
  sub->add_option("scenario", o->scenario, "Base scenario TOML file (docs/scenarios.md)")->required();
  sub->add_option("--trials", o->trials, "Robots drawn, one docking each")->capture_default_str();
  sub->add_option("--controller", o->controller, "seed000, seed004, seed003 or smooth (default: the scenario's)");
  CLI::Option* seed =
      sub->add_option("--seed", o->seed, "Base seed (default: the scenario's)")->check(docksim::non_negative_integer());
  sub->add_option("--jobs", o->jobs, "Worker threads (results do not depend on it)")->capture_default_str();
  sub->add_flag("--json", o->json, "Print JSON instead of the report");
  sub->add_option("--svg", o->svg, "Draw success and failure over each factor's range");
  sub->add_option("--csv", o->csv,
                  "Write one row per trial: outcome, cause, errors at the contacts, time, reversals, retries and every "
                  "drawn factor");
  sub->add_option("--trial", o->trial, "Draw only this trial's robot: print its scenario (or --write it)");
  sub->add_option("--write", o->write, "With --trial: write the trial's scenario file here");
  sub->add_option("--calibration-error-scale", o->calibration_scale,
                  "Times the family's lidar calibration error (±1 cm, ±1° not told to dockcore): 0 draws robots "
                  "whose lidar sits exactly where configured; every other draw stays the same")
      ->check(CLI::Range(0.0, 10.0))
      ->capture_default_str();
  sub->callback([o, seed]() {
    o->seed_set = seed->count() > 0;
    const int rc = run_certify(*o);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace docksim_cli
