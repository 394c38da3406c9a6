#pragma once
/// @file dockd's logic, free of OS event handling so a host test can run it with in-memory fakes: the lidar, the
/// chassis link, the host links (CAN host frames, UDP JSON), the camera and the clock come in as HAL references;
/// main.cpp only builds the real drivers and runs the epoll loop around it.
///
/// Per control tick (on_tick, 50 Hz): chassis poll (its wheel speeds into the core's odometry), lidar scans
/// (Dockcore::on_scan with their stamps), camera, host requests (at most one task command per tick reaches the task
/// manager; the rest wait in a bounded queue), the core's input watch (Dockcore::check_inputs: its changes are logged),
/// Dockcore::tick (which holds the drive on stale input and shapes the twist into wheel speeds), send_wheels, charge
/// request, status (CAN + UDP stream at status_rate_hz and on every change), event log, teach progress, tick-period
/// statistics. Stale lidar or chassis → zero wheel command on that same tick and the watchdog fault code in the
/// status; data back within fault_after_ms → the task continues; stale longer → the task manager faults (185 / 184)
/// and, once the data has been fresh for 0.5 s, dockd re-issues the interrupted command (docs/dockd.md, "Watchdogs").
/// Allocation: the object is large (Dockcore) — create it once at start-up (heap); no allocation per tick.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "config.hpp"
#include "counters.hpp"
#include "dockcore/control/controllers.hpp"
#include "dockcore/dockcore.hpp"
#include "dockcore/drivers/loop_record.hpp"
#include "dockcore/hal/camera.hpp"
#include "dockcore/hal/chassis.hpp"
#include "dockcore/hal/clock.hpp"
#include "dockcore/hal/host_link.hpp"
#include "dockcore/hal/lidar.hpp"
#include "dockcore/hal/log_sink.hpp"
#include "events.hpp"
#include "host_protocol.hpp"
#include "learned_file.hpp"
#include "state_file.hpp"
#include "status.hpp"
#include "teach.hpp"

namespace dockd {

/// What the daemon talks to, all HAL interfaces. lidar, chassis and clock are required; the rest may be null.
struct DaemonIo {
  dockcore::hal::LidarSource* lidar = nullptr;
  dockcore::hal::ChassisLink* chassis = nullptr;
  /// CAN host command / status frames; its host_commands_rejected() (replays, out-of-order) is in the status.
  dockcore::hal::HostLink* can_host = nullptr;
  dockcore::hal::HostRequestLink* udp_host = nullptr;       ///< JSON requests and the status stream.
  dockcore::hal::CameraTargetSource* camera = nullptr;      ///< The UDP camera datagram (external detectors).
  dockcore::hal::CameraTargetSource* camera_own = nullptr;  ///< dockd's own capture + detector (docs/camera.md).
  /// dockd's own detector's tag poses, fused into the dock filter (docs/camera.md, "Fusion"); null: no fusion.
  dockcore::hal::TagPoseSource* tags = nullptr;
  /// dockd's own camera's frame arrivals, for the stall watchdog (camera_stalled); null: no watchdog.
  const dockcore::hal::CameraFrameMonitor* camera_frames = nullptr;
  /// dockd's own camera's state, for the status fields camera_connected, camera_frames, …; null: none. The status
  /// goes without them when they do not fit.
  const dockcore::hal::CameraStatusSource* camera_status = nullptr;
  const dockcore::hal::Clock* clock = nullptr;
  dockcore::hal::LogSink* event_log = nullptr;  ///< JSON-lines event log.
  /// Also print events at or above this level to stderr (journal). kError..kDebug.
  LogLevel stderr_level = LogLevel::kInfo;
};

/// Control-loop timing, measured between consecutive on_tick calls.
struct TickStats {
  std::uint64_t ticks = 0;
  std::uint64_t last_period_us = 0;
  std::uint64_t worst_period_us = 0;  ///< Longest period since start.
  std::uint64_t overruns = 0;         ///< Periods longer than 1.5 × the nominal 20 ms.
  std::uint64_t worst_work_us = 0;    ///< Longest time spent inside on_tick (clock before and after).
};

/// What a config reload request came to (docs/dockd.md, "Config reload").
enum class ReloadResult : std::uint8_t {
  kApplied = 0,   ///< In effect now (the task was idle).
  kPending = 1,   ///< Valid; applied on the first tick the task is idle (NOT_TASKING, no teach, no resume pending).
  kRejected = 2,  ///< Invalid or changes a restart-only key: nothing changed; the message says why.
};

/// The daemon: the wiring of the inputs into the core, the tick, reload and the status. The host protocol is its
/// HostProtocol member, which asks the daemon for what a request needs through HostActions; teach is its Teacher
/// member, which asks through TeachHooks.
class Daemon final : private HostActions, private TeachHooks {
 public:
  /// `config` is copied. Call start() before anything else.
  Daemon(const DockdConfig& config, const DaemonIo& io);
  ~Daemon();

  /// Loads the state file (taught targets; a corrupt file is reported and the backup used), configures Dockcore
  /// for the default dock, logs "start". False + message when the core refuses the configuration.
  bool start(std::string& error);

  /// One control tick at CLOCK_MONOTONIC `now_us`. Bounded cost (see file comment).
  void on_tick(std::uint64_t now_us);
  /// Readiness hints from the event loop: drain that source now (the tick drains everything anyway).
  void on_lidar_readable(std::uint64_t now_us);
  void on_chassis_readable(std::uint64_t now_us);
  void on_host_readable(std::uint64_t now_us);
  void on_camera_readable(std::uint64_t now_us);
  /// The camera target the controllers get: the newest from the camera sources (invalid until one arrived).
  const dockcore::CameraTarget& camera_target() const { return camera_; }

  /// Stop path (SIGTERM/SIGINT, fatal errors, end of tests): sends `frames` zero wheel commands back to back
  /// (main spaces them one tick apart by calling this once per frame) and logs the reason once. O(frames).
  void send_zero(std::uint64_t now_us, int frames = 1);
  /// Logs the shutdown event (reason) once; the caller sends the zero frames.
  void log_shutdown(std::uint64_t now_us, const char* reason);
  /// Finishes `e` and writes it to the event log (and stderr at `level` or above); one that did not fit is counted
  /// in counters().events_too_long instead.
  void log_event(EventLine& e, LogLevel level = LogLevel::kInfo) override;

  /// SIGHUP: reads `path` like --check-config (parse + validation), applies `adjust` (the command-line overrides)
  /// and hands the result to request_reload(). A file that does not parse or validate is rejected with its
  /// "file:line:column: message" in `message`, the event log (event config_reload) and stderr; the running
  /// configuration is untouched. Allocates (parsing); never called from the tick.
  ReloadResult reload_from_file(const std::string& path, std::uint64_t now_us, std::string& message,
                                const std::function<void(DockdConfig&)>& adjust = {});
  /// Takes a parsed, validated config. Rejected when a restart-only key differs from the running config
  /// (restart_only_changes) — all or nothing. Otherwise applied at once when the task is idle, else pending until
  /// the first idle tick (a newer request replaces a pending one). Never changes a running motion. Allocates.
  ReloadResult request_reload(const DockdConfig& next, std::uint64_t now_us, std::string& message);
  bool reload_pending() const { return pending_cfg_ != nullptr; }
  const DockdConfig& config() const override { return cfg_; }

  // Introspection (tests, status).
  dockcore::TaskState state() const;
  dockcore::FaultCode fault() const;
  const dockcore::TaskStatus& last_status() const { return last_out_.status; }
  const dockcore::hal::WheelCommand& last_wheels() const { return last_wheels_; }
  bool lidar_stale() const { return core_->inputs().lidar_stale(); }
  bool chassis_stale() const { return core_->inputs().chassis_stale(); }
  /// The core's input watch: staleness, late scans, the watchdogs' trips. O(1).
  const dockcore::InputWatch& inputs() const { return core_->inputs(); }
  /// The own camera delivered no frame for [camera.device] stall_ms (false without DaemonIo::camera_frames). It
  /// holds nothing and faults nothing: the docking goes on with the lidar.
  bool camera_stalled() const { return camera_stalled_; }
  const TickStats& tick_stats() const { return stats_; }
  const DaemonCounters& counters() const { return counters_; }
  const dockcore::Pose2& odom_pose() const { return core_->odometry().pose(); }
  const StateData& state_data() const { return state_; }
  bool teaching() const { return teach_.active(); }
  /// The profile currently configured (after any taught/configured target correction) and its dock id.
  std::uint16_t active_dock_id() const override { return active_dock_; }
  /// Current status as one JSON object (no newline). Returns the length (0 when it does not fit). O(1).
  std::size_t status_json(char* buf, std::size_t size, std::uint64_t now_us) const;
  /// The status's fields, written into `w` (status_json and the status reply); optional groups (counters, tag
  /// fusion, camera) only when they fit.
  void status_fields(JsonWriter& w, std::uint64_t now_us) const override;
  /// The camera part of the status (`"part":"camera"`): the groups status_fields drops when full, always whole.
  void camera_fields(JsonWriter& w) const override;
  /// The counters part of the status (`"part":"counters"`): the group status_fields drops when full, always whole.
  void counter_fields(JsonWriter& w, std::uint64_t now_us) const override;
  /// Every host command refused, whatever refused it: dockd and the task manager (counters().commands_rejected)
  /// plus the UDP datagrams that did not parse (malformed, unknown command, bad field, too long). The status field
  /// `commands_rejected`. O(1).
  std::uint32_t commands_rejected_total() const { return host_.commands_rejected_total(); }

 private:
  /// Every value of the main status at `now_us`, gathered from the members (write_status writes them). As
  /// code_dock_id().
  StatusValues status_values(std::uint64_t now_us) const;
  /// The camera part's values: the groups of the inputs dockd has. O(1).
  CameraValues camera_values() const;
  /// The dock database id whose reflector code the latest scan read: the active dock when it was found with its
  /// code, another dock of its outline whose code a refused candidate (wrong_code) reads, else -1. O(beams of the
  /// dock's span · profile segments + docks).
  int code_dock_id() const;
  void poll_chassis(std::uint64_t now_us);
  void poll_lidar(std::uint64_t now_us);
  void poll_camera(std::uint64_t now_us);
  // HostActions: what the host protocol asks of the daemon.
  dockcore::SubmitResult submit(dockcore::HostCommandType type, std::uint16_t dock_id, std::uint32_t token,
                                std::uint32_t& displaced) override;
  void start_teach(const HostRequest& r, std::uint64_t now_us) override;
  void cancel_teach(std::uint64_t now_us) override;
  // TeachHooks: what the teach asks of the daemon.
  /// Configures Dockcore for `dock_id` (profile corrected by its taught / configured target). Resets the task
  /// manager: only while idle.
  bool configure_core(std::uint16_t dock_id, bool raw_profile) override;
  /// Puts `t` into the state and saves the state file; the state is kept as it was when the file cannot be saved.
  bool store_target(const TaughtTarget& t, std::string& error) override;
  void reply(const HostRequest& r, const char* json, std::size_t len) override;
  void reply_error(const HostRequest& r, HostErrorCode code, const char* message) override;
  void watchdogs(std::uint64_t now_us);
  /// The own camera's stall watchdog (part of watchdogs): sets camera_stalled_, counts and logs its changes.
  void camera_watchdog(std::uint64_t now_us);
  void publish_status(std::uint64_t now_us);
  void send_wheels(const dockcore::hal::WheelCommand& w);
  void emit_event(LogLevel level, const char* line, std::size_t len);
  void build_core();
  /// The active controller and every controller's parameters, as the loop record keeps them. O(1).
  dockcore::drivers::LoopController loop_controller() const;
  /// Hands the core the learned file's state when it was learned on this configuration's lidar mount and drive
  /// (records the hand-over for replay); reports either way in the `learned` event. O(kDockIds).
  void restore_learned_state(std::uint64_t now_us);
  /// At the end of a task: when the core's learned state differs from the one kept, saves it in the learned file
  /// (with this configuration's mount and drive) and keeps it; a failed save is reported and tried again at the next
  /// end. No heap. O(kDockIds), plus the file's write when it changed.
  void keep_learned_state(std::uint64_t now_us);
  bool reload_can_apply() const;
  bool apply_reload(std::uint64_t now_us, std::string& message);
  void log_reload(std::uint64_t now_us, const char* result, const std::string& message, LogLevel level);

  DockdConfig cfg_;
  DaemonIo io_;
  dockcore::ControllerSet controllers_;
  dockcore::DockingController* controller_ = nullptr;  ///< The configured one of controllers_.
  /// Seed 000's detector, allocated once when a dock of the database picks it; outlives every core it is attached to.
  std::unique_ptr<dockcore::BreakpointDetector> breakpoint_;
  std::unique_ptr<dockcore::Dockcore> core_;
  dockcore::DockcoreConfig core_cfg_{};
  StateData state_;
  /// The learned file (LearnedPaths::beside the state file), what it held at start, and what dockd last kept: the
  /// file's state restored for this configuration, or the core's at start.
  LearnedPaths learned_paths_;
  LearnedState learned_file_{};
  bool have_learned_file_ = false;
  dockcore::DockcoreBase::Learned kept_learned_{};
  char learned_buf_[kMaxLearnedFileBytes] = {};
  std::uint16_t active_dock_ = 0;
  bool active_raw_ = false;

  // Chassis feedback (the odometry is the core's).
  dockcore::hal::ChassisFeedback fb_{};

  // Camera.
  dockcore::CameraTarget camera_{};

  // Watchdogs and resume.
  bool camera_stalled_ = false, prev_camera_stalled_ = false;
  std::uint64_t camera_watch_from_us_ = 0;  ///< First watchdog tick: a camera that never delivers stalls from here.
  bool started_ = false;
  std::uint64_t start_us_ = 0;

  // Output.
  dockcore::TickOutput last_out_{};
  dockcore::hal::WheelCommand last_wheels_{};
  bool charge_requested_ = false;
  std::uint32_t charge_refresh_ = 0;
  std::uint64_t next_status_us_ = 0;
  dockcore::TaskStatus prev_status_{};
  bool prev_status_valid_ = false;
  bool prev_lidar_stale_ = true, prev_chassis_stale_ = true;
  std::uint32_t reported_bus_errors_ = 0;  ///< The chassis link's bus_errors when the last can_error event went out.
  std::uint32_t reported_bus_off_ = 0;     ///< Its bus_off then.

  TickStats stats_{};
  std::uint64_t prev_tick_us_ = 0;
  DaemonCounters counters_{};
  HostProtocol host_;  ///< The host links: requests, replies, the status on both links.
  Teacher teach_;      ///< The running teach, if any.
  bool shutdown_logged_ = false;
  std::unique_ptr<DockdConfig> pending_cfg_;  ///< A validated reload waiting for an idle task.
  /// [record] loop: every call into the core, for dock-sim replay (null when off).
  std::unique_ptr<dockcore::drivers::LoopRecordWriter> loop_record_;
  bool loop_record_full_logged_ = false;
};

/// Short stable name of a task result ("none", "docked", ...). Never null.
const char* to_string_result(dockcore::TaskResult r);

}  // namespace dockd
