// dockd: teach — average the dock's detections while the robot sits on the charger and store the docked target.
#include "daemon.hpp"
#include "daemon_internal.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>

namespace dockd {

void Daemon::start_teach(const HostRequest& r, std::uint64_t now_us) {
  const std::uint16_t id = r.has_dock_id ? r.dock_id : cfg_.default_dock_id;
  if (cfg_.find_dock(id) == nullptr) {
    char msg[96];
    std::snprintf(msg, sizeof msg, "dock id %u is not in the dock database", id);
    host_.reply_error(r, HostErrorCode::kUnknownDockId, msg);
    return;
  }
  if (teach_.active) {
    host_.reply_error(r, HostErrorCode::kBusy, "a teach is already running");
    return;
  }
  const TaskState s = state();
  if (!(s == TaskState::kNotTasking || s == TaskState::kFinishTasking || s == TaskState::kFault)) {
    host_.reply_error(r, HostErrorCode::kTeachFailed, "teach needs an idle robot (stop the running task first)");
    return;
  }
  if (chassis_stale() || !fb_.charging_contact) {
    host_.reply_error(r, HostErrorCode::kTeachFailed, "teach needs the robot on the charger: contacts are not closed");
    return;
  }
  if (lidar_stale()) {
    host_.reply_error(r, HostErrorCode::kTeachFailed, "teach needs the lidar: no fresh scans");
    return;
  }
  // Detections against the dock's own profile, without any earlier correction (that is what is being measured).
  if (!configure_core(id, true)) {
    host_.reply_error(r, HostErrorCode::kTeachFailed, "dock profile refused");
    return;
  }
  teach_.active = true;
  teach_.dock_id = id;
  teach_.wanted = r.scans != 0 ? r.scans : cfg_.teach_scans;
  teach_.have = 0;
  teach_.sx = teach_.sy = teach_.sc = teach_.ss = 0;
  teach_.deadline_us = now_us + static_cast<std::uint64_t>(cfg_.teach_timeout_s * 1e6);
  teach_.request = r;
  EventLine e(now_us, "teach_start");
  e.w.uint("dock_id", id).uint("scans", teach_.wanted);
  log_event(e);
}

void Daemon::teach_sample(const dockcore::DockEstimate& e) {
  if (teach_.have >= teach_.wanted) return;
  teach_.samples[teach_.have++] = e.pose;
  teach_.sx += static_cast<double>(e.pose.x_m);
  teach_.sy += static_cast<double>(e.pose.y_m);
  teach_.sc += std::cos(static_cast<double>(e.pose.yaw_rad));
  teach_.ss += std::sin(static_cast<double>(e.pose.yaw_rad));
}

void Daemon::finish_teach(bool ok, const char* why, std::uint64_t now_us) {
  const HostRequest r = teach_.request;
  const std::uint16_t id = teach_.dock_id;
  teach_.active = false;
  if (!ok) {
    configure_core(active_dock_, false);
    host_.reply_error(r, HostErrorCode::kTeachFailed, why);
    return;
  }
  const double n = teach_.have;
  TaughtTarget t;
  t.dock_id = id;
  t.target = Pose2{static_cast<Real>(teach_.sx / n), static_cast<Real>(teach_.sy / n),
                   static_cast<Real>(std::atan2(teach_.ss, teach_.sc))};
  t.scans = teach_.have;
  double spread = 0;
  for (std::uint16_t i = 0; i < teach_.have; ++i) {
    spread = std::fmax(spread, std::hypot(static_cast<double>(teach_.samples[i].x_m - t.target.x_m),
                                          static_cast<double>(teach_.samples[i].y_m - t.target.y_m)));
  }
  t.spread_m = spread;
  t.taught_unix_s = static_cast<std::uint64_t>(std::time(nullptr));
  // A moving robot or a detection flipping between two fits would teach garbage: 2 cm is far beyond lidar noise
  // averaged over a still robot.
  if (spread > 0.02) {
    configure_core(id, false);
    char msg[128];
    std::snprintf(msg, sizeof msg, "detections spread %.1f mm (> 20 mm): robot moving or dock ambiguous", spread * 1e3);
    host_.reply_error(r, HostErrorCode::kTeachFailed, msg);
    return;
  }
  StateData next = state_;
  next.put(t);
  std::string err;
  if (!save_state(cfg_.state_file, next, err)) {
    configure_core(id, false);
    host_.reply_error(r, HostErrorCode::kTeachFailed, ("state file: " + err).c_str());
    return;
  }
  state_ = next;
  configure_core(id, false);
  const Pose2 nom = nominal_docked_target(cfg_);
  // The taught target, once for the event and once inside the reply.
  char tb[256];
  dockcore::drivers::JsonWriter target(tb, sizeof tb);
  target.uint("dock_id", id)
      .uint("scans", t.scans)
      .real("target_x_m", static_cast<double>(t.target.x_m), 4)
      .real("target_y_m", static_cast<double>(t.target.y_m), 4)
      .real("target_yaw_deg", deg(t.target.yaw_rad), 3);
  char buf[512];
  dockcore::drivers::JsonWriter reply(buf, sizeof buf);
  reply.boolean("ok", true)
      .str("cmd", "teach")
      .uint("seq", r.seq)
      .fields(target.body(), target.body_len())
      .real("spread_mm", spread * 1e3, 2)
      .real("offset_x_mm", static_cast<double>(t.target.x_m - nom.x_m) * 1e3, 1)
      .real("offset_y_mm", static_cast<double>(t.target.y_m - nom.y_m) * 1e3, 1)
      .real("offset_yaw_deg", deg(dockcore::wrap_angle(t.target.yaw_rad - nom.yaw_rad)), 3);
  host_.reply(r, buf, reply.finish());
  EventLine e(now_us, "teach_done");
  e.w.fields(target.body(), target.body_len());
  log_event(e);
}

void Daemon::cancel_teach(std::uint64_t now_us) {
  if (teach_.active) finish_teach(false, "cancelled by stop", now_us);
}

void Daemon::teach_progress(std::uint64_t now_us) {
  if (!teach_.active) return;
  if (teach_.have >= teach_.wanted) {
    finish_teach(true, "", now_us);
  } else if (now_us >= teach_.deadline_us) {
    char msg[128];
    std::snprintf(msg, sizeof msg, "only %u of %u scans saw the dock within %.0f s", teach_.have, teach_.wanted,
                  cfg_.teach_timeout_s);
    finish_teach(false, msg, now_us);
  }
}

}  // namespace dockd
