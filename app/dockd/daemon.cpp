#include "daemon.hpp"
#include "daemon_internal.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>

#include "dockcore/control/kinematics.hpp"

namespace dockd {

const char* to_string_result(dockcore::TaskResult r) {
  switch (r) {
    case dockcore::TaskResult::kNone:
      return "none";
    case dockcore::TaskResult::kDocked:
      return "docked";
    case dockcore::TaskResult::kUndocked:
      return "undocked";
    case dockcore::TaskResult::kCancelled:
      return "cancelled";
    case dockcore::TaskResult::kFaulted:
      return "faulted";
  }
  return "?";
}

Daemon::Daemon(const DockdConfig& config, const DaemonIo& io)
    : cfg_(config),
      io_(io),
      controllers_(config.seed000, config.seed004, config.seed003, config.smooth),
      host_(io.udp_host, io.can_host, *this, counters_),
      teach_(cfg_, *this) {
  build_core();
}

dockcore::drivers::LoopController Daemon::loop_controller() const {
  dockcore::drivers::LoopController c;
  std::snprintf(c.name, sizeof c.name, "%s", controller_->name());
  c.seed000 = cfg_.seed000;
  c.seed004 = cfg_.seed004;
  c.seed003 = cfg_.seed003;
  c.smooth = cfg_.smooth;
  return c;
}

void Daemon::build_core() {
  controllers_ = dockcore::ControllerSet(cfg_.seed000, cfg_.seed004, cfg_.seed003, cfg_.smooth);
  controller_ = controllers_.by_name(cfg_.controller.c_str());
  if (controller_ == nullptr) controller_ = &controllers_.smooth;  // the config validates the name
  core_ = std::make_unique<dockcore::Dockcore>(*controller_);
  for (const DockEntry& d : cfg_.docks) {
    if (d.detector == dockcore::DockDetector::kBreakpoint && !breakpoint_) {
      breakpoint_ = std::make_unique<dockcore::BreakpointDetector>();
    }
  }
  core_->attach_breakpoint(breakpoint_.get());
  core_cfg_ = dockcore::DockcoreConfig{};
  core_cfg_.estimator = cfg_.estimator;
  core_cfg_.task = cfg_.task;
  core_cfg_.footprint = cfg_.footprint;
  core_cfg_.lidar_mount = cfg_.lidar_mount;
  core_cfg_.drive = cfg_.drive;
  core_cfg_.limits = cfg_.limits;
  core_cfg_.control_period_s = static_cast<Real>(kNominalTickUs) * static_cast<Real>(1e-6);
  core_cfg_.watchdog = cfg_.watchdog;
  core_cfg_.deadband = cfg_.deadband;
  core_cfg_.intensity = cfg_.intensity;
  // The tag fusion: the model's keys, and the camera's mount, focal length and tag size (configure_core adds the
  // active dock's tag).
  core_cfg_.tag = cfg_.tag_fusion;
  if (cfg_.camera_device.enabled) {
    const CameraMount& m = cfg_.camera_device.mount;
    core_cfg_.tag.mount = dockcore::CameraMount3{static_cast<Real>(m.x_m),       static_cast<Real>(m.y_m),
                                                 static_cast<Real>(m.z_m),       static_cast<Real>(m.yaw_rad),
                                                 static_cast<Real>(m.pitch_rad), static_cast<Real>(m.roll_rad)};
    core_cfg_.tag.fx_px = static_cast<Real>(cfg_.camera_device.tag.intrinsics.fx_px);
    core_cfg_.tag.tag_size_m = static_cast<Real>(cfg_.camera_device.tag.tag_size_m);
  }
}

Daemon::~Daemon() = default;

dockcore::TaskState Daemon::state() const {
  return core_->task_manager().state();
}
dockcore::FaultCode Daemon::fault() const {
  return core_->task_manager().fault();
}

bool Daemon::configure_core(std::uint16_t dock_id, bool raw_profile) {
  const DockEntry* d = cfg_.find_dock(dock_id);
  if (d == nullptr) return false;
  dockcore::DockProfile prof = d->profile;
  const Pose2 nominal = nominal_docked_target(cfg_);
  // The dock's tag sits in the dock's frame; a taught or configured target moves that frame, so the tag moves with
  // the profile's vertices (nominal⁻¹ ∘ target).
  dockcore::DockTag tag = d->tag;
  auto move_tag = [&tag, &nominal](const Pose2& target) {
    const Pose2 m = nominal.inverse().compose(target);
    const dockcore::Vec2 at = m.transform(dockcore::Vec2(tag.x_m, tag.y_m));
    tag.x_m = at.x();
    tag.y_m = at.y();
    tag.yaw_rad = dockcore::wrap_angle(tag.yaw_rad + m.yaw_rad);
  };
  if (!raw_profile) {
    const TaughtTarget* t = state_.find(dock_id);
    if (t != nullptr) {
      prof = profile_for_target(d->profile, nominal, t->target);
      move_tag(t->target);
      // The taught code, unless the profile file carries its own; all of it or none (start() reported a misfit).
      with_taught_code(prof, *t);
    } else if (d->has_target) {
      prof = profile_for_target(d->profile, nominal, d->target);
      move_tag(d->target);
    }
  }
  core_cfg_.tag.dock_tag = tag;
  core_cfg_.detector = d->detector;
  if (loop_record_) loop_record_->configure(loop_controller(), prof, core_cfg_);
  // What the core learned about the robot — the wheels' deadband floors, the lidar mount's calibration, the aim that
  // closed each dock's contacts — belongs to the robot, not to the dock: it goes on into the new configuration. A
  // reload builds a new core, which starts afresh from the learned file (restore_learned_state).
  const dockcore::DockcoreBase::Learned learned = core_->learned();
  if (!core_->configure(prof, core_cfg_)) return false;
  core_->restore_learned(learned);
  if (loop_record_) loop_record_->restore_learned(learned);
  active_dock_ = dock_id;
  active_raw_ = raw_profile;
  if (loop_record_) loop_record_->rescan();
  core_->rescan();  // the latest scan through the new profile: the next tick sees this dock's estimate
  return true;
}

void Daemon::restore_learned_state(std::uint64_t now_us) {
  kept_learned_ = core_->learned();
  if (!have_learned_file_) return;
  EventLine e(now_us, "learned");
  if (!learned_file_.learned_on(cfg_.lidar_mount, cfg_.drive)) {
    e.w.str("result", "not_restored")
        .str_cut(
            "message",
            (learned_paths_.file + ": learned on another lidar mount or drive: not restored, learned again").c_str(),
            1024);
    log_event(e, LogLevel::kWarn);
    return;
  }
  core_->restore_learned(learned_file_.learned);
  if (loop_record_) loop_record_->restore_learned(learned_file_.learned);
  kept_learned_ = core_->learned();
  const dockcore::TaskManager& tm = core_->task_manager();
  e.w.str("result", "restored")
      .uint("deadband_raises", kept_learned_.deadband.raises)
      .uint("mount_swings", tm.calibrations())
      .str("mount_calibration", dockcore::to_string(tm.last_calibration().status))
      .real("mount_x_m", static_cast<double>(core_->lidar_mount().x_m), 4)
      .real("mount_y_m", static_cast<double>(core_->lidar_mount().y_m), 4);
  log_event(e);
}

void Daemon::keep_learned_state(std::uint64_t now_us) {
  const dockcore::DockcoreBase::Learned now = core_->learned();
  if (same_learned(now, kept_learned_)) return;
  LearnedState l;
  l.lidar_mount = cfg_.lidar_mount;
  l.drive = cfg_.drive;
  l.saved_unix_s = static_cast<std::uint64_t>(std::time(nullptr));
  l.learned = now;
  char err[256];
  EventLine e(now_us, "learned");
  if (!save_learned(learned_paths_, l, learned_buf_, sizeof learned_buf_, err, sizeof err)) {
    ++counters_.learned_save_failures;
    e.w.str("result", "save_failed").str("message", err);
    log_event(e, LogLevel::kWarn);
    return;
  }
  ++counters_.learned_saves;
  learned_file_ = l;
  have_learned_file_ = true;
  kept_learned_ = now;
  e.w.str("result", "saved")
      .uint("deadband_raises", now.deadband.raises)
      .uint("mount_swings", now.task.calibrations)
      .str("mount_calibration", dockcore::to_string(now.task.last_calibration.status));
  log_event(e, LogLevel::kDebug);
}

bool Daemon::start(std::string& error) {
  const std::uint64_t now = io_.clock->now_us();
  std::string msg;
  std::vector<std::string> warnings;
  const StateLoadStatus st = load_state(cfg_.state_file, state_, msg, &warnings);
  if (st == StateLoadStatus::kRecoveredBackup || st == StateLoadStatus::kCorruptNoBackup) {
    EventLine e(now, "state_file");
    e.w.str("level", st == StateLoadStatus::kCorruptNoBackup ? "error" : "warn").str_cut("message", msg.c_str(), 1024);
    log_event(e, st == StateLoadStatus::kCorruptNoBackup ? LogLevel::kError : LogLevel::kWarn);
  }
  // A taught code that does not fit its dock's profile (a segment it lacks, a stripe off its segment): not applied.
  for (const TaughtTarget& t : state_.targets) {
    const DockEntry* d = cfg_.find_dock(t.dock_id);
    dockcore::DockProfile check = d != nullptr ? d->profile : dockcore::DockProfile{};
    dockcore::ProfileError why = dockcore::ProfileError::kOk;
    if (t.stripe_count == 0 || d == nullptr || d->profile.reflector_count > 0 || with_taught_code(check, t, &why)) {
      continue;
    }
    warnings.push_back(cfg_.state_file + ":" + std::to_string(t.code_line) + ": the taught code of dock " +
                       std::to_string(t.dock_id) + " does not fit its profile (" + dockcore::to_string(why) +
                       "): not applied");
  }
  for (const std::string& w : warnings) {
    EventLine e(now, "state_file");
    e.w.str("level", "warn").str_cut("message", w.c_str(), 1024);
    log_event(e, LogLevel::kWarn);
  }
  // What the robot learned, restored once the core is configured (restore_learned_state).
  learned_paths_ = LearnedPaths::beside(cfg_.state_file);
  std::string learned_why;
  const LearnedLoadStatus ls = load_learned(learned_paths_.file, learned_file_, learned_why);
  have_learned_file_ = ls == LearnedLoadStatus::kOk;
  if (ls == LearnedLoadStatus::kCorrupt) {
    EventLine e(now, "learned");
    e.w.str("result", "corrupt").str_cut("message", learned_why.c_str(), 1024);
    log_event(e, LogLevel::kWarn);
  }
  if (cfg_.record_loop && !cfg_.record_dir.empty()) {
    loop_record_ = std::make_unique<dockcore::drivers::LoopRecordWriter>();
    std::string err;
    if (!loop_record_->open(cfg_.record_dir + "/loop.rec", cfg_.record_max_bytes * cfg_.record_max_files, err)) {
      error = "loop record: " + err;
      return false;
    }
  }
  if (!configure_core(cfg_.default_dock_id, false)) {
    error = "dock profile of dock " + std::to_string(cfg_.default_dock_id) + " refused by the estimator";
    return false;
  }
  restore_learned_state(now);
  start_us_ = now;
  started_ = true;
  EventLine e(now, "start");
  e.w.str("controller", controller_->name())
      .uint("docks", cfg_.docks.size())
      .uint("taught", state_.targets.size())
      .uint("default_dock", cfg_.default_dock_id);
  log_event(e, LogLevel::kInfo);
  return true;
}

void Daemon::emit_event(LogLevel level, const char* line, std::size_t len) {
  if (io_.event_log != nullptr) io_.event_log->write_line(line, len);
  if (static_cast<int>(level) <= static_cast<int>(io_.stderr_level)) {
    std::fprintf(stderr, "dockd %s: %.*s", level_name(level), static_cast<int>(len), line);
  }
}

void Daemon::log_event(EventLine& e, LogLevel level) {
  const std::size_t n = e.w.finish(true);
  if (n > 0) {
    emit_event(level, e.buf, n);
  } else {
    ++counters_.events_too_long;
  }
}

dockcore::SubmitResult Daemon::submit(HostCommandType type, std::uint16_t dock_id, std::uint32_t token,
                                      std::uint32_t& displaced) {
  dockcore::QueuedCommand c;
  c.command = dockcore::HostCommand{type, dock_id};
  c.token = token;
  dockcore::QueuedCommand replaced;
  if (loop_record_) loop_record_->submit(c);
  const dockcore::SubmitResult res = core_->submit(c, &replaced);
  displaced = res == dockcore::SubmitResult::kReplacedNewest ? replaced.token : 0u;
  return res;
}

void Daemon::start_teach(const HostRequest& r, std::uint64_t now_us) {
  TeachConditions c;
  c.state = state();
  c.on_charger = !chassis_stale() && fb_.charging_contact;
  c.lidar_fresh = !lidar_stale();
  teach_.start(r, c, now_us);
}

void Daemon::cancel_teach(std::uint64_t now_us) {
  teach_.cancel(now_us);
}

bool Daemon::store_target(const TaughtTarget& t, std::string& error) {
  StateData next = state_;
  next.put(t);
  if (!save_state(cfg_.state_file, next, error)) return false;
  state_ = next;
  return true;
}

void Daemon::reply(const HostRequest& r, const char* json, std::size_t len) {
  host_.reply(r, json, len);
}

void Daemon::reply_error(const HostRequest& r, HostErrorCode code, const char* message) {
  host_.reply_error(r, code, message);
}

void Daemon::send_wheels(const dockcore::hal::WheelCommand& w) {
  last_wheels_ = w;
  if (!io_.chassis->send_wheels(w)) ++counters_.wheel_send_failures;
}

void Daemon::send_zero(std::uint64_t, int frames) {
  dockcore::hal::WheelCommand z;
  z.count = static_cast<std::uint8_t>(dockcore::drive_wheel_count(cfg_.drive.kind));
  for (int i = 0; i < frames; ++i) send_wheels(z);
  if (core_) core_->note_drive_stopped();
}

void Daemon::log_shutdown(std::uint64_t now_us, const char* reason) {
  if (shutdown_logged_) return;
  shutdown_logged_ = true;
  EventLine e(now_us, "shutdown");
  e.w.str("reason", reason)
      .str("state", dockcore::to_string(state()))
      .uint("worst_tick_us", stats_.worst_period_us)
      .uint("overruns", stats_.overruns);
  log_event(e, LogLevel::kInfo);
}

// --- inputs ------------------------------------------------------------------------------------------------------

void Daemon::poll_chassis(std::uint64_t now_us) {
  fb_ = io_.chassis->poll();
  // Error frames on the bus (bus-off, controller error passive, no ACK, ...): one event per poll that saw new ones.
  const dockcore::hal::ChassisCounters& cc = io_.chassis->counters();
  if (cc.bus_errors > reported_bus_errors_) {
    EventLine e(now_us, "can_error");
    e.w.uint("bus_errors", cc.bus_errors).uint("bus_off", cc.bus_off).uint("new", cc.bus_errors - reported_bus_errors_);
    log_event(e, cc.bus_off > reported_bus_off_ ? LogLevel::kError : LogLevel::kWarn);
  }
  reported_bus_errors_ = cc.bus_errors;
  reported_bus_off_ = cc.bus_off;
  dockcore::WheelSpeeds w;
  w.count = dockcore::drive_wheel_count(cfg_.drive.kind);
  for (std::size_t i = 0; i < w.count; ++i) w.radps[i] = fb_.wheel_radps[i];
  if (loop_record_) loop_record_->wheels(w, fb_.wheels_stamp_us);
  core_->on_wheels(w, fb_.wheels_stamp_us);  // a repeated stamp is no new feedback
}

void Daemon::poll_lidar(std::uint64_t now_us) {
  // Only the newest scan matters (poll_scan keeps the newest); bounded to a few per call. The scan stays in the
  // driver's buffer: the core reads it there (and copies it once, for its tick). A late one (a backlog drained late)
  // the core's input watch counts and leaves out.
  const dockcore::LaserScan* scan = nullptr;
  for (int i = 0; i < 4 && (scan = io_.lidar->poll_scan()) != nullptr; ++i) {
    ++counters_.scans;
    if (loop_record_) loop_record_->scan(scan->view(), scan->stamp_us, now_us);
    const dockcore::DockEstimate* e = core_->on_scan(scan->view(), scan->stamp_us, now_us);
    if (e != nullptr && e->found) {
      ++counters_.detections;
      teach_.sample(*e, scan->view(), core_->intensity().usable());
    }
  }
}

void Daemon::poll_camera(std::uint64_t) {
  // Both sources feed the same target; when both have a new one, the newer image wins.
  dockcore::CameraTarget best;
  bool have = false;
  for (dockcore::hal::CameraTargetSource* src : {io_.camera, io_.camera_own}) {
    if (src == nullptr) continue;
    dockcore::CameraTarget t;
    if (src->poll_target(t) && (!have || t.stamp_us >= best.stamp_us)) {
      best = t;
      have = true;
    }
  }
  if (have) camera_ = best;
  // The own camera's tag poses, in frame order, into the dock filter through the odometry pose at each frame's
  // stamp (docs/camera.md, "Fusion"). The source holds at most a queue's worth.
  if (io_.tags != nullptr) {
    dockcore::TagObservation o;
    for (int i = 0; i < 16 && io_.tags->poll_tag(o); ++i) {
      if (loop_record_) loop_record_->tag(o);
      const dockcore::TagStatus st = core_->on_tag(o);
      ++counters_.tags[static_cast<std::size_t>(st)];
    }
  }
}

void Daemon::on_lidar_readable(std::uint64_t now_us) {
  poll_lidar(now_us);
}
void Daemon::on_chassis_readable(std::uint64_t now_us) {
  poll_chassis(now_us);
}
void Daemon::on_host_readable(std::uint64_t now_us) {
  host_.poll(now_us);
}
void Daemon::on_camera_readable(std::uint64_t now_us) {
  poll_camera(now_us);
}

// --- watchdogs -----------------------------------------------------------------------------------------------------

void Daemon::watchdogs(std::uint64_t now_us) {
  if (loop_record_) loop_record_->check_inputs(now_us);
  const dockcore::InputWatch::Change c = core_->check_inputs(now_us);
  const dockcore::InputWatch& w = core_->inputs();
  if (c.lidar) {
    // Why it went stale, for a log read after the fact: how old the newest turn's end and the newest read are
    // (-1: none yet). A turn that ended long ago but was read just now is a backlog; both old is a silent lidar.
    const auto age_ms = [now_us](std::uint64_t t) {
      return t == 0 || t > now_us ? std::int64_t{-1} : static_cast<std::int64_t>((now_us - t) / 1000u);
    };
    EventLine e(now_us, "watchdog");
    e.w.str("which", "lidar")
        .boolean("stale", w.lidar_stale())
        .uint("fault", static_cast<unsigned>(FaultCode::kLidarStale))
        .sint("turn_end_age_ms", age_ms(w.turn_end_us()))
        .sint("parsed_age_ms", age_ms(w.scan_read_us()))
        .uint("late_scans", w.late_scans());
    log_event(e, w.lidar_stale() ? LogLevel::kWarn : LogLevel::kInfo);
  }
  if (c.chassis) {
    EventLine e(now_us, "watchdog");
    e.w.str("which", "chassis")
        .boolean("stale", w.chassis_stale())
        .uint("fault", static_cast<unsigned>(FaultCode::kChassisStale));
    log_event(e, w.chassis_stale() ? LogLevel::kWarn : LogLevel::kInfo);
  }
  camera_watchdog(now_us);
}

void Daemon::camera_watchdog(std::uint64_t now_us) {
  if (io_.camera_frames == nullptr) return;
  if (camera_watch_from_us_ == 0) camera_watch_from_us_ = now_us;
  const std::uint64_t last = io_.camera_frames->last_frame_us();
  // Before the first frame the window runs from the first tick: a camera that never delivers is a stalled one too.
  const std::uint64_t since = last != 0 ? last : camera_watch_from_us_;
  const bool stalled =
      now_us > since && now_us - since > static_cast<std::uint64_t>(cfg_.camera_device.stall_ms) * 1000u;
  if (stalled == camera_stalled_) return;
  if (stalled) ++counters_.camera_stalls;
  EventLine e(now_us, "watchdog");
  e.w.str("which", "camera")
      .boolean("stale", stalled)
      .sint("last_frame_age_ms", last == 0       ? std::int64_t{-1}
                                 : last > now_us ? std::int64_t{0}
                                                 : static_cast<std::int64_t>((now_us - last) / 1000u))
      .uint("camera_stalls", counters_.camera_stalls);
  log_event(e, stalled ? LogLevel::kWarn : LogLevel::kInfo);
  camera_stalled_ = stalled;
}

// --- the tick ------------------------------------------------------------------------------------------------------

void Daemon::on_tick(std::uint64_t now_us) {
  if (prev_tick_us_ != 0 && now_us > prev_tick_us_) {
    const std::uint64_t p = now_us - prev_tick_us_;
    stats_.last_period_us = p;
    if (p > stats_.worst_period_us) stats_.worst_period_us = p;
    if (p * 2 > kNominalTickUs * 3) ++stats_.overruns;
  }
  prev_tick_us_ = now_us;
  ++stats_.ticks;

  poll_chassis(now_us);
  poll_lidar(now_us);
  poll_camera(now_us);
  host_.poll(now_us);
  host_.report_held_events(now_us);
  watchdogs(now_us);
  teach_.progress(now_us);
  if (pending_cfg_ != nullptr && reload_can_apply()) {
    std::string msg;
    apply_reload(now_us, msg);  // logged there
  }

  dockcore::TickInput in;
  in.now_us = now_us;
  in.camera = camera_;
  in.contact = fb_.charging_contact;
  in.charge_current_a = fb_.battery_current_a;
  // The core takes the oldest queued command, else its resume policy's (docs/dockd.md, "Watchdogs"); none while a
  // teach runs. A dock/test for another dock (or after a teach changed the correction) needs the core configured for
  // it; that resets the task manager, so only while it is idle (otherwise the task manager answers "busy").
  const TaskState before = state();
  in.hold_commands = teach_.active();
  const dockcore::QueuedCommand* next = teach_.active() ? nullptr : core_->next_command();
  if (next != nullptr &&
      (next->command.type == HostCommandType::kDock || next->command.type == HostCommandType::kTestMode) &&
      idle_state(before) && (next->command.dock_id != active_dock_ || active_raw_)) {
    configure_core(next->command.dock_id, false);
  }

  const dockcore::TickOutput out = core_->tick(in);
  if (loop_record_) {
    loop_record_->tick(in, out);
    loop_record_->flush();
    if (loop_record_->full() && !loop_record_full_logged_) {
      loop_record_full_logged_ = true;
      EventLine e(now_us, "loop_record_full");
      e.w.str("message", "loop.rec reached record.max_bytes x record.max_files: no more calls recorded");
      log_event(e, LogLevel::kWarn);
    }
  }
  if (out.resume == dockcore::ResumeEvent::kResumed) {
    ++counters_.resumes;
    EventLine e(now_us, "resume");
    e.w.uint("command", static_cast<unsigned>(out.command.command.type))
        .uint("dock_id", out.command.command.dock_id)
        .uint("resume", out.resumes);
    log_event(e);
  } else if (out.resume == dockcore::ResumeEvent::kGivenUp) {
    EventLine e(now_us, "resume_given_up");
    e.w.str("reason", "max resumes reached");
    log_event(e, LogLevel::kWarn);
  }
  if (out.command_taken) host_.command_taken(out, before, now_us);

  // Motion: Dockcore's shaped wheel speeds (zero while stale input holds the robot).
  dockcore::hal::WheelCommand wc;
  wc.count = static_cast<std::uint8_t>(out.wheels.count);
  for (std::size_t i = 0; i < out.wheels.count && i < 4; ++i) wc.radps[i] = out.wheels.radps[i];
  send_wheels(wc);

  const bool charge = out.status.charge_enable;
  if (charge != charge_requested_ || ++charge_refresh_ >= 50) {
    io_.chassis->request_charging(charge);
    charge_refresh_ = 0;
    if (charge != charge_requested_) {
      EventLine e(now_us, "charge_request");
      e.w.boolean("on", charge);
      log_event(e);
    }
    charge_requested_ = charge;
  }

  // Events.
  const dockcore::TaskStatus& s = out.status;
  // A task's end, the robot standing: what it taught about the robot goes into the learned file (once per change,
  // never while the robot moves: an fsync may take longer than a tick).
  const bool task_ended =
      s.state == TaskState::kFinishTasking || s.state == TaskState::kFault || s.state == TaskState::kNotTasking;
  if (prev_status_valid_ && s.state != prev_status_.state && task_ended) keep_learned_state(now_us);
  if (!prev_status_valid_ || s.state != prev_status_.state) {
    EventLine e(now_us, "state");
    e.w.str("from", prev_status_valid_ ? dockcore::to_string(prev_status_.state) : "START")
        .str("to", dockcore::to_string(s.state))
        .uint("dock_id", s.dock_id)
        .str("result", to_string_result(s.last_result));
    if (s.state == TaskState::kRetry) {
      // Why the attempt ended, and in which controller phase: what a user needs to tell a bad line-up from a
      // charger that never delivered.
      e.w.str("reason", dockcore::to_string(s.retry_reason))
          .uint("code", static_cast<unsigned>(s.retry_reason))
          .str("phase", prev_status_.state == TaskState::kAlign ? controller_->phase_name(prev_status_.phase)
                                                                : dockcore::to_string(prev_status_.state));
    }
    // Where each attempt aims beside the dock's axis: the remembered aim plus the retries' search.
    if (s.state == TaskState::kAlign) e.w.real("aim_lateral_m", static_cast<double>(s.aim_lateral_m), 4);
    log_event(e);
  }
  if (s.state == TaskState::kAlign &&
      (!prev_status_valid_ || s.phase != prev_status_.phase || prev_status_.state != TaskState::kAlign)) {
    EventLine e(now_us, "phase");
    e.w.uint("phase", s.phase).str("name", controller_->phase_name(s.phase));
    log_event(e, LogLevel::kDebug);
  }
  if (s.fault != FaultCode::kNone && (!prev_status_valid_ || s.fault != prev_status_.fault)) {
    EventLine e(now_us, "fault");
    e.w.uint("code", static_cast<unsigned>(s.fault)).str("name", dockcore::to_string(s.fault));
    log_event(e, LogLevel::kWarn);
  }
  const bool changed = !prev_status_valid_ || s.state != prev_status_.state || s.fault != prev_status_.fault ||
                       s.phase != prev_status_.phase || s.retries != prev_status_.retries ||
                       s.last_command != prev_status_.last_command || lidar_stale() != prev_lidar_stale_ ||
                       chassis_stale() != prev_chassis_stale_ || camera_stalled_ != prev_camera_stalled_;
  prev_camera_stalled_ = camera_stalled_;
  prev_lidar_stale_ = lidar_stale();
  prev_chassis_stale_ = chassis_stale();
  last_out_ = out;
  prev_status_ = s;
  prev_status_valid_ = true;
  if (changed || now_us >= next_status_us_) {
    publish_status(now_us);
    next_status_us_ = now_us + static_cast<std::uint64_t>(1e6 / cfg_.status_rate_hz);
  }

  if (io_.clock != nullptr) {
    const std::uint64_t end = io_.clock->now_us();
    if (end > now_us && end - now_us > stats_.worst_work_us) stats_.worst_work_us = end - now_us;
  }
}

}  // namespace dockd
