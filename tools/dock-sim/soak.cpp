// `dock-sim soak`: N consecutive dock -> charge -> undock cycles of ONE simulated robot.
//
// Unlike montecarlo (independent runs), one Dockcore, one controller, one chassis, one lidar and one camera live for
// the whole soak; simulated time, odometry, encoders, battery and every noise stream run on from cycle to cycle.
// Between cycles the robot is carried (teleported: Chassis::set_true_pose, which odometry does not see) to the start
// of montecarlo trial i — draw_start(scenario, trial_seed(seed, i)) — so cycle i starts where montecarlo's trial i
// does, only with the state the previous cycles left behind. A cycle:
//   settle (robot idle, motors run down) -> carried to the start -> gap (idle; scans taken at the old place are
//   delivered and forgotten) -> host "dock" -> until charging is confirmed (FINISH_TASKING), a fault or max_time_s ->
//   charge for charge_s -> host "undock" -> until NOT_TASKING with result UNDOCKED, a fault or undock_timeout_s.
// A cycle that faults or times out gets a host "cancel" and the next cycle starts as usual.
// Heap: every malloc/new of the process is counted (alloc_count.hpp); those made inside Dockcore::on_scan/tick are
// core's and must be zero, the rest is the simulator's and is reported separately.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "alloc_count.hpp"
#include "commands.hpp"
#include "dockcore/control/controllers.hpp"
#include "dockcore/control/kinematics.hpp"
#include "dockcore/dockcore.hpp"
#include "dockcore/task/faults.hpp"
#include "docksim/camera_sim.hpp"
#include "docksim/chassis.hpp"
#include "docksim/cli_checks.hpp"
#include "docksim/lidar_sim.hpp"
#include "docksim/rng.hpp"
#include "docksim/scenario.hpp"
#include "docksim/sim_run.hpp"
#include "mc_stats.hpp"

namespace docksim_cli {
namespace {

using dockcore::Pose2;
using dockcore::Real;
using dockcore::TaskState;

constexpr int kStepsPerTick = 4;  // 4 x 5 ms = 50 Hz, as run_docking and dockd

struct SoakOptions {
  std::string scenario;
  int cycles = 1000;
  std::string controller;  // empty: the scenario's
  std::uint64_t seed = 0;
  bool seed_set = false;
  double charge_s = 5.0;
  double gap_s = 1.0;
  double settle_s = 0.5;
  double undock_timeout_s = 40.0;
  int drift_window = 100;
  double max_drift_lateral_mm = 2.0;
  double max_drift_yaw_deg = 0.5;
  bool json = false;
};

/// What one cycle did.
struct Cycle {
  int index = 0;
  docksim::StartPose start{};
  bool docked = false;                                    ///< Charging confirmed.
  bool charged = false;                                   ///< Stayed in FINISH_TASKING for charge_s.
  bool undocked = false;                                  ///< NOT_TASKING with result UNDOCKED.
  double lateral_m = 0, longitudinal_m = 0, yaw_rad = 0;  ///< Pads at charging confirmation (truth).
  double dock_time_s = 0;                                 ///< Dock command to charging confirmed (simulated).
  double cycle_time_s = 0;                                ///< Settle start to the end of the undock (simulated).
  double wall_s = 0;                                      ///< Wall-clock time of the cycle.
  std::map<int, int> faults;
  std::string failure;  ///< Empty when the cycle succeeded.
  std::uint64_t core_allocs = 0, sim_allocs = 0;
  std::size_t heap_bytes = 0;  ///< malloc heap in use after the cycle.
  long rss_kib = -1;
  double soc = 0;           ///< Battery state of charge after the cycle.
  double odom_error_m = 0;  ///< |odometry displacement − true displacement| accumulated over the soak so far.
  bool success() const { return docked && charged && undocked; }
};

/// The four controllers (DockingController has no public destructor: owned by value, chosen by name).
struct Controllers {
  explicit Controllers(const docksim::Scenario& sc)
      : s000(sc.seed000), s004(sc.seed004), s003(sc.seed003), smooth(sc.smooth) {}
  dockcore::Seed000Controller s000;
  dockcore::Seed004Controller s004;
  dockcore::Seed003Controller s003;
  dockcore::SmoothController smooth;
  dockcore::DockingController* get(const std::string& name) {
    if (name == "seed000") return &s000;
    if (name == "seed004") return &s004;
    if (name == "seed003") return &s003;
    if (name == "smooth") return &smooth;
    return nullptr;
  }
};

/// The continuous world: run_docking's loop without events, clearance and timeline, made resumable step by step.
class SoakWorld {
 public:
  SoakWorld(const docksim::Scenario& sc, dockcore::DockingController& ctl, std::uint64_t seed)
      : sc_(sc),
        chassis_(sc.chassis, docksim::seed_stream(seed, 0x43484153ull)),
        lidar_rng_(docksim::seed_stream(seed, 0x4C494441ull)),
        camera_(docksim::camera_sim_params(sc), docksim::seed_stream(seed, 0x43414dull)),
        world_(docksim::scenario_world(sc, true)),
        geom_(docksim::core_drive_geometry(sc.chassis.geometry)),
        target_world_(sc.dock_pose.transform(sc.camera.target_in_dock)) {
    core_ = std::make_unique<dockcore::Dockcore>(ctl);  // ~334 KiB: heap, not stack
    breakpoint_ = docksim::attach_detector(sc, *core_);
    configured_ = core_->configure(sc.profile, docksim::core_config(sc));
    chassis_.set_dock(docksim::dock_placement(sc));
    chassis_.reset_odometry(Pose2{});
    // Scans in flight: the latency is a few scan periods at most; a fixed ring keeps the loop free of per-scan heap.
    for (auto& p : ring_) p = std::make_unique<Pending>();
  }

  bool configured() const { return configured_; }
  docksim::Chassis& chassis() { return chassis_; }
  double t_s() const { return static_cast<double>(k_) * sc_.chassis.dt_s; }
  const dockcore::TickOutput& last() const { return last_; }

  /// Places the robot (truth only; odometry does not see it) at rest-ish. O(1).
  void carry_to(const Pose2& world) { chassis_.set_true_pose(world); }

  /// Advances to the end of the next control tick, queueing `cmd` for it. Returns its output.
  const dockcore::TickOutput& run_tick(dockcore::HostCommandType cmd = dockcore::HostCommandType::kNone) {
    if (cmd != dockcore::HostCommandType::kNone) {
      AllocScope scope;
      dockcore::QueuedCommand q;
      q.command = dockcore::HostCommand{cmd, 0};
      core_->submit(q);
    }
    for (;;) {
      if (step()) return last_;
    }
  }

  /// Runs ticks until `done(output)` or `timeout_s` of simulated time; true when done.
  template <typename F>
  bool run_until(double timeout_s, F done) {
    const double t0 = t_s();
    while (t_s() - t0 < timeout_s) {
      if (done(run_tick())) return true;
    }
    return false;
  }

  /// Accumulated |odometry − truth| displacement (carrying excluded): how far the two have drifted apart.
  double odom_error_m() const { return odom_err_m_; }

 private:
  struct Pending {
    dockcore::LaserScan scan;
    std::uint64_t stamp_us = 0;
  };

  /// One 5 ms step; true when it held a control tick.
  bool step() {
    const double t = t_s();
    const std::uint64_t now_us = static_cast<std::uint64_t>(std::llround(t * 1e6));
    const docksim::ChassisState& cs = chassis_.state();
    {
      AllocScope scope;
      docksim::feed_chassis(*core_, sc_, cs, now_us);
    }

    if (t + 1e-9 >= next_scan_t_) {
      next_scan_t_ += 1.0 / sc_.lidar.rate_hz;
      if (count_ < ring_.size()) {
        Pending& p = *ring_[(head_ + count_) % ring_.size()];
        docksim::simulate_scan(world_, cs.true_pose.compose(sc_.true_lidar_mount()), sc_.lidar, lidar_rng_, &p.scan,
                               now_us);
        p.stamp_us = now_us;
        ++count_;
      } else {
        ++scans_dropped_;
      }
    }
    while (count_ > 0) {
      Pending& p = *ring_[head_];
      if (static_cast<double>(now_us - p.stamp_us) * 1e-6 + 1e-9 < sc_.scan_latency_s) break;
      {
        AllocScope scope;
        core_->on_scan(p.scan.view(), p.stamp_us, now_us);
      }
      head_ = (head_ + 1) % ring_.size();
      --count_;
    }
    if (sc_.camera.enabled) camera_.update(now_us, cs.true_pose, target_world_, true);

    bool ticked = false;
    if (k_ % kStepsPerTick == 0) {
      dockcore::TickInput in;
      in.now_us = now_us;
      if (sc_.camera.enabled) in.camera = camera_.latest();
      in.contact = cs.contact;
      in.charge_current_a = static_cast<Real>(cs.charge_current_a);
      {
        AllocScope scope;
        last_ = core_->tick(in);
      }
      const dockcore::WheelSpeeds& w = last_.wheels;
      docksim::WheelRadps wr{};
      for (std::size_t i = 0; i < w.count && i < docksim::kMaxWheels; ++i) wr[i] = static_cast<double>(w.radps[i]);
      chassis_.command_wheels(wr);
      // The charger relay follows the task manager's charge request, as dockd's ChassisLink::request_charging does
      // (run_docking leaves it on: it never undocks, the undock waits for the current to stop). An unswitched dock
      // ([dock.contacts] switched = false) has no relay: it delivers whenever the contacts close.
      chassis_.set_charging_inhibited(sc_.chassis.contact.switched && !last_.status.charge_enable);
      ticked = true;
    }

    const Pose2 tb = cs.true_pose, ob = cs.odom_pose;
    chassis_.step();
    const docksim::ChassisState& a = chassis_.state();
    // Displacement error of this step in the body frame (truth vs odometry): the odometry's drift per metre.
    const Pose2 dt_true = tb.inverse().compose(a.true_pose), dt_odom = ob.inverse().compose(a.odom_pose);
    odom_err_m_ +=
        std::hypot(static_cast<double>(dt_true.x_m - dt_odom.x_m), static_cast<double>(dt_true.y_m - dt_odom.y_m));
    ++k_;
    return ticked;
  }

  const docksim::Scenario& sc_;
  docksim::Chassis chassis_;
  docksim::Rng lidar_rng_;
  docksim::CameraSim camera_;
  docksim::World world_;
  dockcore::DriveGeometry geom_;
  dockcore::Vec2 target_world_;
  std::unique_ptr<dockcore::BreakpointDetector> breakpoint_;  // before core_: outlives it
  std::unique_ptr<dockcore::Dockcore> core_;
  bool configured_ = false;
  std::uint64_t k_ = 0;
  double next_scan_t_ = 0;
  std::array<std::unique_ptr<Pending>, 8> ring_{};
  std::size_t head_ = 0, count_ = 0;
  std::uint64_t scans_dropped_ = 0;
  dockcore::TickOutput last_{};
  double odom_err_m_ = 0;
};

double mean(const std::vector<double>& v) {
  if (v.empty()) return std::nan("");
  double s = 0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

/// Least-squares slope of y over x.
double slope(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() < 2) return 0;
  const double mx = mean(x), my = mean(y);
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
  }
  return sxx > 0 ? sxy / sxx : 0;
}

nlohmann::ordered_json stats_json(const std::vector<double>& v) {
  if (v.empty()) return nlohmann::ordered_json();
  return {{"p50", r6(pct(v, 50))},
          {"p95", r6(pct(v, 95))},
          {"max", r6(*std::max_element(v.begin(), v.end()))},
          {"mean", r6(mean(v))}};
}

/// Runs one cycle; faults raised are recorded as they appear.
Cycle run_cycle(SoakWorld& w, const docksim::Scenario& sc, const SoakOptions& opt, int index, std::uint64_t base) {
  using dockcore::HostCommandType;
  Cycle c;
  c.index = index;
  c.start = docksim::draw_start(sc, docksim::trial_seed(base, static_cast<std::uint64_t>(index)));
  const double t0 = w.t_s();
  dockcore::FaultCode prev_fault = w.last().status.fault;
  auto watch = [&](const dockcore::TickOutput& o) {
    if (o.status.fault != prev_fault && o.status.fault != dockcore::FaultCode::kNone)
      ++c.faults[static_cast<int>(o.status.fault)];
    prev_fault = o.status.fault;
  };
  auto idle = [&](double s) {
    w.run_until(s, [&](const dockcore::TickOutput& o) {
      watch(o);
      return false;
    });
  };

  idle(opt.settle_s);
  w.carry_to(c.start.robot_world);
  idle(opt.gap_s);

  watch(w.run_tick(HostCommandType::kDock));
  if (w.last().command_result != dockcore::CommandResult::kAccepted) {
    c.failure = std::string("dock command ") + dockcore::to_string(w.last().command_result);
  }
  const double t_cmd = w.t_s();
  if (c.failure.empty()) {
    const bool ended = w.run_until(sc.max_time_s, [&](const dockcore::TickOutput& o) {
      watch(o);
      return o.status.state == TaskState::kFinishTasking || o.status.state == TaskState::kFault;
    });
    if (w.last().status.state == TaskState::kFinishTasking) {
      c.docked = true;
      c.dock_time_s = w.t_s() - t_cmd;
      const docksim::ChassisState& cs = w.chassis().state();
      c.lateral_m = cs.pad_lateral_m;
      c.longitudinal_m = -cs.press_m;
      c.yaw_rad = cs.pad_yaw_error_rad;
    } else {
      c.failure = ended ? "docking fault" : "docking timeout";
    }
  }
  if (c.docked) {
    const bool left = w.run_until(opt.charge_s, [&](const dockcore::TickOutput& o) {
      watch(o);
      return o.status.state != TaskState::kFinishTasking;
    });
    c.charged = !left;
    if (!c.charged)
      c.failure = std::string("left FINISH_TASKING while charging: ") + dockcore::to_string(w.last().status.state);
  }
  if (c.charged) {
    watch(w.run_tick(HostCommandType::kUndock));
    if (w.last().command_result != dockcore::CommandResult::kAccepted) {
      c.failure = std::string("undock command ") + dockcore::to_string(w.last().command_result);
    } else {
      const bool ended = w.run_until(opt.undock_timeout_s, [&](const dockcore::TickOutput& o) {
        watch(o);
        return o.status.state == TaskState::kNotTasking || o.status.state == TaskState::kFault;
      });
      c.undocked = ended && w.last().status.state == TaskState::kNotTasking &&
                   w.last().status.last_result == dockcore::TaskResult::kUndocked;
      if (!c.undocked) c.failure = ended ? "undocking fault" : "undocking timeout";
    }
  }
  if (!c.success()) watch(w.run_tick(HostCommandType::kCancel));
  c.cycle_time_s = w.t_s() - t0;
  c.soc = w.chassis().state().battery_soc;
  c.odom_error_m = w.odom_error_m();
  return c;
}

int run_soak(const SoakOptions& opt) {
  docksim::Scenario sc;
  try {
    sc = docksim::load_scenario_file(opt.scenario);
  } catch (const docksim::ScenarioError& e) {
    std::cerr << "dock-sim soak: " << e.what() << "\n";
    return 2;
  }
  if (!sc.events.empty()) {
    std::cerr << "dock-sim soak: scenario '" << sc.name
              << "' has scripted events; soak runs event-free scenarios only\n";
    return 2;
  }
  if (sc.camera.enabled && sc.camera.render) {
    std::cerr << "dock-sim soak: scenario '" << sc.name
              << "' renders camera frames (robot.camera.render); soak runs the target-level camera only: use run or "
                 "montecarlo\n";
    return 2;
  }
  const std::string ctl_name = opt.controller.empty() ? sc.controller : opt.controller;
  auto ctls = std::make_unique<Controllers>(sc);
  dockcore::DockingController* ctl = ctls->get(ctl_name);
  if (ctl == nullptr) {
    std::cerr << "dock-sim soak: unknown controller '" << ctl_name << "' (seed000, seed004, seed003, smooth)\n";
    return 2;
  }
  if (opt.cycles < 1 || opt.drift_window < 1 || !(opt.charge_s >= 0) || !(opt.gap_s >= 0) || !(opt.settle_s >= 0)) {
    std::cerr << "dock-sim soak: --cycles and --drift-window must be >= 1, times >= 0\n";
    return 2;
  }
  const std::uint64_t base = opt.seed_set ? opt.seed : sc.seed;
  SoakWorld w(sc, *ctl, base);
  if (!w.configured()) {
    std::cerr << "dock-sim soak: dock profile has no segments\n";
    return 2;
  }

  std::vector<Cycle> cycles;
  cycles.reserve(static_cast<std::size_t>(opt.cycles));
  alloc_count_arm(true);
  // The counter must count inside a scope, or core's zero below would prove nothing.
  bool counter_works = false;
  {
    const AllocCounts before = alloc_counts();
    {
      AllocScope scope;
      void* (*volatile heap_call)(std::size_t) = std::malloc;  // volatile: the call cannot be elided
      void* probe = heap_call(64);
      counter_works = alloc_counts().in_scope > before.in_scope && probe != nullptr;
      std::free(probe);
    }
  }
  for (int i = 0; i < opt.cycles; ++i) {
    const AllocCounts a0 = alloc_counts();
    const auto w0 = std::chrono::steady_clock::now();
    Cycle c = run_cycle(w, sc, opt, i, base);
    const auto w1 = std::chrono::steady_clock::now();
    const AllocCounts a1 = alloc_counts();
    c.wall_s = std::chrono::duration<double>(w1 - w0).count();
    c.core_allocs = a1.in_scope - a0.in_scope;
    c.sim_allocs = (a1.total - a0.total) - c.core_allocs;
    c.heap_bytes = heap_in_use_bytes();  // after the counters: its own calls are not the cycle's
    c.rss_kib = rss_kib();
    cycles.push_back(std::move(c));
    if (!opt.json && ((i + 1) % 50 == 0 || i + 1 == opt.cycles)) {
      std::fflush(stdout);
      std::fprintf(stderr, "\rsoak: %d/%d cycles", i + 1, opt.cycles);
      if (i + 1 == opt.cycles) std::fprintf(stderr, "\n");
    }
  }
  alloc_count_arm(false);

  // Summary.
  int successes = 0;
  std::map<int, int> faults;
  std::map<std::string, int> failures;
  std::vector<double> lat_mm, lon_mm, yaw_deg, dock_s, cycle_s, wall_s, idx;
  std::uint64_t core_after_first = 0, sim_after_first = 0, sim_max_cycle = 0;
  for (const Cycle& c : cycles) {
    successes += c.success();
    for (const auto& kv : c.faults) faults[kv.first] += kv.second;
    if (!c.failure.empty()) ++failures[c.failure];
    if (c.docked) {
      lat_mm.push_back(std::fabs(c.lateral_m) * 1e3);
      lon_mm.push_back(std::fabs(c.longitudinal_m) * 1e3);
      yaw_deg.push_back(std::fabs(c.yaw_rad) * kRadToDeg);
      dock_s.push_back(c.dock_time_s);
      idx.push_back(c.index);
    }
    cycle_s.push_back(c.cycle_time_s);
    wall_s.push_back(c.wall_s);
    if (c.index > 0) {
      core_after_first += c.core_allocs;
      sim_after_first += c.sim_allocs;
      sim_max_cycle = std::max(sim_max_cycle, c.sim_allocs);
    }
  }
  // Drift: the first and the last `window` cycles (at most half each), docked ones only.
  const std::size_t win = std::min<std::size_t>(static_cast<std::size_t>(opt.drift_window), cycles.size() / 2);
  std::vector<double> lat_first, lat_last, yaw_first, yaw_last;
  for (const Cycle& c : cycles) {
    if (!c.docked) continue;
    const std::size_t i = static_cast<std::size_t>(c.index);
    if (i < win) {
      lat_first.push_back(std::fabs(c.lateral_m) * 1e3);
      yaw_first.push_back(std::fabs(c.yaw_rad) * kRadToDeg);
    }
    if (i >= cycles.size() - win) {
      lat_last.push_back(std::fabs(c.lateral_m) * 1e3);
      yaw_last.push_back(std::fabs(c.yaw_rad) * kRadToDeg);
    }
  }
  const double d_lat = win > 0 ? mean(lat_last) - mean(lat_first) : 0;
  const double d_yaw = win > 0 ? mean(yaw_last) - mean(yaw_first) : 0;
  const double lat_slope = slope(idx, lat_mm) * 1000.0;  // mm per 1000 cycles
  const double yaw_slope = slope(idx, yaw_deg) * 1000.0;
  const bool drift_ok = !(std::fabs(d_lat) > opt.max_drift_lateral_mm) && !(std::fabs(d_yaw) > opt.max_drift_yaw_deg);
  const Cycle& first = cycles.front();
  const Cycle& lastc = cycles.back();
  const std::size_t heap_second = cycles.size() > 1 ? cycles[1].heap_bytes : first.heap_bytes;
  const long rss_second = cycles.size() > 1 ? cycles[1].rss_kib : first.rss_kib;
  long rss_max = 0;
  for (const Cycle& c : cycles) rss_max = std::max(rss_max, c.rss_kib);
  const bool counted = alloc_count_available();
  const bool heap_ok = !counted || (counter_works && core_after_first == 0);
  const bool all_ok = successes == opt.cycles && heap_ok && drift_ok;

  if (opt.json) {
    nlohmann::ordered_json j;
    j["scenario"] = sc.name;
    j["controller"] = ctl_name;
    j["seed"] = base;
    j["cycles"] = opt.cycles;
    j["charge_s"] = opt.charge_s;
    j["successes"] = successes;
    nlohmann::ordered_json f = nlohmann::ordered_json::object();
    for (const auto& kv : faults) f[std::to_string(kv.first)] = kv.second;
    j["faults"] = f;
    nlohmann::ordered_json fl = nlohmann::ordered_json::object();
    for (const auto& kv : failures) fl[kv.first] = kv.second;
    j["failures"] = fl;
    j["lateral_mm"] = stats_json(lat_mm);
    j["longitudinal_mm"] = stats_json(lon_mm);
    j["yaw_deg"] = stats_json(yaw_deg);
    j["drift"] = {{"window", win},
                  {"lateral_mm_first", r6(mean(lat_first))},
                  {"lateral_mm_last", r6(mean(lat_last))},
                  {"lateral_mm_change", r6(d_lat)},
                  {"yaw_deg_first", r6(mean(yaw_first))},
                  {"yaw_deg_last", r6(mean(yaw_last))},
                  {"yaw_deg_change", r6(d_yaw)},
                  {"lateral_mm_per_1000_cycles", r6(lat_slope)},
                  {"yaw_deg_per_1000_cycles", r6(yaw_slope)},
                  {"max_lateral_mm_change", opt.max_drift_lateral_mm},
                  {"max_yaw_deg_change", opt.max_drift_yaw_deg},
                  {"ok", drift_ok}};
    j["dock_time_s"] = stats_json(dock_s);
    j["cycle_time_s"] = stats_json(cycle_s);
    j["wall_s_per_cycle"] = stats_json(wall_s);
    j["simulated_s"] = r6(w.t_s());
    j["heap"] = {{"counted", counted},
                 {"counter_self_test", counter_works},
                 {"core_allocations_after_first_cycle", core_after_first},
                 {"core_allocations_first_cycle", first.core_allocs},
                 {"sim_allocations_after_first_cycle", sim_after_first},
                 {"sim_allocations_max_per_cycle", sim_max_cycle},
                 {"heap_bytes_after_cycle_2", heap_second},
                 {"heap_bytes_after_last", lastc.heap_bytes},
                 {"rss_kib_after_cycle_2", rss_second},
                 {"rss_kib_after_last", lastc.rss_kib},
                 {"rss_kib_max", rss_max},
                 {"ok", heap_ok}};
    j["battery_soc"] = {{"after_first", r6(first.soc)}, {"after_last", r6(lastc.soc)}};
    j["odometry_drift_m"] = r6(lastc.odom_error_m);
    j["ok"] = all_ok;
    nlohmann::ordered_json arr = nlohmann::ordered_json::array();
    for (const Cycle& c : cycles) {
      nlohmann::ordered_json e;
      e["cycle"] = c.index;
      e["start"] = {{"distance_m", r6(c.start.distance_m)},
                    {"bearing_deg", r6(c.start.bearing_rad * kRadToDeg)},
                    {"heading_deg", r6(c.start.heading_rad * kRadToDeg)}};
      e["success"] = c.success();
      if (!c.failure.empty()) e["failure"] = c.failure;
      e["lateral_mm"] = c.docked ? nlohmann::ordered_json(r6(c.lateral_m * 1e3)) : nlohmann::ordered_json();
      e["longitudinal_mm"] = c.docked ? nlohmann::ordered_json(r6(c.longitudinal_m * 1e3)) : nlohmann::ordered_json();
      e["yaw_deg"] = c.docked ? nlohmann::ordered_json(r6(c.yaw_rad * kRadToDeg)) : nlohmann::ordered_json();
      e["dock_time_s"] = c.docked ? nlohmann::ordered_json(r6(c.dock_time_s)) : nlohmann::ordered_json();
      e["cycle_time_s"] = r6(c.cycle_time_s);
      e["wall_s"] = r6(c.wall_s);
      nlohmann::ordered_json cf = nlohmann::ordered_json::object();
      for (const auto& kv : c.faults) cf[std::to_string(kv.first)] = kv.second;
      e["faults"] = cf;
      e["core_allocations"] = c.core_allocs;
      e["sim_allocations"] = c.sim_allocs;
      e["heap_bytes"] = c.heap_bytes;
      e["rss_kib"] = c.rss_kib;
      arr.push_back(e);
    }
    j["per_cycle"] = arr;
    std::cout << j.dump() << "\n";
  } else {
    auto tri = [](const std::vector<double>& v, const char* f) {
      if (v.empty()) return std::string("-");
      char b[96];
      const std::string ff = std::string(f) + "/" + f + "/" + f;
      std::snprintf(b, sizeof b, ff.c_str(), pct(v, 50), pct(v, 95), *std::max_element(v.begin(), v.end()));
      return std::string(b);
    };
    std::printf(
        "soak: scenario %s, controller %s, seed %llu: %d dock -> charge (%.1f s) -> undock cycles of one robot, "
        "%.0f s simulated\n",
        sc.name.c_str(), ctl_name.c_str(), static_cast<unsigned long long>(base), opt.cycles, opt.charge_s, w.t_s());
    std::printf("success          %d/%d\n", successes, opt.cycles);
    std::string fs;
    for (const auto& kv : faults) {
      fs += (fs.empty() ? "" : ", ") + std::to_string(kv.first) + " " +
            dockcore::to_string(static_cast<dockcore::FaultCode>(kv.first)) + " x" + std::to_string(kv.second);
    }
    std::printf("faults           %s\n", fs.empty() ? "none" : fs.c_str());
    for (const auto& kv : failures) std::printf("failed cycles    %s x%d\n", kv.first.c_str(), kv.second);
    std::printf("lateral mm       %s (p50/p95/max of |.|)\n", tri(lat_mm, "%.2f").c_str());
    std::printf("longitudinal mm  %s\n", tri(lon_mm, "%.2f").c_str());
    std::printf("yaw deg          %s\n", tri(yaw_deg, "%.3f").c_str());
    std::printf(
        "drift            first %zu vs last %zu cycles: lateral %.2f -> %.2f mm (%+.2f, limit %.2f), yaw %.3f -> "
        "%.3f deg (%+.3f, limit %.2f); slope %+.3f mm, %+.4f deg per 1000 cycles: %s\n",
        win, win, mean(lat_first), mean(lat_last), d_lat, opt.max_drift_lateral_mm, mean(yaw_first), mean(yaw_last),
        d_yaw, opt.max_drift_yaw_deg, lat_slope, yaw_slope, drift_ok ? "ok" : "DRIFT");
    std::printf("dock time s      %s\n", tri(dock_s, "%.1f").c_str());
    std::printf("cycle time s     %s (simulated)\n", tri(cycle_s, "%.1f").c_str());
    std::printf("wall s / cycle   %s\n", tri(wall_s, "%.3f").c_str());
    if (counted) {
      std::printf(
          "heap             core: %llu allocations after the first cycle (%llu in it): %s; simulator: %llu "
          "after the first cycle (max %llu in a cycle)\n",
          static_cast<unsigned long long>(core_after_first), static_cast<unsigned long long>(first.core_allocs),
          heap_ok ? "ok" : (counter_works ? "CORE ALLOCATES" : "COUNTER BROKEN"),
          static_cast<unsigned long long>(sim_after_first), static_cast<unsigned long long>(sim_max_cycle));
      std::printf("                 malloc heap in use %zu B after cycle 2, %zu B after the last\n", heap_second,
                  lastc.heap_bytes);
    } else {
      std::printf("heap             not counted (sanitizer build: the runtime owns malloc)\n");
    }
    std::printf("rss KiB          %ld after cycle 2, %ld after the last, max %ld\n", rss_second, lastc.rss_kib,
                rss_max);
    std::printf("battery soc      %.4f after the first cycle, %.4f after the last; odometry vs truth drift %.3f m\n",
                first.soc, lastc.soc, lastc.odom_error_m);
    std::printf("%s\n", all_ok ? "soak: ok" : "soak: FAILED");
    std::fflush(stdout);
  }
  return all_ok ? 0 : 1;
}

}  // namespace

void register_soak(CLI::App& app) {
  auto o = std::make_shared<SoakOptions>();
  CLI::App* sub = app.add_subcommand(
      "soak",
      "N consecutive dock -> charge -> undock cycles of one continuous simulated robot (one Dockcore, chassis, "
      "odometry and battery for all cycles); between cycles the robot is carried to montecarlo trial i's start. "
      "Reports success, faults by code, contact errors and their drift, time per cycle and heap calls (core's must be "
      "zero). Exit 0 when every cycle succeeded, core made no heap call after the first cycle and the drift is within "
      "the limits; 1 otherwise; 2 for bad arguments or a bad scenario file.");
  sub->add_option("scenario", o->scenario, "Scenario TOML file without events (docs/scenarios.md)")->required();
  sub->add_option("--cycles", o->cycles, "Dock -> charge -> undock cycles")->capture_default_str();
  sub->add_option("--controller", o->controller, "seed000, seed004, seed003 or smooth (default: the scenario's)");
  CLI::Option* seed = sub->add_option("--seed", o->seed,
                                      "Base seed: starts (montecarlo's trial seeds) and noise "
                                      "(default: the scenario's)")
                          ->check(docksim::non_negative_integer());
  sub->add_option("--charge-s", o->charge_s, "Time on the charger per cycle, s")->capture_default_str();
  sub->add_option("--gap-s", o->gap_s, "Idle time after the robot is carried to its start, s")->capture_default_str();
  sub->add_option("--settle-s", o->settle_s, "Idle time after an undock before the robot is carried, s")
      ->capture_default_str();
  sub->add_option("--undock-timeout-s", o->undock_timeout_s, "Undock not done within this: failed cycle")
      ->capture_default_str();
  sub->add_option("--drift-window", o->drift_window, "Cycles compared at the start and the end (at most half each)")
      ->capture_default_str();
  sub->add_option("--max-drift-lateral-mm", o->max_drift_lateral_mm,
                  "Largest allowed change of the mean |lateral| error, last window vs first")
      ->capture_default_str();
  sub->add_option("--max-drift-yaw-deg", o->max_drift_yaw_deg,
                  "Largest allowed change of the mean |yaw| error, last window vs first")
      ->capture_default_str();
  sub->add_flag("--json", o->json, "Print one JSON object (summary and per-cycle results) instead of text");
  sub->callback([o, seed]() {
    o->seed_set = seed->count() > 0;
    const int rc = run_soak(*o);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace docksim_cli
