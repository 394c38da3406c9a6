// dockd: config reload (SIGHUP) — parse and validate a new file, apply it while the task is idle, all or nothing.
#include "daemon.hpp"
#include "daemon_internal.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>

namespace dockd {

void Daemon::log_reload(std::uint64_t now_us, const char* result, const std::string& message, LogLevel level) {
  EventLine e(now_us, "config_reload");
  e.w.str("result", result).str_cut("message", message.c_str(), 1024);
  log_event(e, level);
}

ReloadResult Daemon::reload_from_file(const std::string& path, std::uint64_t now_us, std::string& message,
                                      const std::function<void(DockdConfig&)>& adjust) {
  DockdConfig next;
  try {
    next = load_config_file(path);
  } catch (const ConfigError& e) {
    message = std::string(e.what()) + " (config reload rejected; the running configuration stays)";
    ++counters_.config_reloads_rejected;
    log_reload(now_us, "rejected", message, LogLevel::kError);
    return ReloadResult::kRejected;
  }
  if (adjust) adjust(next);
  return request_reload(next, now_us, message);
}

ReloadResult Daemon::request_reload(const DockdConfig& next, std::uint64_t now_us, std::string& message) {
  const std::vector<std::string> changed = restart_only_changes(cfg_, next);
  if (!changed.empty()) {
    message = next.source + ": config reload rejected: restart-only keys changed (";
    for (std::size_t i = 0; i < changed.size(); ++i) message += (i > 0 ? ", " : "") + changed[i];
    message += "); restart dockd to change them. The running configuration stays.";
    ++counters_.config_reloads_rejected;
    log_reload(now_us, "rejected", message, LogLevel::kError);
    return ReloadResult::kRejected;
  }
  pending_cfg_ = std::make_unique<DockdConfig>(next);
  if (reload_can_apply()) return apply_reload(now_us, message) ? ReloadResult::kApplied : ReloadResult::kRejected;
  message = next.source + ": config reload valid; pending until the task is idle (state " +
            dockcore::to_string(state()) + ")";
  log_reload(now_us, "pending", message, LogLevel::kInfo);
  return ReloadResult::kPending;
}

bool Daemon::reload_can_apply() const {
  // Rebuilding the core resets the task manager: only while nothing runs, no fault is latched (the host must see
  // it) and no watchdog resume waits — so no motion, charge or fault report changes under a reload.
  return state() == TaskState::kNotTasking && !teach_.active() && !core_->resume_pending();
}

bool Daemon::apply_reload(std::uint64_t now_us, std::string& message) {
  std::unique_ptr<DockdConfig> next = std::move(pending_cfg_);
  std::string err;
  // The only step that can still refuse: done first, so a refusal leaves everything as it was.
  if (!host_.set_allowlist(next->host.allowlist, err)) {
    ++counters_.config_reloads_rejected;
    message = next->source + ": config reload rejected: " + err + " (the running configuration stays)";
    log_reload(now_us, "rejected", message, LogLevel::kError);
    return false;
  }
  DockdConfig old = cfg_;
  cfg_ = *next;
  // The old core holds the latest scan (dockd keeps no copy of its own): alive until the new core has it.
  const std::unique_ptr<dockcore::Dockcore> previous = std::move(core_);
  build_core();
  core_->take_inputs(*previous);  // the robot and its sensors carry on: odometry, input watch, latest scan
  if (loop_record_) loop_record_->take_inputs();
  if (!configure_core(cfg_.default_dock_id, false)) {
    // A profile the estimator refuses (validated configs do not have one): back to the old config entirely.
    cfg_ = old;
    build_core();
    core_->take_inputs(*previous);
    if (loop_record_) loop_record_->take_inputs();
    configure_core(cfg_.default_dock_id, false);
    restore_learned_state(now_us);
    host_.set_allowlist(cfg_.host.allowlist, err);
    ++counters_.config_reloads_rejected;
    message = next->source +
              ": config reload rejected: dock profile refused by the estimator (the running "
              "configuration stays)";
    log_reload(now_us, "rejected", message, LogLevel::kError);
    return false;
  }
  // The new core starts afresh; what the robot taught the old one is in the learned file (kept at every task's end,
  // and a reload waits for an idle task) and goes on when the lidar mount and drive are the same.
  restore_learned_state(now_us);
  io_.stderr_level = cfg_.log_level;
  ++counters_.config_reloads;
  message = cfg_.source + ": config reloaded";
  log_reload(now_us, "applied", message, LogLevel::kWarn);
  return true;
}

}  // namespace dockd
