// dockd's Daemon with in-memory fakes closing the loop through dockcore_sim: the simulated chassis (motors, slip,
// encoders, contacts, charger) behind hal::ChassisLink and the lidar simulator behind hal::LidarSource, in the
// default scenario's world. Checks a whole dock -> charging -> undock, both watchdogs (zero wheels on the tick the
// data goes stale, fault code, resume), a UDP command flood, and teach -> state file -> later docking.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <string>

#include "dockcore/drivers/udp_host_link.hpp"
#include "dockd_sim_rig.hpp"
#include "docksim/rng.hpp"
#include "session_record.hpp"

#include "CppUTest/TestHarness.h"

using dockcore::TaskState;

namespace {

using dockd_test::FakeHost;
using dockd_test::SimChassis;
using dockd_test::SimClock;
using dockd_test::SimLidar;

/// The default scenario's robot and dock, as a dockd config, plus the simulated world around a Daemon.
struct Rig {
  docksim::Scenario sc = docksim::load_scenario_file(dockd_test::default_scenario_path());
  dockd::DockdConfig cfg = dockd_test::scenario_config(sc);
  SimClock clock;
  std::unique_ptr<docksim::Chassis> chassis;
  SimChassis link;
  SimLidar lidar;
  FakeHost host;
  docksim::World world;
  docksim::Rng rng{7};
  std::unique_ptr<dockd::Daemon> daemon;
  bool lidar_blocked = false;
  std::uint64_t scan_lag_us = 0;  ///< Scans are delivered this long after they were measured (a backlog).
  std::uint64_t next_scan_us = 0;
  std::string state_file;
  std::unique_ptr<dockcore::drivers::UdpHostLink> udp;

  std::string record_dir;  ///< The session record's directory when `record`.
  dockd::DaemonIo io;
  dockd::RotatingLog event_log;

  /// The own camera's frame arrivals (with `watch_camera`): every 33 ms while camera_live, then none.
  struct Frames final : dockcore::hal::CameraFrameMonitor {
    std::uint64_t last = 0;
    std::uint64_t last_frame_us() const override { return last; }
  } frames;
  bool camera_live = true;

  /// `scenario`: a file of tools/scenarios instead of default.toml. `adjust`: changes the config before the daemon
  /// is built (dock 3, the copy of dock 0, included).
  explicit Rig(const char* state_name, bool with_udp = false, double start_distance = 1.2, bool record = false,
               bool watch_camera = false, const char* scenario = nullptr,
               const std::function<void(dockd::DockdConfig&)>& adjust = nullptr) {
    if (scenario != nullptr) {
      sc = docksim::load_scenario_file(std::string(DOCKCORE_SOURCE_DIR) + "/tools/scenarios/" + scenario);
      cfg = dockd_test::scenario_config(sc);
    }
    state_file = std::string("/tmp/dockd_test_") + std::to_string(::getpid()) + "_" + state_name;
    std::remove(state_file.c_str());
    std::remove((state_file + ".bak").c_str());
    std::remove((state_file + ".learned").c_str());
    cfg.state_file = state_file;
    if (record) {
      record_dir = state_file + "_record";
      remove_record();
      ::mkdir(record_dir.c_str(), 0700);
      std::string err;
      CHECK_TRUE_TEXT(event_log.open(record_dir, "events.jsonl", 1 << 20, 2, err), err.c_str());
      cfg.record_dir = record_dir;
      cfg.record_loop = true;
    }
    cfg.teach_scans = 10;
    dockd::DockEntry d3 = cfg.docks[0];
    d3.id = 3;
    cfg.docks.push_back(d3);
    cfg.task.accepted_dock_ids = (1u << 0) | (1u << 3);
    if (adjust) adjust(cfg);
    chassis = dockd_test::scenario_chassis(sc, link, clock);
    const docksim::StartPose sp = docksim::start_from(sc, start_distance, 0.2, 0.1);
    chassis->set_true_pose(sp.robot_world);
    world = docksim::scenario_world(sc, true);
    io.lidar = &lidar;
    io.chassis = &link;
    io.can_host = &host;
    io.clock = &clock;
    io.stderr_level = std::getenv("DOCKD_TEST_LOG") ? dockd::LogLevel::kDebug : dockd::LogLevel::kError;
    if (record) io.event_log = &event_log;
    if (watch_camera) io.camera_frames = &frames;
    if (with_udp) {
      dockcore::drivers::UdpHostLinkOptions o;
      o.port = 0;
      std::string err;
      udp = dockcore::drivers::open_udp_host_link(o, err);
      io.udp_host = udp.get();
    }
    daemon = std::make_unique<dockd::Daemon>(cfg, io);
    std::string err;
    CHECK_TRUE(daemon->start(err));
  }
  /// dockd stops and starts again (a restart, a reboot) on the same robot, configuration and files.
  void restart() {
    daemon.reset();
    daemon = std::make_unique<dockd::Daemon>(cfg, io);
    std::string err;
    CHECK_TRUE_TEXT(daemon->start(err), err.c_str());
  }
  ~Rig() {
    daemon.reset();  // its shutdown event goes to event_log, declared (so destroyed) after it
    std::remove(state_file.c_str());
    std::remove((state_file + ".bak").c_str());
    std::remove((state_file + ".learned").c_str());
    if (!record_dir.empty()) remove_record();
  }
  void remove_record() const {
    for (const char* f : {"/events.jsonl", "/events.jsonl.1", "/can.log", "/can.log.1", "/loop.rec"})
      std::remove((record_dir + f).c_str());
    ::rmdir(record_dir.c_str());
  }
  /// The event log's lines with "event":"NAME".
  std::string events(const char* name) const {
    std::string out, line;
    FILE* f = std::fopen((record_dir + "/events.jsonl").c_str(), "r");
    if (f == nullptr) return out;
    const std::string key = std::string("\"event\":\"") + name + "\"";
    char buf[1024];
    while (std::fgets(buf, sizeof buf, f) != nullptr) {
      line = buf;
      if (line.find(key) != std::string::npos) out += line;
    }
    std::fclose(f);
    return out;
  }

  /// One 20 ms tick of the world: 4 chassis steps of 5 ms, a 10 Hz scan, then the daemon's tick.
  void tick() {
    for (int i = 0; i < 4; ++i) chassis->step();
    clock.t += 20000;
    if (clock.t >= next_scan_us) {
      next_scan_us = clock.t + 100000;
      if (!lidar_blocked) {
        // Where the lidar really is: the configured mount and the scenario's calibration error dockd is not told.
        const dockcore::Pose2 lp = chassis->state().true_pose.compose(sc.true_lidar_mount());
        docksim::simulate_scan(world, lp, sc.lidar, rng, lidar.scan.get(), clock.t - scan_lag_us);
        lidar.pending = true;
      }
    }
    if (camera_live && clock.t >= frames.last + 33333) frames.last = clock.t;
    daemon->on_tick(clock.t);
  }
  /// Ticks until `pred` or `max_s` of simulated time; true when pred held.
  template <typename P>
  bool run_until(P pred, double max_s) {
    const int n = static_cast<int>(max_s / 0.02);
    for (int i = 0; i < n; ++i) {
      tick();
      if (pred()) return true;
    }
    return false;
  }
  /// Sends dock `dock_id` and runs until charging is confirmed (FINISH_TASKING) or max_s; true when it was, and then
  /// *code_read says whether an ALIGN status said the dock's code was read.
  bool dock_reading_code(std::uint16_t dock_id, double max_s, bool* code_read) {
    host.command(1, dock_id);
    char json[dockcore::drivers::kMaxHostReply];
    *code_read = false;
    return run_until(
        [&] {
          if (daemon->state() == TaskState::kAlign && daemon->status_json(json, sizeof json, clock.t) > 0)
            *code_read = *code_read || std::strstr(json, "\"det_code\":\"read\"") != nullptr;
          return daemon->state() == TaskState::kFinishTasking;
        },
        max_s);
  }
  /// A UDP socket for requests to dockd's host link (a rig `with_udp`); `to` receives the link's address.
  int udp_client(sockaddr_in& to) const {
    to = sockaddr_in{};
    to.sin_family = AF_INET;
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    to.sin_port = htons(udp->bound_port());
    return ::socket(AF_INET, SOCK_DGRAM, 0);
  }
  bool wheels_zero() const {
    for (int i = 0; i < link.last.count; ++i) {
      if (link.last.radps[i] != 0) return false;
    }
    return true;
  }
};

}  // namespace

// The scenario parser's static name table is built on first use; build it before CppUTest's per-test leak check.
static const bool kNamesWarm = !docksim::controller_names().empty();

TEST_GROUP(DockdDaemon){};

TEST(DockdDaemon, TheLoopRecordReplaysEveryTickBitForBit) {
  // A docking with a chassis outage long enough for fault 184 and the resume, recorded with [record] loop; a fresh
  // core fed the record's calls must produce every tick's output exactly as dockd's core did.
  Rig r("replay", false, 1.2, true);
  CHECK_TRUE(r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0));
  r.host.command(1, 0);
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kAlign && !r.wheels_zero(); }, 20.0));
  r.link.silent = true;
  CHECK_TRUE(r.run_until([&] { return r.daemon->fault() == dockcore::FaultCode::kChassisStale; }, 3.0));
  r.link.silent = false;
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kFinishTasking; }, 60.0));
  CHECK_EQUAL(1u, r.daemon->counters().resumes);
  const std::uint64_t ticks = r.daemon->tick_stats().ticks;
  r.daemon.reset();  // flushes the record
  const std::string rec = r.record_dir + "/loop.rec";
  const dockcore::drivers::ReplayResult ok = dockcore::drivers::replay_loop_record(rec);
  CHECK_TRUE_TEXT(ok.error.empty(), ok.error.c_str());
  CHECK_TRUE_TEXT(!ok.diverged, ok.diverged_field.c_str());
  CHECK_TRUE(ok.ok);
  CHECK_FALSE(ok.truncated);
  CHECK_EQUAL(ticks, ok.ticks);
  std::printf("\nloop record: %llu records, %llu ticks, %llu scans, %llu commands replayed bit for bit\n",
              static_cast<unsigned long long>(ok.records), static_cast<unsigned long long>(ok.ticks),
              static_cast<unsigned long long>(ok.scans), static_cast<unsigned long long>(ok.commands));
  CHECK(ok.commands >= 1);
  CHECK(ok.scans > 50);  // a whole docking: some 10 s of LD06 turns
  // The replay can fail: a record whose core got other inputs diverges, and says where.
  std::FILE* f = std::fopen(rec.c_str(), "r+b");
  CHECK(f != nullptr);
  std::vector<unsigned char> bytes;
  for (int ch; (ch = std::fgetc(f)) != EOF;) bytes.push_back(static_cast<unsigned char>(ch));
  // The last wheel feedback record (kind 2): its first wheel speed changed, so the odometry differs from there on.
  std::size_t off = 0, last_wheels = 0;
  const std::size_t header = std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size()).find('\n', 8) + 1;
  for (off = header; off + 5 <= bytes.size();) {
    const std::size_t len = bytes[off + 1] | (bytes[off + 2] << 8) | (bytes[off + 3] << 16) |
                            (static_cast<std::size_t>(bytes[off + 4]) << 24);
    if (bytes[off] == 2 && off < bytes.size() / 2) last_wheels = off;
    off += 5 + len;
  }
  CHECK_EQUAL(bytes.size(), off);
  CHECK(last_wheels > 0);
  bytes[last_wheels + 5 + sizeof(dockcore::Real) - 1] ^= 0x40;  // the sign/exponent byte of wheel 0 (little-endian)
  std::fseek(f, 0, SEEK_SET);
  CHECK_EQUAL(bytes.size(), std::fwrite(bytes.data(), 1, bytes.size(), f));
  std::fclose(f);
  const dockcore::drivers::ReplayResult bad = dockcore::drivers::replay_loop_record(rec);
  CHECK_TRUE(bad.diverged);
  CHECK(bad.diverged_tick > 0 && bad.diverged_tick < ticks);
  // A truncated record replays up to its cut; a file that is no record is refused with its reason.
  CHECK_EQUAL(0, ::truncate(rec.c_str(), static_cast<off_t>(last_wheels + 3)));
  const dockcore::drivers::ReplayResult cut = dockcore::drivers::replay_loop_record(rec);
  CHECK_TRUE(cut.ok && cut.truncated && !cut.diverged);
  const dockcore::drivers::ReplayResult none = dockcore::drivers::replay_loop_record(r.record_dir + "/events.jsonl");
  STRCMP_CONTAINS("not a dockcore loop record", none.error.c_str());
}

// A lidar 1 cm / 1 cm / 1° off its configured mount (tools/scenarios/lidar-miscalibrated.toml): the first docking
// misses, swings and measures the mount (status mount_*), and docks. What the core learned is the robot's: the next
// docking, at another dock id (dockd configures the core for it), keeps the measured mount and docks at the first
// attempt. The session record replays it bit for bit.
TEST(DockdDaemon, TheMeasuredLidarMountGoesOnToTheNextDock) {
  Rig r("mount", false, 1.2, true, false, "lidar-miscalibrated.toml");
  CHECK_TRUE(r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0));
  r.host.command(1, 0);
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kFinishTasking; }, 120.0));
  CHECK(r.daemon->last_status().retries >= 1);
  char json[dockcore::drivers::kMaxHostReply];
  CHECK(r.daemon->status_json(json, sizeof json, r.clock.t) > 0);
  STRCMP_CONTAINS("\"mount_swings\":1,\"mount_calibration\":\"ok\",", json);
  const double configured_y = static_cast<double>(r.cfg.lidar_mount.y_m);
  const double true_y = static_cast<double>(r.sc.true_lidar_mount().y_m);
  CHECK(std::fabs(true_y - configured_y) > 0.008);
  // The mount in use, as the status gives it (4 decimals): within 3 mm of the truth, not the configuration.
  const char* at = std::strstr(json, "\"mount_y_m\":");
  CHECK(at != nullptr);
  const double in_use_y = std::atof(at + std::strlen("\"mount_y_m\":"));
  CHECK(std::fabs(in_use_y - true_y) < 0.003);
  r.host.command(3, 0);  // undock
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kNotTasking; }, 40.0));
  r.host.command(1, 3);  // dock 3: the core is configured for it
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kFinishTasking; }, 120.0));
  CHECK_EQUAL(0, r.daemon->last_status().retries);
  CHECK_EQUAL(3, r.daemon->last_status().dock_id);
  CHECK(r.daemon->status_json(json, sizeof json, r.clock.t) > 0);
  STRCMP_CONTAINS("\"mount_swings\":1,\"mount_calibration\":\"ok\",", json);
  const std::uint64_t ticks = r.daemon->tick_stats().ticks;
  r.daemon.reset();  // flushes the record
  const dockcore::drivers::ReplayResult rep = dockcore::drivers::replay_loop_record(r.record_dir + "/loop.rec");
  CHECK_TRUE_TEXT(rep.error.empty(), rep.error.c_str());
  CHECK_TRUE_TEXT(!rep.diverged, rep.diverged_field.c_str());
  CHECK_EQUAL(ticks, rep.ticks);
}

TEST(DockdDaemon, WhatTheRobotLearnedOutlivesARestartOnTheSameConfiguration) {
  Rig r("learned", false, 1.2, true, false, "lidar-miscalibrated.toml");
  CHECK_TRUE(r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0));
  r.host.command(1, 0);
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kFinishTasking; }, 120.0));
  CHECK(r.daemon->last_status().retries >= 1);  // missed once, swung, docked
  CHECK(r.daemon->counters().learned_saves >= 1);
  char json[dockcore::drivers::kMaxHostReply];
  CHECK(r.daemon->status_json(json, sizeof json, r.clock.t) > 0);
  STRCMP_CONTAINS("\"mount_swings\":1,\"mount_calibration\":\"ok\",", json);
  const char* at = std::strstr(json, "\"mount_y_m\":");
  CHECK(at != nullptr);
  const std::string mount_y(at, std::strcspn(at, ","));
  r.host.command(3, 0);  // undock
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kNotTasking; }, 40.0));

  // Restarted: the measured mount (and the deadband floors, the remembered aim) are in use before any docking, and
  // the next docking closes the contacts at its first attempt.
  r.restart();
  CHECK(r.daemon->status_json(json, sizeof json, r.clock.t) > 0);
  STRCMP_CONTAINS("\"mount_swings\":1,\"mount_calibration\":\"ok\",", json);
  STRCMP_CONTAINS(mount_y.c_str(), json);
  STRCMP_CONTAINS("\"result\":\"restored\"", r.events("learned").c_str());
  CHECK_TRUE(r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0));
  r.host.command(1, 0);
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kFinishTasking; }, 120.0));
  CHECK_EQUAL(0, r.daemon->last_status().retries);
  // The restarted session's record replays the hand-over: bit for bit.
  const std::uint64_t ticks = r.daemon->tick_stats().ticks;
  r.daemon.reset();
  const dockcore::drivers::ReplayResult rep = dockcore::drivers::replay_loop_record(r.record_dir + "/loop.rec");
  CHECK_TRUE_TEXT(rep.error.empty(), rep.error.c_str());
  CHECK_TRUE_TEXT(!rep.diverged, rep.diverged_field.c_str());
  CHECK_EQUAL(ticks, rep.ticks);

  // Restarted with the lidar configured elsewhere: what was learned on the old mount is not used.
  r.cfg.lidar_mount.x_m += static_cast<dockcore::Real>(0.01);
  r.restart();
  CHECK(r.daemon->status_json(json, sizeof json, r.clock.t) > 0);
  STRCMP_CONTAINS("\"mount_swings\":0,\"mount_calibration\":\"none\",", json);
  STRCMP_CONTAINS("\"result\":\"not_restored\"", r.events("learned").c_str());
}

TEST(DockdDaemon, DocksChargesAndUndocksInSimulation) {
  Rig r("dock");
  CHECK_TRUE(r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0));
  CHECK_EQUAL(static_cast<int>(TaskState::kNotTasking), static_cast<int>(r.daemon->state()));
  r.host.command(1, 0);  // CAN host frame: dock at dock 0
  bool moved = false;
  CHECK_TRUE(r.run_until(
      [&] {
        moved = moved || !r.wheels_zero();
        return r.daemon->state() == TaskState::kFinishTasking;
      },
      60.0));
  CHECK_TRUE(moved);
  CHECK_TRUE(r.chassis->state().charging);
  CHECK_TRUE(r.wheels_zero());
  CHECK_EQUAL(static_cast<int>(TaskState::kFinishTasking), r.host.last.task_state);
  // Odometry from the measured wheels follows the chassis' own dead reckoning (same encoders).
  const dockcore::Pose2 co = r.chassis->state().odom_pose;
  const dockcore::Pose2 dodom = r.daemon->odom_pose();
  const double dist = std::hypot(static_cast<double>(co.x_m), static_cast<double>(co.y_m));
  CHECK(dist > 0.3);
  const double pos_err = std::hypot(static_cast<double>(dodom.x_m - co.x_m), static_cast<double>(dodom.y_m - co.y_m));
  CHECK(pos_err < 0.05 * dist + 0.01);
  // The simulated LD06's intensities vary with the surfaces: the core's intensity check calls them usable.
  char json[dockcore::drivers::kMaxHostReply];
  CHECK(r.daemon->status_json(json, sizeof json, r.clock.t) > 0);
  STRCMP_CONTAINS("\"lidar_intensity\":\"usable\",", json);

  r.host.command(3, 0);  // undock
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kNotTasking; }, 40.0));
  CHECK_EQUAL(static_cast<int>(dockcore::TaskResult::kUndocked), static_cast<int>(r.daemon->last_status().last_result));
  CHECK_FALSE(r.chassis->state().contact);
  CHECK(r.daemon->tick_stats().ticks > 100);
}

// Two docks of one shape, told apart by their tape: the status says the dock in view was read with its own
// pattern, and the robot charges at it; the untaped default dock reads no code at all.
TEST(DockdDaemon, TheStatusSaysWhetherTheDocksCodeWasRead) {
  Rig r("code", false, 1.2, false, false, "two-docks.toml");
  CHECK_TRUE(r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0));
  bool read = false;
  CHECK_TRUE(r.dock_reading_code(0, 60.0, &read));  // dock 0: plate-v-code-a
  CHECK_TRUE(read);
  char json[dockcore::drivers::kMaxHostReply];
  CHECK(r.daemon->status_json(json, sizeof json, r.clock.t) > 0);
  CHECK_TRUE(r.chassis->state().charging);
  STRCMP_CONTAINS("\"lidar_intensity\":\"usable\"", json);
  Rig plain("code_plain");
  plain.run_until([] { return false; }, 0.5);
  CHECK(plain.daemon->status_json(json, sizeof json, plain.clock.t) > 0);
  STRCMP_CONTAINS("\"det_code\":\"none\"", json);
}

// The status names the database dock whose code it read: sent to a dock whose pattern stands nowhere in the room,
// the robot refuses the taped dock it sees (wrong_code) and the status says that dock is dock 0; never the dock it
// was sent to.
TEST(DockdDaemon, TheStatusNamesTheDockWhoseCodeItRead) {
  Rig r("code_id", false, 1.2, false, false, "two-docks.toml", [](dockd::DockdConfig& c) {
    dockd::DockEntry& d3 = c.docks.back();  // dock 3: dock 0's outline with a code of its own
    d3.profile.reflector_count = 0;
    CHECK(dockcore::add_reflector(d3.profile, {1, 0.0f, 0.05f}) == dockcore::ProfileError::kOk);
    CHECK(dockcore::add_reflector(d3.profile, {1, 0.25f, 0.30f}) == dockcore::ProfileError::kOk);
  });
  CHECK_TRUE(r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0));
  r.host.command(1, 3);  // dock at dock 3
  char json[dockcore::drivers::kMaxHostReply];
  int named_0 = 0, named_other = 0;
  r.run_until(
      [&] {
        if (r.daemon->status_json(json, sizeof json, r.clock.t) > 0 &&
            std::strstr(json, "\"det_code\":\"wrong\"") != nullptr) {
          if (std::strstr(json, "\"det_code_dock\":0,") != nullptr) ++named_0;
          if (std::strstr(json, "\"det_code_dock\":-1,") == nullptr &&
              std::strstr(json, "\"det_code_dock\":0,") == nullptr) {
            ++named_other;
          }
        }
        return false;
      },
      3.0);
  CHECK(named_0 > 10);
  LONGS_EQUAL(0, named_other);
  CHECK(r.daemon->state() != TaskState::kAlign);  // the wrong dock was never taken
}

// CAN error frames (counted by the bus, mirrored by the chassis link) reach the session record as can_error events:
// one per poll that saw new ones, with the totals and how many are new; nothing else changes.
TEST(DockdDaemon, CanErrorFramesAreLoggedWithTheirTotals) {
  Rig r("canerr", false, 1.2, true);
  for (int i = 0; i < 5; ++i) r.tick();
  CHECK_TRUE(r.events("can_error").empty());
  r.link.c.bus_errors = 3;  // e.g. error passive, bus error, bus-off
  r.link.c.bus_off = 1;
  r.tick();
  std::string ev = r.events("can_error");
  STRCMP_CONTAINS("\"bus_errors\":3,\"bus_off\":1,\"new\":3", ev.c_str());
  for (int i = 0; i < 5; ++i) r.tick();  // nothing new: no further event
  ev = r.events("can_error");
  LONGS_EQUAL(1, static_cast<long>(std::count(ev.begin(), ev.end(), '\n')));
  r.link.c.bus_errors = 5;
  r.tick();
  ev = r.events("can_error");
  LONGS_EQUAL(2, static_cast<long>(std::count(ev.begin(), ev.end(), '\n')));
  STRCMP_CONTAINS("\"bus_errors\":5,\"bus_off\":1,\"new\":2", ev.c_str());
  CHECK(r.daemon->state() == TaskState::kNotTasking);
}

// A failed attempt says why in the event log (a retry names its cause): the charger's
// relay stays open for the first attempt, so WAIT_FOR_CHARGE times out into RETRY with charge_not_confirmed; the
// second attempt charges.
TEST(DockdDaemon, RetryEventSaysWhyTheAttemptEnded) {
  Rig r("retry", false, 1.2, true);
  CHECK_TRUE(r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0));
  r.link.relay_broken = true;
  r.host.command(1, 0);
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kRetry; }, 60.0));
  CHECK_EQUAL(182, static_cast<int>(r.daemon->last_status().retry_reason));
  CHECK_EQUAL(0, static_cast<int>(r.daemon->last_status().fault));
  r.link.relay_broken = false;
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kFinishTasking; }, 60.0));
  CHECK_EQUAL(1, r.daemon->last_status().retries);
  const std::string ev = r.events("state");
  CHECK_TEXT(
      ev.find("\"from\":\"WAIT_FOR_CHARGE\",\"to\":\"RETRY\",\"dock_id\":0,\"result\":\"none\","
              "\"reason\":\"charge_not_confirmed\",\"code\":182,\"phase\":\"WAIT_FOR_CHARGE\"}") != std::string::npos,
      ev.c_str());
  // Only the RETRY entry carries a reason.
  int reasons = 0;
  for (std::size_t p = ev.find("\"reason\""); p != std::string::npos; p = ev.find("\"reason\"", p + 1)) ++reasons;
  CHECK_EQUAL(1, reasons);
}

TEST(DockdDaemon, ChassisStaleStopsWithinOneTickFaultsAndResumes) {
  Rig r("chassis");
  r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0);
  r.host.command(1, 0);
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kAlign && !r.wheels_zero(); }, 20.0));
  r.link.silent = true;
  // 200 ms stale limit: the first tick past it commands zero and the task manager faults with 184.
  int ticks = 0;
  while (!r.daemon->chassis_stale() && ticks < 50) {
    r.tick();
    ++ticks;
    if (!r.daemon->chassis_stale()) CHECK_FALSE(r.wheels_zero() && r.daemon->state() == TaskState::kFault);
  }
  CHECK_TRUE(r.daemon->chassis_stale());
  CHECK(ticks >= 10 && ticks <= 12);
  CHECK_TRUE(r.wheels_zero());
  CHECK_EQUAL(184, r.host.last.fault_code);  // the watchdog's code is in the status at once
  // Stale for fault_after_ms (1 s) more: the task manager faults; the wheels stay at zero throughout.
  for (int i = 0; i < 50; ++i) {
    r.tick();
    CHECK_TRUE(r.wheels_zero());
  }
  CHECK_EQUAL(static_cast<int>(TaskState::kFault), static_cast<int>(r.daemon->state()));
  CHECK_EQUAL(184, static_cast<int>(r.daemon->fault()));
  CHECK_EQUAL(184, r.host.last.fault_code);
  for (int i = 0; i < 25; ++i) {
    r.tick();
    CHECK_TRUE(r.wheels_zero());
  }
  // Data returns: after 0.5 s of fresh data the interrupted docking restarts and completes.
  r.link.silent = false;
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kFinishTasking; }, 60.0));
  CHECK_EQUAL(1u, r.daemon->counters().resumes);
  CHECK_EQUAL(1u, r.daemon->inputs().chassis_trips());
}

TEST(DockdDaemon, LidarOutageMidUndockResumesTheBackOff) {
  // Found by the HIL soak on a loaded host: a 185 mid back-off faulted the undocking off the contacts, and the
  // resume's undock was refused as "not docked", leaving the robot in FAULT between the dock and the staging point.
  Rig r("undock");
  r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0);
  r.host.command(1, 0);
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kFinishTasking; }, 60.0));
  r.host.command(3, 0);
  CHECK_TRUE(r.run_until([&] { return !r.chassis->state().contact && !r.wheels_zero(); }, 10.0));
  r.lidar_blocked = true;
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kFault; }, 2.0));
  CHECK_EQUAL(185, static_cast<int>(r.daemon->fault()));
  CHECK_TRUE(r.wheels_zero());
  r.lidar_blocked = false;
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kNotTasking; }, 30.0));
  CHECK_EQUAL(1u, r.daemon->counters().resumes);
  CHECK_EQUAL(static_cast<int>(dockcore::TaskResult::kUndocked), static_cast<int>(r.daemon->last_status().last_result));
  CHECK_FALSE(r.chassis->state().contact);
  CHECK_TRUE(r.wheels_zero());
}

TEST(DockdDaemon, LidarStaleStopsWithinOneTickAndFaults) {
  Rig r("lidar");
  r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0);
  r.host.command(1, 0);
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kAlign && !r.wheels_zero(); }, 20.0));
  r.lidar_blocked = true;
  CHECK_TRUE(r.run_until([&] { return r.daemon->lidar_stale(); }, 1.0));
  CHECK_TRUE(r.wheels_zero());
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kFault; }, 1.5));
  CHECK_TRUE(r.wheels_zero());
  CHECK_EQUAL(185, static_cast<int>(r.daemon->fault()));
  // A stop while faulted forgets the interrupted command: no resume when the lidar returns.
  r.host.command(2, 0);
  r.tick();
  r.lidar_blocked = false;
  r.run_until([] { return false; }, 2.0);
  CHECK_EQUAL(0u, r.daemon->counters().resumes);
  CHECK_EQUAL(static_cast<int>(TaskState::kNotTasking), static_cast<int>(r.daemon->state()));
  CHECK_TRUE(r.wheels_zero());
}

TEST(DockdDaemon, LidarWatchdogDoesNotFlapAtStartUp) {
  // A real sensor's turn reaches dockd a turn and a bit after its first sample (the parser closes it on the next
  // turn's first point): here 130 ms. The first scan alone does not say when its turn ended; taken for ending at
  // its first sample, it would make the lidar fresh and then stale again just before the second scan (a 185 in the
  // status of a docking commanded right after start-up). Once fresh, it must stay fresh.
  Rig r("startup", false, 1.2, true);
  r.scan_lag_us = 130000;
  bool was_fresh = false;
  int flaps = 0;
  for (int i = 0; i < 100; ++i) {  // 2 s
    r.tick();
    if (!r.daemon->lidar_stale())
      was_fresh = true;
    else if (was_fresh)
      ++flaps;
  }
  CHECK_TRUE(was_fresh);
  CHECK_EQUAL(0, flaps);
  CHECK_EQUAL(0u, r.daemon->inputs().lidar_trips());
  CHECK_EQUAL(0u, r.daemon->inputs().late_scans());
  // The watchdog's events say how old the data was: the one that went fresh carries the ages.
  const std::string ev = r.events("watchdog");
  CHECK_TRUE(ev.find("\"which\":\"lidar\",\"stale\":false") != std::string::npos);
  CHECK_TRUE(ev.find("\"turn_end_age_ms\":") != std::string::npos);
}

TEST(DockdDaemon, ScansDeliveredLateDoNotKeepTheLidarFresh) {
  // A reader behind a backlog keeps parsing turns, but their stamps (sensor clock) are old: the stale watchdog must
  // go by when the turn was measured, not when dockd parsed it.
  Rig r("late");
  r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0);
  r.host.command(1, 0);
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kAlign && !r.wheels_zero(); }, 20.0));
  const std::uint32_t scans_before = r.daemon->counters().scans;
  r.scan_lag_us = 600000;
  CHECK_TRUE(r.run_until([&] { return r.daemon->lidar_stale(); }, 0.3));
  CHECK_TRUE(r.wheels_zero());
  r.run_until([] { return false; }, 0.5);
  CHECK_TRUE(r.daemon->lidar_stale());
  CHECK_TRUE(r.wheels_zero());
  CHECK(r.daemon->counters().scans >= scans_before + 4);  // they kept coming...
  CHECK(r.daemon->inputs().late_scans() >= 4);            // ...and were counted as late
  // 0.8 s without a usable scan: held, not faulted; the task manager hears of it once the lidar has been stale for
  // fault_after_ms (1 s), then faults 185. Live scans again resume the docking.
  CHECK_EQUAL(0, static_cast<int>(r.daemon->fault()));
  CHECK_TRUE(r.daemon->state() == TaskState::kAlign);
  CHECK_TRUE(r.run_until([&] { return r.daemon->fault() == dockcore::FaultCode::kLidarStale; }, 0.6));
  CHECK_TRUE(r.wheels_zero());
  r.scan_lag_us = 0;
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kFinishTasking; }, 60.0));
  CHECK_EQUAL(1u, r.daemon->counters().resumes);
}

TEST(DockdDaemon, CanHostCommandsTheTaskManagerRejectsAreCounted) {
  // Fault matrix row host_bad_commands: an unknown command code and an unknown dock id over CAN are rejected by the
  // task manager; the status counter commands_rejected must count them as it counts UDP refusals, and nothing else
  // changes.
  Rig r("canrej");
  r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0);
  const std::uint32_t before = r.daemon->counters().commands_rejected;
  r.host.command(9, 0);  // no such command
  r.tick();
  r.tick();
  r.host.command(1, 9);  // dock 9 is not in the database
  r.tick();
  r.tick();
  CHECK_EQUAL(before + 2, r.daemon->counters().commands_rejected);
  CHECK_EQUAL(static_cast<int>(TaskState::kNotTasking), static_cast<int>(r.daemon->state()));
  CHECK_TRUE(r.wheels_zero());
}

TEST(DockdDaemon, ShortLidarGapHoldsTheRobotAndTheDockingContinues) {
  Rig r("gap");
  r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0);
  r.host.command(1, 0);
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kAlign && !r.wheels_zero(); }, 20.0));
  r.lidar_blocked = true;
  CHECK_TRUE(r.run_until([&] { return r.daemon->lidar_stale(); }, 1.0));
  for (int i = 0; i < 10; ++i) {  // 200 ms more without scans: held at zero, not faulted
    CHECK_TRUE(r.wheels_zero());
    CHECK_EQUAL(static_cast<int>(TaskState::kAlign), static_cast<int>(r.daemon->state()));
    r.tick();
  }
  r.lidar_blocked = false;
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kFinishTasking; }, 60.0));
  CHECK_EQUAL(0u, r.daemon->counters().resumes);
  CHECK_EQUAL(1u, r.daemon->inputs().lidar_trips());
}

TEST(DockdDaemon, UdpFloodStaysConsistentAndUnknownDockIsRejected) {
  Rig r("flood", true);
  r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0);
  sockaddr_in to{};
  const int s = r.udp_client(to);
  auto send = [&](const std::string& m) {
    ::sendto(s, m.data(), m.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
  };
  send("{\"cmd\":\"dock\",\"dock_id\":9,\"seq\":1}");
  r.tick();
  char buf[2048];
  ssize_t n = ::recv(s, buf, sizeof buf - 1, MSG_DONTWAIT);
  CHECK(n > 0);
  buf[n] = 0;
  STRCMP_CONTAINS("\"unknown_dock_id\"", buf);
  CHECK_EQUAL(static_cast<int>(TaskState::kNotTasking), static_cast<int>(r.daemon->state()));
  // 1000 commands/s for 2 s: dock / stop / garbage / status mixed. The state must stay a valid task state, the
  // robot must never move while a stop is the last command, and the loop keeps ticking.
  int seq = 10;
  for (int t = 0; t < 100; ++t) {
    for (int k = 0; k < 20; ++k) {
      switch ((t * 20 + k) % 4) {
        case 0:
          send("{\"cmd\":\"dock\",\"seq\":" + std::to_string(seq++) + "}");
          break;
        case 1:
          send("{\"cmd\":\"stop\",\"seq\":" + std::to_string(seq++) + "}");
          break;
        case 2:
          send("{\"cmd\":\"dock\",\"seq\":");
          break;
        default:
          send("{\"cmd\":\"status\",\"seq\":" + std::to_string(seq++) + "}");
          break;
      }
    }
    r.tick();
    while (::recv(s, buf, sizeof buf, MSG_DONTWAIT) > 0) {
    }
    CHECK(static_cast<int>(r.daemon->state()) <= 9);
  }
  send("{\"cmd\":\"stop\",\"seq\":99999}");
  r.run_until([] { return false; }, 0.5);
  CHECK_EQUAL(static_cast<int>(TaskState::kNotTasking), static_cast<int>(r.daemon->state()));
  CHECK_TRUE(r.wheels_zero());
  CHECK(r.daemon->counters().udp.malformed >= 400);
  CHECK(r.daemon->counters().commands > 100);
  // The status counts every refusal: dockd's and the task manager's plus the link's malformed requests.
  CHECK(r.daemon->commands_rejected_total() >= r.daemon->counters().commands_rejected + 500);
  char st[dockcore::drivers::kMaxHostReply];
  const std::size_t len = r.daemon->status_json(st, sizeof st, 0);
  CHECK(len > 0);
  STRCMP_CONTAINS(("\"commands_rejected\":" + std::to_string(r.daemon->commands_rejected_total()) + ",").c_str(), st);
  ::close(s);
}

// A flood of refused requests reaches the record as at most EventRateLimit::kPerWindow refusal events a second and
// one events_held_back line per window with the rest: each refusal is logged or counted there, none twice.
TEST(DockdDaemon, RefusalFloodIsLoggedAtTheCapAndTheRestCounted) {
  Rig r("refusals", true, 1.2, true);
  r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0);
  sockaddr_in to{};
  const int s = r.udp_client(to);
  const std::uint32_t before = r.daemon->counters().commands_rejected;
  char buf[2048];
  int seq = 1;
  for (int t = 0; t < 150; ++t) {  // 3 s at 1000 unknown-dock requests a second
    for (int k = 0; k < 20; ++k) {
      const std::string m = "{\"cmd\":\"dock\",\"dock_id\":9,\"seq\":" + std::to_string(seq++) + "}";
      ::sendto(s, m.data(), m.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
    }
    r.tick();
    while (::recv(s, buf, sizeof buf, MSG_DONTWAIT) > 0) {
    }
  }
  r.run_until([] { return false; }, 1.1);  // the last window ends and its held-back count is logged
  ::close(s);
  const std::uint32_t refused = r.daemon->counters().commands_rejected - before;
  CHECK_EQUAL(3000u, refused);
  const std::string logged = r.events("command_rejected");
  const std::string held = r.events("events_held_back");
  const long n_logged = std::count(logged.begin(), logged.end(), '\n');
  long n_held = 0;
  for (std::size_t at = held.find("\"count\":"); at != std::string::npos; at = held.find("\"count\":", at + 1)) {
    n_held += std::strtol(held.c_str() + at + 8, nullptr, 10);
  }
  CHECK(n_logged <= 4 * static_cast<long>(dockd::EventRateLimit::kPerWindow));
  CHECK(n_logged >= 3 * static_cast<long>(dockd::EventRateLimit::kPerWindow));
  CHECK_EQUAL(static_cast<long>(refused), n_logged + n_held);
  STRCMP_CONTAINS("\"of\":\"refusals\"", held.c_str());
}

TEST(DockdDaemon, EveryQueuedOrRefusedUdpCommandIsAnsweredOnce) {
  // More task commands per tick than the queue holds: the queued ones are answered with their result when the core
  // takes them, the rest at once with busy; a stop that finds the queue full takes the newest entry's place. Each
  // request gets exactly one reply, whatever order the refusals and the queue's answers come in.
  Rig r("answers", true);
  r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0);
  sockaddr_in to{};
  const int s = r.udp_client(to);
  std::vector<int> replies(2000, 0);
  char buf[2048];
  auto drain = [&]() {
    for (ssize_t n; (n = ::recv(s, buf, sizeof buf - 1, MSG_DONTWAIT)) > 0;) {
      buf[n] = '\0';
      const char* at = std::strstr(buf, "\"seq\":");
      if (at != nullptr) ++replies[static_cast<std::size_t>(std::strtol(at + 6, nullptr, 10))];
    }
  };
  int seq = 1;
  for (int t = 0; t < 40; ++t) {
    for (int k = 0; k < 30; ++k) {  // docks and tests, one stop in every ten
      const char* cmd = k % 10 == 9 ? "stop" : (k % 2 == 0 ? "dock" : "test");
      const std::string m = std::string("{\"cmd\":\"") + cmd + "\",\"seq\":" + std::to_string(seq++) + "}";
      ::sendto(s, m.data(), m.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
    }
    r.tick();
    drain();
  }
  for (int t = 0; t < 20; ++t) {
    r.tick();
    drain();
  }
  ::close(s);
  int none = 0, twice = 0;
  for (int q = 1; q < seq; ++q) {
    if (replies[static_cast<std::size_t>(q)] == 0) ++none;
    if (replies[static_cast<std::size_t>(q)] > 1) ++twice;
  }
  // A stop that displaced a queued command leaves that command unanswered (documented): at most one per stop.
  CHECK(none <= (seq - 1) / 10);
  CHECK_EQUAL(0, twice);
  CHECK(r.daemon->counters().queue_overflows > 0);
}

TEST(DockdDaemon, TeachStoresTargetUsedByLaterDockings) {
  Rig r("teach", true);
  // Dock first, so the robot sits on the charger (as if placed there by hand).
  r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0);
  r.host.command(1, 3);
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kFinishTasking; }, 60.0));
  sockaddr_in to{};
  const int s = r.udp_client(to);
  const std::string m = "{\"cmd\":\"teach\",\"dock_id\":3,\"scans\":8,\"seq\":5}";
  ::sendto(s, m.data(), m.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
  char buf[2048];
  ssize_t n = -1;
  for (int i = 0; i < 200 && n <= 0; ++i) {
    r.tick();
    n = ::recv(s, buf, sizeof buf - 1, MSG_DONTWAIT);
  }
  CHECK(n > 0);
  buf[n] = 0;
  STRCMP_CONTAINS("{\"ok\":true,\"cmd\":\"teach\"", buf);
  const dockd::TaughtTarget* t = r.daemon->state_data().find(3);
  CHECK(t != nullptr);
  CHECK_EQUAL(8, t->scans);
  // The taught target is where the dock is seen from the docked robot: near the nominal one (pads at the
  // contacts, within the controller's docking accuracy).
  const dockcore::Pose2 nom = dockd::nominal_docked_target(r.cfg);
  CHECK(std::fabs(static_cast<double>(t->target.x_m - nom.x_m)) < 0.03);
  CHECK(std::fabs(static_cast<double>(t->target.y_m - nom.y_m)) < 0.03);
  // It survives a restart: a new daemon loads it from the state file.
  dockd::StateData loaded;
  std::string msg;
  CHECK_EQUAL(static_cast<int>(dockd::StateLoadStatus::kOk),
              static_cast<int>(dockd::load_state(r.state_file, loaded, msg)));
  CHECK(loaded.find(3) != nullptr);
  DOUBLES_EQUAL(static_cast<double>(t->target.x_m), static_cast<double>(loaded.find(3)->target.x_m), 1e-6);
  ::close(s);
}

namespace {

/// Sends a teach request for `dock_id` over UDP and ticks until its reply; returns the reply ("" when none came).
std::string teach_over_udp(Rig& r, int dock_id, int scans, int seq) {
  sockaddr_in to{};
  const int s = r.udp_client(to);
  const std::string m = "{\"cmd\":\"teach\",\"dock_id\":" + std::to_string(dock_id) +
                        ",\"scans\":" + std::to_string(scans) + ",\"seq\":" + std::to_string(seq) + "}";
  ::sendto(s, m.data(), m.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
  char buf[2048];
  ssize_t n = -1;
  for (int i = 0; i < 400 && n <= 0; ++i) {
    r.tick();
    n = ::recv(s, buf, sizeof buf - 1, MSG_DONTWAIT);
  }
  ::close(s);
  if (n <= 0) return "";
  buf[n] = 0;
  return buf;
}

}  // namespace

// Two docks of one shape, told apart by their tape (two-docks.toml): dock 3 is configured without stripes. On the
// charger of the taped dock, teach reads its code (the simulated stripes within a few millimetres) and stores it with
// the target; a later docking of dock 3 reads that code. Dock 0's profile carries its own stripes: its teach stores
// none and says whether what it read agrees.
TEST(DockdDaemon, TeachRecordsTheDocksCodeAndDockingsReadIt) {
  Rig r("teach_code", true, 1.2, false, false, "two-docks.toml",
        [](dockd::DockdConfig& c) { c.docks[1].profile.reflector_count = 0; });
  const dockcore::DockProfile taped = r.cfg.docks[0].profile;
  CHECK_EQUAL(2u, taped.reflector_count);
  CHECK_TRUE(r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0));
  r.host.command(1, 0);
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kFinishTasking; }, 60.0));
  CHECK_TRUE(r.chassis->state().contact);

  // Dock 0's profile has its own stripes: kept, the teach reports the agreement.
  std::string reply = teach_over_udp(r, 0, 10, 7);
  STRCMP_CONTAINS("{\"ok\":true,\"cmd\":\"teach\"", reply.c_str());
  STRCMP_CONTAINS("\"code\":\"profile\",\"stripes\":[[1,", reply.c_str());
  STRCMP_CONTAINS("\"code_matches\":true", reply.c_str());
  CHECK_EQUAL(0, r.daemon->state_data().find(0)->stripe_count);

  // Dock 3, the same dock without stripes in its profile: the code is taught.
  reply = teach_over_udp(r, 3, 10, 8);
  STRCMP_CONTAINS("\"code\":\"taught\",\"stripes\":[[1,", reply.c_str());
  STRCMP_CONTAINS("\"code_spread_mm\":", reply.c_str());
  const dockd::TaughtTarget* t = r.daemon->state_data().find(3);
  CHECK(t != nullptr);
  CHECK_EQUAL(taped.reflector_count, t->stripe_count);
  for (std::size_t q = 0; q < t->stripe_count; ++q) {
    CHECK_EQUAL(taped.reflectors[q].segment, t->stripes[q].segment);
    // Each edge lies between two beams 4 mm apart at the docked range, plus what is left of the pose's spread.
    CHECK(std::fabs(static_cast<double>(t->stripes[q].from_m - taped.reflectors[q].from_m)) < 0.005);
    CHECK(std::fabs(static_cast<double>(t->stripes[q].to_m - taped.reflectors[q].to_m)) < 0.005);
  }
  CHECK(t->code_scans >= 6);
  // One scan's edges move with its pose (σ 10 mm lidar: the detections spread ~5 mm) and its beams (4 mm apart).
  CHECK(t->code_spread_m < 0.010);
  // In the state file with the target.
  dockd::StateData loaded;
  std::string msg;
  CHECK_EQUAL(static_cast<int>(dockd::StateLoadStatus::kOk),
              static_cast<int>(dockd::load_state(r.state_file, loaded, msg)));
  CHECK_EQUAL(t->stripe_count, loaded.find(3)->stripe_count);

  // Off the charger and back, to dock 3: the estimator reads the taught code.
  r.host.command(3, 0);
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kNotTasking; }, 40.0));
  bool read = false;
  CHECK_TRUE(r.dock_reading_code(3, 60.0, &read));
  CHECK_TRUE(read);
  CHECK_TRUE(r.chassis->state().charging);

  // A lidar whose intensity is flat (an RPLIDAR in express mode): teach records no code and says why.
  r.sc.lidar.intensity_output = docksim::IntensityOutput::kConstant;
  char json[dockcore::drivers::kMaxHostReply];
  CHECK_TRUE(r.run_until(
      [&] {
        return r.daemon->status_json(json, sizeof json, r.clock.t) > 0 &&
               std::strstr(json, "\"lidar_intensity\":\"flat\"") != nullptr;
      },
      10.0));
  reply = teach_over_udp(r, 3, 10, 9);
  STRCMP_CONTAINS("{\"ok\":true,\"cmd\":\"teach\"", reply.c_str());
  STRCMP_CONTAINS("\"code\":\"intensity_unusable\"", reply.c_str());
  CHECK_EQUAL(0, r.daemon->state_data().find(3)->stripe_count);
}

// A state file with a bad code line and a code that does not fit its dock's profile: each reported at its line, the
// targets loaded, the misfit code not applied.
TEST(DockdDaemon, AStateFilesBadCodeIsReportedAtItsLine) {
  Rig r("code_misfit", false, 1.2, true, false, nullptr, [](dockd::DockdConfig& c) {
    const std::string body = std::string("dockd-state 1\n") +
                             "target 0 0.225000000 0.000000000 3.141592654 20 0.001000 0\n" +
                             "code 0 20 0.001 1 1 0.20 0.205\n" +  // shorter than 1 cm
                             "target 3 0.225000000 0.000000000 3.141592654 20 0.001000 0\n" +
                             "code 3 20 0.001 1 5 0.0 0.1\n";  // plate-v has segments 0-2
    char crc[32];
    std::snprintf(crc, sizeof crc, "crc32 %08x\n", dockd::crc32_ieee(body.data(), body.size()));
    std::FILE* f = std::fopen(c.state_file.c_str(), "w");
    std::fputs((body + crc).c_str(), f);
    std::fclose(f);
  });
  const std::string ev = r.events("state_file");
  STRCMP_CONTAINS((r.state_file + ":3: bad code line 'code 0 20 0.001 1 1 0.20 0.205'").c_str(), ev.c_str());
  STRCMP_CONTAINS((r.state_file + ":5: the taught code of dock 3 does not fit its profile (reflector stripe on a "
                                  "segment the outline does not have): not applied")
                      .c_str(),
                  ev.c_str());
  CHECK(r.daemon->state_data().find(0) != nullptr);
  CHECK_EQUAL(1, r.daemon->state_data().find(3)->stripe_count);
  char json[dockcore::drivers::kMaxHostReply];
  CHECK(r.daemon->status_json(json, sizeof json, r.clock.t) > 0);
  STRCMP_CONTAINS("\"det_code\":\"none\"", json);  // dock 0: no code applied
}

// SIGHUP config reload (docs/dockd.md, "Config reload").
TEST(DockdDaemon, ConfigReloadAppliesValidRejectsBadAndWaitsForIdle) {
  Rig r("reload");
  CHECK_TRUE(r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0));
  std::string msg;

  // Valid, runtime keys only, robot idle: in effect at once.
  dockd::DockdConfig next = r.cfg;
  next.source = "good.toml";
  next.log_level = dockd::LogLevel::kError;  // the reload applies [log] level to stderr: keep the test quiet
  next.watchdog.chassis_stale_ms = 300;
  next.smooth.v_max_mps = static_cast<dockcore::Real>(0.15);
  CHECK_EQUAL(static_cast<int>(dockd::ReloadResult::kApplied),
              static_cast<int>(r.daemon->request_reload(next, r.clock.t, msg)));
  STRCMP_CONTAINS("good.toml: config reloaded", msg.c_str());
  CHECK_EQUAL(300u, r.daemon->config().watchdog.chassis_stale_ms);
  CHECK_EQUAL(1u, r.daemon->counters().config_reloads);

  // A file that does not parse: rejected with file:line:col, nothing changes.
  const std::string bad = "/tmp/dockd_test_" + std::to_string(::getpid()) + "_bad.toml";
  {
    std::FILE* f = std::fopen(bad.c_str(), "w");
    std::fputs("[watchdog]\nchassis_stale_ms = 500\nlidar_stale_ms = \"fast\"\n", f);
    std::fclose(f);
  }
  CHECK_EQUAL(static_cast<int>(dockd::ReloadResult::kRejected),
              static_cast<int>(r.daemon->reload_from_file(bad, r.clock.t, msg)));
  STRCMP_CONTAINS((bad + ":3:18: watchdog.lidar_stale_ms must be an integer").c_str(), msg.c_str());
  STRCMP_CONTAINS("running configuration stays", msg.c_str());
  CHECK_EQUAL(300u, r.daemon->config().watchdog.chassis_stale_ms);
  std::remove(bad.c_str());

  // A restart-only key: the whole reload is refused, the runtime keys in it included.
  dockd::DockdConfig other = r.daemon->config();
  other.source = "restart.toml";
  other.can_interface = "vcan7";
  other.watchdog.chassis_stale_ms = 400;
  CHECK_EQUAL(static_cast<int>(dockd::ReloadResult::kRejected),
              static_cast<int>(r.daemon->request_reload(other, r.clock.t, msg)));
  STRCMP_CONTAINS("restart-only keys changed (can.interface)", msg.c_str());
  CHECK_EQUAL(300u, r.daemon->config().watchdog.chassis_stale_ms);
  STRCMP_EQUAL("can0", r.daemon->config().can_interface.c_str());
  CHECK_EQUAL(2u, r.daemon->counters().config_reloads_rejected);

  // Mid-docking: valid but pending; the motion goes on unchanged until the task is idle again.
  r.host.command(1, 0);
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kAlign && !r.wheels_zero(); }, 20.0));
  dockd::DockdConfig slow = r.daemon->config();
  slow.source = "slow.toml";
  slow.smooth.v_max_mps = static_cast<dockcore::Real>(0.05);
  slow.watchdog.chassis_stale_ms = 250;
  CHECK_EQUAL(static_cast<int>(dockd::ReloadResult::kPending),
              static_cast<int>(r.daemon->request_reload(slow, r.clock.t, msg)));
  STRCMP_CONTAINS("pending until the task is idle (state ALIGN)", msg.c_str());
  CHECK_TRUE(r.daemon->reload_pending());
  for (int i = 0; i < 10; ++i) {
    r.tick();
    CHECK_EQUAL(static_cast<int>(TaskState::kAlign), static_cast<int>(r.daemon->state()));
    CHECK_FALSE(r.wheels_zero());
  }
  CHECK_EQUAL(300u, r.daemon->config().watchdog.chassis_stale_ms);
  char json[dockcore::drivers::kMaxHostReply];
  CHECK(r.daemon->status_json(json, sizeof json - 64, r.clock.t) > 0);  // still fits the status reply
  // The latest scan's decision: the dock in view is accepted, with its evidence above the threshold and each cue.
  STRCMP_CONTAINS("\"det_found\":true,\"det_evidence_nats\":", json);
  STRCMP_CONTAINS("\"det_reject\":\"none\",", json);
  STRCMP_CONTAINS("\"dock_confirmed\":true,", json);
  // Four scans so far: too few for the intensity check to judge the sensor.
  STRCMP_CONTAINS("\"lidar_intensity\":\"unknown\",", json);
  const char* ev = std::strstr(json, "\"det_evidence_nats\":");
  CHECK(ev != nullptr && std::atof(ev + 20) >= 3.5);
  CHECK(std::strstr(json, "\"det_cues_nats\":[") != nullptr);
  STRCMP_CONTAINS("\"config_reloads\":1,\"config_reloads_rejected\":2", json);
  STRCMP_CONTAINS("\"config_reload_pending\":true", json);
  r.host.command(2, 0);  // stop: idle -> the pending reload applies on that tick
  CHECK_TRUE(r.run_until([&] { return !r.daemon->reload_pending(); }, 1.0));
  CHECK_EQUAL(static_cast<int>(TaskState::kNotTasking), static_cast<int>(r.daemon->state()));
  CHECK_EQUAL(250u, r.daemon->config().watchdog.chassis_stale_ms);
  CHECK_EQUAL(2u, r.daemon->counters().config_reloads);
  // The rebuilt core docks with the new parameters.
  r.host.command(1, 0);
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kFinishTasking; }, 90.0));
}

// dockd stalls around a 0.5 m push and then drops the late scans: the core's scan-age backstop faults 185, the
// watchdog resume re-issues the dock command once scans are fresh, and the new task restarts the filter at the pushed
// pose. Pushed (sideways 0.5 m, or turned 40 deg about the dock) during a gap of late scans, the resumed task must
// report the push (178/179) and not dock.
TEST(DockdDaemon, PushDuringALateScanGapIsReportedAfterTheResume) {
  const double gaps_s[] = {0.6, 1.0, 2.0};
  for (const double gap_s : gaps_s) {
    for (int turned = 0; turned <= 1; ++turned) {
      char what[64];
      std::snprintf(what, sizeof what, "gap %.1f s %s", gap_s, turned != 0 ? "turned" : "sideways");
      Rig r("pushgap");
      r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0);
      r.host.command(1, 0);
      CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kAlign && !r.wheels_zero(); }, 20.0));
      r.run_until([] { return false; }, 0.3);
      r.scan_lag_us = 600000;  // every scan arrives measured 0.6 s ago: dropped as late
      const int n = static_cast<int>(gap_s / 0.02 + 0.5);
      for (int i = 0; i < n; ++i) {
        if (i == n / 2) {
          dockcore::Pose2 p = r.chassis->state().true_pose;
          if (turned != 0) {
            const dockcore::Pose2 dock = r.sc.dock_pose;
            p = dock.compose(dockcore::Pose2{0, 0, dockcore::deg_to_rad(static_cast<dockcore::Real>(40))})
                    .compose(dock.inverse().compose(p));
          } else {
            p = p.compose(dockcore::Pose2{0, 0.5, 0});
          }
          r.chassis->set_true_pose(p);
        }
        r.tick();
      }
      r.scan_lag_us = 0;
      const int want = turned != 0 ? 179 : 178;
      CHECK_TEXT(r.run_until(
                     [&] {
                       return static_cast<int>(r.daemon->fault()) == want ||
                              r.daemon->state() == TaskState::kFinishTasking;
                     },
                     30.0),
                 what);
      CHECK_EQUAL_TEXT(want, static_cast<int>(r.daemon->fault()), what);
      CHECK_TEXT(r.wheels_zero(), what);
    }
  }
}

// A chassis outage (184, resumed when the feedback returns) keeps the pre-outage dock as the push reference too
// (docs/faults.md, 178): the wheels are held meanwhile, so a robot that still stands where it stopped docks on, and
// one pushed during the outage is reported. Odometry does not see a push while the feedback is silent.
TEST(DockdDaemon, ChassisOutageResumeKeepsThePushReference) {
  for (int pushed = 0; pushed <= 1; ++pushed) {
    const char* what = pushed != 0 ? "pushed" : "not pushed";
    Rig r("chassisgap");
    r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0);
    r.host.command(1, 0);
    CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kAlign && !r.wheels_zero(); }, 20.0));
    r.run_until([] { return false; }, 0.3);
    r.link.silent = true;
    CHECK_TRUE_TEXT(r.run_until([&] { return r.daemon->state() == TaskState::kFault; }, 3.0), what);
    CHECK_EQUAL_TEXT(184, static_cast<int>(r.daemon->fault()), what);
    if (pushed != 0) r.chassis->set_true_pose(r.chassis->state().true_pose.compose(dockcore::Pose2{0, 0.5, 0}));
    r.run_until([] { return false; }, 0.5);
    r.link.silent = false;
    if (pushed != 0) {
      CHECK_TEXT(r.run_until(
                     [&] {
                       return static_cast<int>(r.daemon->fault()) == 178 ||
                              r.daemon->state() == TaskState::kFinishTasking;
                     },
                     30.0),
                 what);
      CHECK_EQUAL_TEXT(178, static_cast<int>(r.daemon->fault()), what);
      CHECK_TEXT(r.wheels_zero(), what);
    } else {
      CHECK_TEXT(r.run_until([&] { return r.daemon->state() == TaskState::kFinishTasking; }, 60.0), what);
    }
    CHECK_EQUAL_TEXT(1u, r.daemon->counters().resumes, what);
  }
}

// A camera that stops delivering frames mid-docking is reported (status flag, counter, watchdog event) and changes
// nothing else: the docking goes on with the lidar alone — no hold, no fault, no retry.
TEST(DockdDaemon, ACameraStallIsReportedAndTheDockingGoesOnWithTheLidar) {
  Rig r("camstall", false, 1.2, true, true);
  CHECK_TRUE(r.run_until([&] { return !r.daemon->lidar_stale() && !r.daemon->chassis_stale(); }, 1.0));
  CHECK_FALSE(r.daemon->camera_stalled());
  r.host.command(1, 0);
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kAlign && !r.wheels_zero(); }, 20.0));
  r.camera_live = false;
  const std::uint64_t last = r.frames.last;
  CHECK_TRUE(r.run_until([&] { return r.daemon->camera_stalled(); }, 1.0));
  CHECK(r.clock.t - last <= 220000);  // stall_ms (200) plus at most one tick
  CHECK_FALSE(r.wheels_zero());       // still driving
  CHECK_TRUE(r.run_until([&] { return r.daemon->state() == TaskState::kFinishTasking; }, 60.0));
  CHECK_TRUE(r.chassis->state().charging);
  CHECK_TRUE(r.daemon->camera_stalled());
  CHECK_EQUAL(1u, r.daemon->counters().camera_stalls);
  CHECK_EQUAL(0u, r.daemon->counters().resumes);
  CHECK_EQUAL(0u, r.daemon->inputs().lidar_trips());
  CHECK_EQUAL(0, static_cast<int>(r.daemon->last_status().retries));
  const std::string ev = r.events("watchdog");
  CHECK_TRUE(ev.find("\"which\":\"camera\",\"stale\":true") != std::string::npos);
  CHECK_TRUE(ev.find("\"camera_stalls\":1") != std::string::npos);
}
