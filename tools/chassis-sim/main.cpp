// chassis-sim: the scripted chassis of dock-sim (docksim::Chassis, scenario files) on a real CAN
// interface, plus the lidar it carries (through dockcore_emu's LidarEmitter on a pty or UDP), in real time.
//
// It plays the robot base for dockd in the vcan HIL suite: consumes wheel command frames (dockcore CAN v1 or AgileX
// V2), integrates the chassis model every 5 ms, sends feedback / encoders / power / status at their documented
// periods, stops the motors after 500 ms without a command (and says so in its status), switches the charger relay
// by the ChargeRequest frames, and simulates scans of the scenario's world from the true pose so dockd sees the world
// move. Scenario events run on a clock that starts at the first non-zero wheel command ("motion start").
// A truth log (JSON lines, --truth) records the true pose and contact state for the test to judge the docking.
#include <poll.h>
#include <signal.h>
#include <time.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "chassis_sim_lidar.hpp"
#include "dockcore/drivers/can_link.hpp"
#include "dockcore/protocols/can/can_agilex_v2.hpp"
#include "dockcore/protocols/can/can_dockcore_v1.hpp"
#include "docksim/chassis.hpp"
#include "docksim/cli_checks.hpp"
#include "docksim/lidar_sim.hpp"
#include "docksim/rng.hpp"
#include "docksim/scenario.hpp"
#include "docksim/sim_run.hpp"

namespace {

using dockcore::CanFrame;
namespace v1 = dockcore::can_v1;
namespace agx = dockcore::agilex_v2;
using docksim::Pose2;

volatile sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

constexpr double kPi = 3.14159265358979323846;

std::uint64_t monotonic_us() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000u + static_cast<std::uint64_t>(ts.tv_nsec) / 1000u;
}

void sleep_until_us(std::uint64_t t_us) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t_us / 1000000u);
  ts.tv_nsec = static_cast<long>((t_us % 1000000u) * 1000u);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR && !g_stop) {
  }
}

std::int16_t sat16(double v) {
  return static_cast<std::int16_t>(std::clamp(std::lround(v), -32768L, 32767L));
}

struct Options {
  std::string can_iface;
  std::string protocol = "dockcore-v1";
  std::uint32_t chassis_base_id = v1::kDefaultChassisBaseId;
  std::uint32_t host_base_id = v1::kDefaultHostBaseId;
  std::string scenario_path;
  std::string start;  // "D,BEARING_DEG,HEADING_DEG"
  std::uint64_t seed = 1;
  double duration_s = 0;
  double command_timeout_s = 0.5;
  std::string truth_path;
  double silent_at_s = -1, silent_for_s = 0;
  bool no_charge = false;
  double break_contact_after_s = -1;  ///< Contacts break (robot nudged 3 cm back) this long after charging began.
  LidarOutOptions lidar;
};

/// One line of the truth log.
/// `wall_us` (CLOCK_REALTIME µs) stamps the line with an earlier moment than now (0: now).
void write_truth(std::FILE* f, double t_s, double motion_t_s, const docksim::ChassisState& cs, bool relay,
                 bool silent, const char* event, std::int64_t wall_us = 0) {
  if (f == nullptr) return;
  // "wall" is CLOCK_REALTIME, the clock candump stamps frames with, so a test can line events up with the CAN log.
  timespec wall{};
  clock_gettime(CLOCK_REALTIME, &wall);
  if (wall_us > 0) {
    wall.tv_sec = static_cast<time_t>(wall_us / 1000000);
    wall.tv_nsec = static_cast<long>(wall_us % 1000000) * 1000;
  }
  std::fprintf(f, "{\"wall\":%lld.%06ld,", static_cast<long long>(wall.tv_sec), wall.tv_nsec / 1000);
  std::fprintf(f,
               "\"t\":%.3f,\"motion_t\":%.3f,\"x\":%.4f,\"y\":%.4f,\"yaw\":%.5f,\"contact\":%s,\"charging\":%s,"
               "\"current_a\":%.3f,\"pad_lateral_m\":%.4f,\"press_m\":%.4f,\"pad_yaw_rad\":%.5f,"
               "\"wheel_target\":[%.3f,%.3f],\"relay\":%s,\"silent\":%s%s%s%s}\n",
               t_s, motion_t_s, static_cast<double>(cs.true_pose.x_m), static_cast<double>(cs.true_pose.y_m), static_cast<double>(cs.true_pose.yaw_rad), cs.contact ? "true" : "false",
               cs.charging ? "true" : "false", cs.charge_current_a, cs.pad_lateral_m, cs.press_m,
               cs.pad_yaw_error_rad, cs.wheel_target_radps[0], cs.wheel_target_radps[1], relay ? "true" : "false",
               silent ? "true" : "false", event ? ",\"event\":\"" : "", event ? event : "", event ? "\"" : "");
  std::fflush(f);
}

int run(const Options& opt) {
  docksim::Scenario sc = docksim::load_scenario_file(opt.scenario_path);
  const auto proto = dockcore::drivers::parse_chassis_protocol(opt.protocol);
  if (!proto) {
    std::fprintf(stderr, "chassis-sim: unknown --protocol '%s' (dockcore-v1 | agilex-v2)\n", opt.protocol.c_str());
    return 2;
  }
  for (const docksim::ScenarioEvent& ev : sc.events) {
    if (ev.kind == docksim::EventKind::kHostStall) {
      // dockd is another process: its stalls come from the machine (or SIGSTOP), not from this program.
      std::fprintf(stderr, "chassis-sim: %s: event host_stall at %.2f s is dock-sim only (stall dockd with SIGSTOP)\n",
                   opt.scenario_path.c_str(), ev.t_s);
      return 2;
    }
    if (ev.kind == docksim::EventKind::kObstacle && (ev.vx_mps != 0 || ev.vy_mps != 0)) {
      // A passer-by gives way to the robot, which needs the true pose on every step of the walk: dock-sim's loop.
      std::fprintf(stderr, "chassis-sim: %s: a walking obstacle at %.2f s is dock-sim only\n",
                   opt.scenario_path.c_str(), ev.t_s);
      return 2;
    }
    if (ev.after_state) {
      // The task state is dockd's: this program sees only wheel commands, so it cannot time an event on it.
      std::fprintf(stderr, "chassis-sim: %s: an event with in_state at %.2f s is dock-sim only\n",
                   opt.scenario_path.c_str(), ev.t_s);
      return 2;
    }
  }
  const bool agilex = *proto == dockcore::drivers::ChassisProtocol::kAgilexV2;
  v1::Ids ids;
  ids.chassis_base = opt.chassis_base_id;
  ids.host_base = opt.host_base_id;
  if (!agilex && !v1::ids_valid(ids)) {
    std::fprintf(stderr, "chassis-sim: base ids 0x%X / 0x%X are not valid 11-bit ranges\n", ids.chassis_base,
                 ids.host_base);
    return 2;
  }

  // Start pose: given, or drawn from the scenario's envelope.
  docksim::StartPose start;
  if (!opt.start.empty()) {
    double d = 0, b = 0, h = 0;
    char c1 = 0, c2 = 0;
    std::istringstream is(opt.start);
    if (!(is >> d >> c1 >> b >> c2 >> h) || c1 != ',' || c2 != ',') {
      std::fprintf(stderr, "chassis-sim: --start wants DISTANCE_M,BEARING_DEG,HEADING_DEG, got '%s'\n",
                   opt.start.c_str());
      return 2;
    }
    start = docksim::start_from(sc, d, b * kPi / 180, h * kPi / 180);
  } else {
    start = docksim::draw_start(sc, opt.seed);
  }

  // The CAN bus: the base receives wheel commands and the charge request only.
  std::vector<std::uint32_t> rx;
  if (agilex) {
    rx = {agx::kIdControlMode, agx::kIdMotionCommand};
  } else {
    rx = {v1::id_of(ids, v1::MessageKind::kWheelCmdA), v1::id_of(ids, v1::MessageKind::kWheelCmdB),
          v1::id_of(ids, v1::MessageKind::kChargeRequest)};
  }
  std::string err;
  auto bus = dockcore::drivers::open_socketcan(opt.can_iface, rx.data(), rx.size(), err);
  if (!bus) {
    std::fprintf(stderr, "chassis-sim: cannot open CAN interface '%s': %s\n", opt.can_iface.c_str(), err.c_str());
    return 1;
  }

  auto lidar = open_lidar_out(opt.lidar, err);
  if (!lidar) {
    std::fprintf(stderr, "chassis-sim: lidar output: %s\n", err.c_str());
    return 1;
  }

  std::FILE* truth = nullptr;
  if (!opt.truth_path.empty()) {
    truth = std::fopen(opt.truth_path.c_str(), "w");
    if (truth == nullptr) {
      std::fprintf(stderr, "chassis-sim: cannot write %s: %s\n", opt.truth_path.c_str(), std::strerror(errno));
      return 1;
    }
  }

  // The chassis model. Its own command timeout stays off: this program implements the 500 ms protection on the
  // CAN side, where a real base does it, and reports it in the status frame.
  docksim::ChassisParams cp = sc.chassis;
  cp.motor.command_timeout_s = 0;
  docksim::Chassis chassis(cp, opt.seed ^ 0x43484153ull);
  docksim::DockPlacement dp;
  dp.pose_world = sc.dock_pose;
  dp.face_half_width_m = sc.dock_face_half_width_m;
  chassis.set_dock(dp);
  chassis.set_true_pose(start.robot_world);
  chassis.reset_odometry(Pose2{});
  if (opt.no_charge) chassis.set_charging_inhibited(true);
  const docksim::World world_with_dock = docksim::scenario_world(sc, true);
  const docksim::World world_no_dock = docksim::scenario_world(sc, false);
  docksim::Rng lidar_rng(opt.seed ^ 0x4C494441ull);
  const auto& geom = sc.chassis.geometry;
  const std::size_t wheels = docksim::wheel_count(geom.kind);

  std::fprintf(stderr,
               "chassis-sim: %s on %s, start d %.2f m bearing %.1f deg heading %.1f deg, lidar %s %s, scenario %s\n",
               opt.protocol.c_str(), opt.can_iface.c_str(), start.distance_m, start.bearing_rad * 180 / kPi,
               start.heading_rad * 180 / kPi, opt.lidar.protocol.c_str(),
               opt.lidar.udp.empty() ? opt.lidar.pty_link.c_str() : opt.lidar.udp.c_str(), sc.name.c_str());

  signal(SIGTERM, on_signal);
  signal(SIGINT, on_signal);
  signal(SIGPIPE, SIG_IGN);

  const double dt = cp.dt_s;
  const std::uint64_t dt_us = static_cast<std::uint64_t>(std::llround(dt * 1e6));
  const std::uint64_t t0_us = monotonic_us();
  std::uint64_t next_us = t0_us;
  std::uint64_t last_cmd_us = 0;
  bool have_cmd = false;
  bool cmd_timed_out = true;
  bool agx_can_mode = false;
  // The charger relay follows dockd's ChargeRequest (v1) when the scenario's dock is switched; AgileX has no relay
  // frame and an unswitched dock is live: its charger delivers whenever the contacts close.
  const bool relay_switched = !agilex && cp.contact.switched;
  bool relay = !relay_switched;
  std::uint64_t last_charge_req_us = 0;
  double motion_t0 = -1;  // scenario clock origin
  std::size_t next_event = 0;
  double occluded_until = -1, dropout_until = -1, silent_until = -1;
  bool silent = false, silent_done = false;
  struct Disc {
    dockcore::Vec2 c;
    double r, until;
  };
  std::vector<Disc> discs;
  std::uint8_t ctr_fb = 0, ctr_enc = 0, ctr_pwr = 0, ctr_st = 0, agx_count = 0;
  std::uint8_t last_cmd_counter = 255;
  std::uint64_t step = 0;
  std::uint64_t next_fb_us = t0_us, next_pwr_us = t0_us;
  std::uint32_t late_iterations = 0;
  int max_catch_up = 0;
  const double scan_period_s = 1.0 / sc.lidar.rate_hz;
  double next_scan_t = 0, next_truth_t = 0;
  std::uint32_t bad_frames = 0, frames_rx = 0, scans_sent = 0;
  v1::CounterTracker cmd_tracker;
  LidarFaultState lidar_fault_state;
  std::int64_t last_scan_wall_us = 0;
  std::uint64_t lidar_late_seen = 0;
  double charging_since_t = -1;
  bool contact_broken = false;
  // A LaserScan is ~64 kB: keep it off the stack.
  auto scan_owner = std::make_unique<dockcore::LaserScan>();
  dockcore::LaserScan& scan = *scan_owner;

  while (!g_stop) {
    sleep_until_us(next_us);
    const std::uint64_t now_us = monotonic_us();
    next_us += dt_us;
    if (next_us < now_us) next_us = now_us + dt_us;  // late: no burst of back-to-back iterations
    const double t = static_cast<double>(now_us - t0_us) * 1e-6;
    if (opt.duration_s > 0 && t >= opt.duration_s) break;
    const double mt = motion_t0 >= 0 ? t - motion_t0 : -1;

    // 1. Scripted events on the motion clock (scenario [[events]] plus --silent-at).
    while (motion_t0 >= 0 && next_event < sc.events.size() && sc.events[next_event].t_s <= mt) {
      const docksim::ScenarioEvent& ev = sc.events[next_event++];
      switch (ev.kind) {
        case docksim::EventKind::kPush: chassis.apply_pose_jump(ev.dx_m, ev.dy_m, ev.dyaw_rad); break;
        case docksim::EventKind::kOccludeDock: occluded_until = std::max(occluded_until, mt + ev.duration_s); break;
        case docksim::EventKind::kObstacle:
          discs.push_back({docksim::obstacle_entry(sc, ev, chassis.state().true_pose, 0), ev.r_m,
                           ev.duration_s > 0 ? mt + ev.duration_s : 1e300});
          break;
        case docksim::EventKind::kLidarDropout: dropout_until = std::max(dropout_until, mt + ev.duration_s); break;
        case docksim::EventKind::kChargingNeverStarts: chassis.set_charging_inhibited(true); break;
        case docksim::EventKind::kHostStall: break;  // refused at start-up
        case docksim::EventKind::kChassisSilent:
          silent_until = std::max(silent_until, mt + ev.duration_s);
          silent = true;
          chassis.set_frozen(true, ev.hold_last_command ? docksim::FreezeMotion::kHoldLastCommand
                                                        : docksim::FreezeMotion::kStop);
          break;
      }
      write_truth(truth, t, mt, chassis.state(), relay, silent, docksim::to_string(ev.kind));
    }
    if (motion_t0 >= 0 && opt.silent_at_s >= 0 && mt >= opt.silent_at_s && !silent_done) {
      silent_done = true;
      silent_until = mt + opt.silent_for_s;  // the full window even when this loop was late
      silent = true;
      chassis.set_frozen(true, docksim::FreezeMotion::kStop);
      write_truth(truth, t, mt, chassis.state(), relay, silent, "chassis_silent");
    }
    if (silent && mt >= silent_until) {
      silent = false;
      chassis.set_frozen(false);
      write_truth(truth, t, mt, chassis.state(), relay, silent, "chassis_answers");
    }
    // Ends of timed events, in the truth log so a test knows when the fault cleared.
    for (const auto& d : discs)
      if (mt >= d.until) write_truth(truth, t, mt, chassis.state(), relay, silent, "obstacle_gone");
    discs.erase(std::remove_if(discs.begin(), discs.end(), [&](const Disc& d) { return mt >= d.until; }), discs.end());
    if (occluded_until >= 0 && mt >= occluded_until) {
      write_truth(truth, t, mt, chassis.state(), relay, silent, "occlude_dock_end");
      occluded_until = -1;
    }
    if (dropout_until >= 0 && mt >= dropout_until) {
      write_truth(truth, t, mt, chassis.state(), relay, silent, "lidar_dropout_end");
      dropout_until = -1;
    }

    // 2. Receive: wheel commands and the charge request. A silent base reads nothing (its firmware hung).
    bus->service(now_us);
    CanFrame f;
    std::uint64_t stamp = 0;
    while (bus->receive(f, stamp)) {
      ++frames_rx;
      if (silent) continue;
      if (agilex) {
        agx::ControlModeFrame cm;
        agx::MotionCommandFrame mc;
        if (agx::decode(f, cm) == agx::AgxError::kOk) {
          agx_can_mode = cm.mode == 1;
        } else if (agx::decode(f, mc) == agx::AgxError::kOk) {
          if (!agx_can_mode) continue;  // the real base ignores motion until CAN mode is enabled
          docksim::BodyTwist tw;
          tw.vx_mps = mc.linear_mmps * agx::kMpsPerBit;
          tw.vy_mps = mc.lateral_mmps * agx::kMpsPerBit;
          tw.wz_radps = mc.angular_mradps * agx::kRadpsPerBit;
          chassis.command_wheels(docksim::body_twist_to_wheel_radps(geom, tw));
          last_cmd_us = now_us;
          have_cmd = true;
          if (motion_t0 < 0 && (mc.linear_mmps != 0 || mc.angular_mradps != 0 || mc.lateral_mmps != 0)) motion_t0 = t;
        } else {
          ++bad_frames;
        }
        continue;
      }
      v1::WheelCommandFrame wc;
      v1::ChargeRequestFrame cr;
      if (v1::decode(ids, f, wc) == v1::CanV1Error::kOk) {
        if (wc.rear) continue;  // four-wheel commands: this simulator drives differential bases via the A half
        if (!v1::accepted(cmd_tracker.accept(wc.counter))) {
          ++bad_frames;
          continue;
        }
        docksim::WheelRadps w{};
        for (std::size_t i = 0; i < 2; ++i) {
          w[i] = wc.enable ? wc.wheel_mmps[i] * v1::kWheelMpsPerBit / geom.wheel_radius_m : 0.0;
        }
        chassis.command_wheels(w);
        last_cmd_us = now_us;
        have_cmd = true;
        last_cmd_counter = wc.counter;
        if (motion_t0 < 0 && wc.enable && (wc.wheel_mmps[0] != 0 || wc.wheel_mmps[1] != 0)) motion_t0 = t;
      } else if (v1::decode(ids, f, cr) == v1::CanV1Error::kOk) {
        if (relay_switched) relay = cr.enable;
        last_charge_req_us = now_us;
      } else {
        ++bad_frames;
      }
    }
    // Communication protection: no command for command_timeout_s -> motors stop.
    const bool was_timed_out = cmd_timed_out;
    cmd_timed_out = !have_cmd || static_cast<double>(now_us - last_cmd_us) * 1e-6 > opt.command_timeout_s;
    if (cmd_timed_out && !silent) chassis.command_wheels(docksim::WheelRadps{});
    // The moment the base's own protection stops the motors (the SIGKILL row of the fault matrix measures it).
    if (cmd_timed_out && !was_timed_out) write_truth(truth, t, mt, chassis.state(), relay, silent, "command_timeout");
    // The relay opens when its request stops coming (500 ms), as documented for the base.
    if (relay_switched && relay && now_us - last_charge_req_us > 500000u) relay = false;
    if (!opt.no_charge) chassis.set_charging_inhibited(!relay);

    // 3. Physics.
    // Physics keeps up with real time: when this process was descheduled (a loaded machine, an emulated VM), the
    // missed 5 ms steps are taken now, so the robot moves as far as the commands say. Bounded per iteration.
    const std::uint64_t due_steps = (now_us - t0_us) / dt_us + 1;
    int catch_up = 0;
    do {
      chassis.step();
      ++step;
    } while (step < due_steps && ++catch_up < 200);
    if (catch_up > 0) {
      ++late_iterations;
      max_catch_up = std::max(max_catch_up, catch_up);
    }
    const docksim::ChassisState& cs = chassis.state();
    if (cs.charging && charging_since_t < 0) charging_since_t = t;
    if (opt.break_contact_after_s >= 0 && charging_since_t >= 0 && !contact_broken &&
        t - charging_since_t >= opt.break_contact_after_s) {
      // Someone bumps the robot: 3 cm straight back from the contacts, which opens them.
      const double yaw = static_cast<double>(cs.true_pose.yaw_rad);
      chassis.apply_pose_jump(-0.03 * std::cos(yaw), -0.03 * std::sin(yaw), 0.0);
      contact_broken = true;
      write_truth(truth, t, mt, cs, relay, silent, "contact_break");
    }

    // 4. Transmit at the documented periods (20 ms feedback, 100 ms power/status); nothing while silent.
    if (!silent) {
      // Periods on the real clock (not the step count): a late iteration sends once, not a burst.
      const bool every20 = now_us >= next_fb_us, every100 = now_us >= next_pwr_us;
      if (every20) next_fb_us = std::max(next_fb_us + 20000u, now_us + 10000u);
      if (every100) next_pwr_us = std::max(next_pwr_us + 100000u, now_us + 50000u);
      if (agilex) {
        if (every20) {
          const auto tw = docksim::wheel_radps_to_body_twist(geom, cs.wheel_measured_radps);
          agx::MotionStateFrame ms;
          ms.linear_mmps = sat16(tw.vx_mps * 1000);
          ms.angular_mradps = sat16(tw.wz_radps * 1000);
          ms.lateral_mmps = sat16(tw.vy_mps * 1000);
          bus->send(agx::encode(ms));
          agx::OdometryFrame od;
          const double mm_per_count = 2 * kPi * geom.wheel_radius_m * 1000 / cp.noise.encoder_cpr;
          od.left_mm = static_cast<std::int32_t>(std::llround(cs.encoder_counts[0] * mm_per_count));
          od.right_mm = static_cast<std::int32_t>(std::llround(cs.encoder_counts[1] * mm_per_count));
          bus->send(agx::encode(od));
        }
        if (every100) {
          agx::SystemStateFrame ss;
          ss.vehicle_state = 0;
          ss.control_mode = agx_can_mode ? 1 : 0;
          ss.voltage_100mv = static_cast<std::uint16_t>(std::lround(cs.battery_voltage_v * 10));
          ss.error_code = cmd_timed_out && have_cmd ? 0x0100 : 0;
          ss.count = agx_count++;
          bus->send(agx::encode(ss));
          agx::BmsFrame bms;
          bms.soc_pct = static_cast<std::uint8_t>(std::lround(cs.battery_soc * 100));
          bms.soh_pct = 100;
          bms.voltage_100mv = ss.voltage_100mv;
          bms.current_100ma = sat16(cs.battery_current_a * 10);
          bms.temperature_100mdegc = 250;
          bus->send(agx::encode(bms));
        }
      } else {
        if (every20) {
          v1::WheelFeedbackFrame fb;
          v1::EncoderFrame enc;
          for (std::size_t i = 0; i < 2; ++i) {
            fb.wheel_mmps[i] = sat16(cs.wheel_measured_radps[i] * geom.wheel_radius_m * 1000);
            enc.counts[i] = cs.encoder_counts[i];
          }
          fb.counter = ctr_fb++;
          enc.counter = ctr_enc++;
          bus->send(v1::encode(ids, fb));
          bus->send(v1::encode(ids, enc));
          if (wheels == 4) {
            v1::WheelFeedbackFrame fb2;
            v1::EncoderFrame enc2;
            fb2.rear = enc2.rear = true;
            for (std::size_t i = 0; i < 2; ++i) {
              fb2.wheel_mmps[i] = sat16(cs.wheel_measured_radps[2 + i] * geom.wheel_radius_m * 1000);
              enc2.counts[i] = cs.encoder_counts[2 + i];
            }
            fb2.counter = fb.counter;
            enc2.counter = enc.counter;
            bus->send(v1::encode(ids, fb2));
            bus->send(v1::encode(ids, enc2));
          }
        }
        if (every100) {
          v1::PowerFrame pw;
          pw.voltage_10mv = static_cast<std::uint16_t>(std::lround(cs.battery_voltage_v * 100));
          pw.current_10ma = sat16(cs.battery_current_a * 100);
          pw.soc_pct = static_cast<std::uint8_t>(std::lround(cs.battery_soc * 100));
          pw.contact = cs.contact;
          pw.charge_relay = relay;
          pw.counter = ctr_pwr++;
          bus->send(v1::encode(ids, pw));
          v1::ChassisStatusFrame st;
          st.mode = static_cast<std::uint8_t>(v1::ChassisMode::kCanControl);
          st.fault_bits = cmd_timed_out && have_cmd ? v1::kFaultCmdTimeout : 0;
          st.last_cmd_counter = last_cmd_counter;
          st.counter = ctr_st++;
          bus->send(v1::encode(ids, st));
        }
      }
    }

    // 5. Lidar at the model's rate from the true pose; the turn's packets leave paced over the next turn period.
    lidar->pump(now_us);
    last_scan_wall_us = lidar->stats().last_turn_written_wall_us;
    if (lidar->stats().paced_packets_late != lidar_late_seen) {
      // This process ran late and the simulated sensor's packets left > 30 ms after their time (or a turn started
      // > 30 ms late, below): a stale lidar in dockd right after is the simulator's, not dockd's (tests/hil/matrix.py
      // watchdog_onsets).
      lidar_late_seen = lidar->stats().paced_packets_late;
      write_truth(truth, t, mt, chassis.state(), relay, silent, "sim_lidar_late");
    }
    if (t >= next_scan_t) {
      if (t - next_scan_t > 0.03 && t < next_scan_t + scan_period_s) {
        // The turn starts > 30 ms after its time: the gap between turns grows by that much, which eats into dockd's
        // lidar watchdog margin (one turn) just like a late packet does.
        write_truth(truth, t, mt, chassis.state(), relay, silent, "sim_lidar_late");
      }
      next_scan_t += scan_period_s;
      if (next_scan_t < t) {
        // Fell behind (slow VM): skip, do not burst. The truth log says so: the lidar rows of the HIL matrix must
        // not blame dockd for a stale lidar that the simulated sensor caused (tests/hil/matrix.py faults-split).
        next_scan_t = t + scan_period_s;
        write_truth(truth, t, mt, chassis.state(), relay, silent, "sim_scan_skipped");
      }
      if (!(motion_t0 >= 0 && mt < dropout_until)) {
        const bool occluded = motion_t0 >= 0 && mt < occluded_until;
        docksim::World w = occluded ? world_no_dock : world_with_dock;
        for (const auto& d : discs) w.add_circle(d.c, d.r);
        const Pose2 lidar_world = cs.true_pose.compose(sc.true_lidar_mount());
        docksim::simulate_scan(w, lidar_world, sc.lidar, lidar_rng, &scan, now_us);
        if (lidar->emit_scan(scan.view())) ++scans_sent;
      }
    }
    lidar_faults(*lidar, opt.lidar, mt, lidar_fault_state, [&](const char* ev) {
      write_truth(truth, t, mt, cs, relay, silent, ev);
      // The reference of the stale-lidar reaction: the last scan that left before the fault began.
      if (std::strcmp(ev, "lidar_stall") == 0 || std::strcmp(ev, "lidar_unplug") == 0 ||
          std::strcmp(ev, "lidar_corrupt") == 0 || std::strcmp(ev, "lidar_wrong_baud") == 0)
        write_truth(truth, t, mt, cs, relay, silent, "lidar_last_good_scan", last_scan_wall_us);
    });
    if (step % 4 == 0) lidar->service_requests();  // RPLIDAR requests answered within ~20 ms

    if (t >= next_truth_t) {
      next_truth_t += 0.1;
      write_truth(truth, t, mt, cs, relay, silent, nullptr);
    }
  }

  // Leave the truth log with the final state; the base itself stops (no commands any more).
  write_truth(truth, static_cast<double>(monotonic_us() - t0_us) * 1e-6, motion_t0 >= 0 ? 0 : -1, chassis.state(),
              relay, silent, "exit");
  if (truth) std::fclose(truth);
  const auto& bc = bus->counters();
  const auto& ls = lidar->stats();
  std::fprintf(stderr,
               "chassis-sim: exit after %.1f s: %u frames received, %u rejected, %u sent, %u send failures, %u scans; "
               "lidar %llu packets, %llu dropped, %llu bytes corrupted, %llu unwritten; %u late iterations (max %d steps caught up)\n",
               static_cast<double>(monotonic_us() - t0_us) * 1e-6, frames_rx, bad_frames, bc.frames_sent,
               bc.send_failures, scans_sent, static_cast<unsigned long long>(ls.packets),
               static_cast<unsigned long long>(ls.packets_dropped), static_cast<unsigned long long>(ls.bytes_corrupted),
               static_cast<unsigned long long>(ls.bytes_unwritten), late_iterations, max_catch_up);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"chassis-sim: the simulated robot base (dockcore CAN v1 or AgileX V2) and its lidar, in real time"};
  Options o;
  app.add_option("scenario", o.scenario_path, "Scenario TOML (as dock-sim run)")->required();
  app.add_option("--can", o.can_iface, "CAN interface, e.g. vcan0")->required();
  app.add_option("--protocol", o.protocol, "dockcore-v1 | agilex-v2");
  app.add_option("--chassis-base-id", o.chassis_base_id, "dockcore v1 chassis base id (default 0x100)");
  app.add_option("--host-base-id", o.host_base_id, "dockcore v1 host base id (default 0x180)");
  app.add_option("--start", o.start, "Start pose DISTANCE_M,BEARING_DEG,HEADING_DEG (default: drawn with --seed)");
  app.add_option("--seed", o.seed, "Seed for the start pose and every noise source")
      ->check(docksim::non_negative_integer());
  app.add_option("--duration", o.duration_s, "Stop after this many seconds (0 = until SIGTERM)");
  app.add_option("--command-timeout", o.command_timeout_s, "Motors stop after this long without a wheel command (s)");
  app.add_option("--truth", o.truth_path, "Write the true state as JSON lines (10 Hz and at events)");
  app.add_option("--silent-at", o.silent_at_s, "Stop answering this many seconds after motion start");
  app.add_option("--silent-for", o.silent_for_s, "... for this long");
  app.add_flag("--no-charge", o.no_charge, "The charger never delivers current");
  app.add_option("--break-contact-after", o.break_contact_after_s,
                 "Nudge the robot 3 cm back this many seconds after charging began (contacts break)");
  add_lidar_out_options(app, o.lidar);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    return run(o);
  } catch (const docksim::ScenarioError& e) {
    std::fprintf(stderr, "chassis-sim: %s\n", e.what());
    return 2;
  }
}
