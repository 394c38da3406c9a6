// dockd: teach — average the dock's detections while the robot sits on the charger and store the docked target.
#include "teach.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>

#include "daemon_internal.hpp"

namespace dockd {

Teacher::Teacher(const DockdConfig& config, TeachHooks& hooks)
    : cfg_(config), hooks_(hooks), samples_(std::make_unique<Pose2[]>(kMaxScans)) {}

Teacher::~Teacher() = default;

void Teacher::start(const HostRequest& r, const TeachConditions& c, std::uint64_t now_us) {
  const std::uint16_t id = r.has_dock_id ? r.dock_id : cfg_.default_dock_id;
  if (cfg_.find_dock(id) == nullptr) {
    char msg[96];
    std::snprintf(msg, sizeof msg, "dock id %u is not in the dock database", id);
    hooks_.reply_error(r, HostErrorCode::kUnknownDockId, msg);
    return;
  }
  if (active_) {
    hooks_.reply_error(r, HostErrorCode::kBusy, "a teach is already running");
    return;
  }
  const TaskState s = c.state;
  if (!(s == TaskState::kNotTasking || s == TaskState::kFinishTasking || s == TaskState::kFault)) {
    hooks_.reply_error(r, HostErrorCode::kTeachFailed, "teach needs an idle robot (stop the running task first)");
    return;
  }
  if (!c.on_charger) {
    hooks_.reply_error(r, HostErrorCode::kTeachFailed, "teach needs the robot on the charger: contacts are not closed");
    return;
  }
  if (!c.lidar_fresh) {
    hooks_.reply_error(r, HostErrorCode::kTeachFailed, "teach needs the lidar: no fresh scans");
    return;
  }
  // Detections against the dock's own profile, without any earlier correction (that is what is being measured).
  if (!hooks_.configure_core(id, true)) {
    hooks_.reply_error(r, HostErrorCode::kTeachFailed, "dock profile refused");
    return;
  }
  active_ = true;
  dock_id_ = id;
  wanted_ = r.scans != 0 ? r.scans : cfg_.teach_scans;
  if (wanted_ > kMaxScans) wanted_ = kMaxScans;  // the parser and the config bound both to 1..kMaxScans already
  have_ = 0;
  sx_ = sy_ = sc_ = ss_ = 0;
  deadline_us_ = now_us + static_cast<std::uint64_t>(cfg_.teach_timeout_s * 1e6);
  request_ = r;
  EventLine e(now_us, "teach_start");
  e.w.uint("dock_id", id).uint("scans", wanted_);
  hooks_.log_event(e, LogLevel::kInfo);
}

void Teacher::sample(const dockcore::DockEstimate& e) {
  if (!active_ || have_ >= wanted_) return;
  samples_[have_++] = e.pose;
  sx_ += static_cast<double>(e.pose.x_m);
  sy_ += static_cast<double>(e.pose.y_m);
  sc_ += std::cos(static_cast<double>(e.pose.yaw_rad));
  ss_ += std::sin(static_cast<double>(e.pose.yaw_rad));
}

void Teacher::finish(bool ok, const char* why, std::uint64_t now_us) {
  const HostRequest r = request_;
  const std::uint16_t id = dock_id_;
  active_ = false;
  if (!ok) {
    hooks_.configure_core(hooks_.active_dock_id(), false);
    hooks_.reply_error(r, HostErrorCode::kTeachFailed, why);
    return;
  }
  const double n = have_;
  TaughtTarget t;
  t.dock_id = id;
  t.target = Pose2{static_cast<Real>(sx_ / n), static_cast<Real>(sy_ / n), static_cast<Real>(std::atan2(ss_, sc_))};
  t.scans = have_;
  double spread = 0;
  for (std::uint16_t i = 0; i < have_; ++i) {
    spread = std::fmax(spread, std::hypot(static_cast<double>(samples_[i].x_m - t.target.x_m),
                                          static_cast<double>(samples_[i].y_m - t.target.y_m)));
  }
  t.spread_m = spread;
  t.taught_unix_s = static_cast<std::uint64_t>(std::time(nullptr));
  // A moving robot or a detection flipping between two fits would teach garbage: 2 cm is far beyond lidar noise
  // averaged over a still robot.
  if (spread > 0.02) {
    hooks_.configure_core(id, false);
    char msg[128];
    std::snprintf(msg, sizeof msg, "detections spread %.1f mm (> 20 mm): robot moving or dock ambiguous", spread * 1e3);
    hooks_.reply_error(r, HostErrorCode::kTeachFailed, msg);
    return;
  }
  std::string err;
  if (!hooks_.store_target(t, err)) {
    hooks_.configure_core(id, false);
    hooks_.reply_error(r, HostErrorCode::kTeachFailed, ("state file: " + err).c_str());
    return;
  }
  hooks_.configure_core(id, false);
  const Pose2 nom = nominal_docked_target(cfg_);
  // The taught target, once for the event and once inside the reply.
  char tb[256];
  JsonWriter target(tb, sizeof tb);
  target.uint("dock_id", id)
      .uint("scans", t.scans)
      .real("target_x_m", static_cast<double>(t.target.x_m), 4)
      .real("target_y_m", static_cast<double>(t.target.y_m), 4)
      .real("target_yaw_deg", deg(t.target.yaw_rad), 3);
  char buf[512];
  JsonWriter reply(buf, sizeof buf);
  reply.boolean("ok", true)
      .str("cmd", "teach")
      .uint("seq", r.seq)
      .fields(target.body(), target.body_len())
      .real("spread_mm", spread * 1e3, 2)
      .real("offset_x_mm", static_cast<double>(t.target.x_m - nom.x_m) * 1e3, 1)
      .real("offset_y_mm", static_cast<double>(t.target.y_m - nom.y_m) * 1e3, 1)
      .real("offset_yaw_deg", deg(dockcore::wrap_angle(t.target.yaw_rad - nom.yaw_rad)), 3);
  hooks_.reply(r, buf, reply.finish());
  EventLine e(now_us, "teach_done");
  e.w.fields(target.body(), target.body_len());
  hooks_.log_event(e, LogLevel::kInfo);
}

void Teacher::cancel(std::uint64_t now_us) {
  if (active_) finish(false, "cancelled by stop", now_us);
}

void Teacher::progress(std::uint64_t now_us) {
  if (!active_) return;
  if (have_ >= wanted_) {
    finish(true, "", now_us);
  } else if (now_us >= deadline_us_) {
    char msg[128];
    std::snprintf(msg, sizeof msg, "only %u of %u scans saw the dock within %.0f s", have_, wanted_,
                  cfg_.teach_timeout_s);
    finish(false, msg, now_us);
  }
}

}  // namespace dockd
