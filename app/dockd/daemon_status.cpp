// dockd: the status — the JSON object every status reply and stream carries, and its publication on CAN and UDP.
#include "daemon.hpp"
#include "daemon_internal.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>

namespace dockd {

namespace {

/// A read stripe edge within this of a code's, plus the beam spacing at the dock, is the same edge, m.
constexpr double kCodeEdgeToleranceM = 0.02;

/// Two profiles of the same outline (every vertex within 1 mm): stripes on one are comparable with the other's.
bool same_outline(const dockcore::DockProfile& a, const dockcore::DockProfile& b) {
  if (a.vertex_count != b.vertex_count) return false;
  for (std::size_t i = 0; i < a.vertex_count; ++i) {
    if ((a.vertices_m[i] - b.vertices_m[i]).norm() > static_cast<Real>(0.001)) return false;
  }
  return true;
}

/// What the latest scan read of the active dock's reflector code (docs/docks.md, "Reflectors"): "none" (its profile
/// has no stripes), "not_read" (the lidar's intensity is flat or absent: geometry only), "read" (the dock was found
/// with its own pattern: it is the dock of this id), "wrong" (a dock of its shape with another pattern was refused),
/// "unread" (a dock of its shape whose stripes were too far or oblique to read was refused), or "no_dock".
const char* code_reading(const dockcore::DockcoreBase& core) {
  if (core.estimator().profile().reflector_count == 0 || core.config().detector != dockcore::DockDetector::kEstimator) {
    return "none";
  }
  if (!core.estimator().intensity_usable()) return "not_read";
  const dockcore::DockEstimate& e = core.last_estimate();
  if (e.found) return "read";
  if (e.reject == dockcore::RejectReason::kWrongCode) return "wrong";
  if (e.reject == dockcore::RejectReason::kCodeUnread) return "unread";
  return "no_dock";
}

}  // namespace

int Daemon::code_dock_id() const {
  const dockcore::DockcoreBase& core = *core_;
  if (core.estimator().profile().reflector_count == 0 || core.config().detector != dockcore::DockDetector::kEstimator ||
      !core.estimator().intensity_usable()) {
    return -1;
  }
  const dockcore::DockEstimate& e = core.last_estimate();
  if (e.found) return active_dock_;
  const DockEntry* active = cfg_.find_dock(active_dock_);
  if (e.reject != dockcore::RejectReason::kWrongCode || active == nullptr) return -1;
  // Another dock of this shape was refused: read its stripes where it stands and look its pattern up among the
  // database's docks of the same outline (their own stripes, or their taught code).
  const dockcore::ScanView scan = core.last_scan();
  const dockcore::StripeRead r = dockcore::read_reflector_stripes(scan, cfg_.lidar_mount, core.estimator().profile(),
                                                                  e.refused_pose, stripe_read_params(cfg_));
  if (r.status != dockcore::StripeReadStatus::kOk || r.count == 0) return -1;
  // An edge is read to about half a beam spacing at the dock, plus the pose's own error.
  const Real dist_m = std::hypot(e.refused_pose.x_m, e.refused_pose.y_m);
  const Real tolerance_m = static_cast<Real>(kCodeEdgeToleranceM) + dist_m * scan.angle_increment_rad;
  for (const DockEntry& d : cfg_.docks) {
    if (d.id == active_dock_ || !same_outline(d.profile, active->profile)) continue;
    dockcore::DockProfile coded = d.profile;
    const TaughtTarget* t = state_.find(d.id);
    if (t != nullptr) with_taught_code(coded, *t);
    if (coded.reflector_count > 0 &&
        dockcore::same_stripes(coded.reflectors, coded.reflector_count, r.stripes, r.count, tolerance_m)) {
      return d.id;
    }
  }
  return -1;
}

void Daemon::publish_status(std::uint64_t now_us) {
  const dockcore::TaskStatus& s = last_out_.status;
  dockcore::hal::StatusMessage m;
  m.task_state = static_cast<std::uint8_t>(s.state);
  m.align_phase = s.phase;
  // The watchdogs' codes are reported even while idle (the task manager faults only in active states).
  m.fault_code = static_cast<std::uint16_t>(s.fault != FaultCode::kNone ? s.fault
                                            : chassis_stale()           ? FaultCode::kChassisStale
                                            : lidar_stale()             ? FaultCode::kLidarStale
                                                                        : FaultCode::kNone);
  m.retries = s.retries;
  m.last_result = static_cast<std::uint8_t>(s.last_command);
  m.dock_valid = s.dock_valid;
  m.dock_in_robot = s.dock_pose;
  m.stamp_us = now_us;
  host_.publish_status(m, now_us);
}

std::size_t Daemon::status_json(char* buf, std::size_t size, std::uint64_t now_us) const {
  JsonWriter w(buf, size);
  status_fields(w, now_us);
  return w.finish();
}

void Daemon::status_fields(JsonWriter& w, std::uint64_t now_us) const {
  const dockcore::TaskStatus& s = last_out_.status;
  const FaultCode watchdog_fault = chassis_stale() ? FaultCode::kChassisStale
                                   : lidar_stale() ? FaultCode::kLidarStale
                                                   : FaultCode::kNone;
  const dockcore::hal::LidarCounters& lc = io_.lidar->counters();
  const dockcore::hal::ChassisCounters& cc = io_.chassis->counters();
  // The latest scan's detection decision: its evidence and each cue (for a miss, the best refused candidate's).
  const dockcore::DockEstimate& e = core_->last_estimate();
  double cues[dockcore::kEvidenceCueCount];
  for (std::size_t i = 0; i < dockcore::kEvidenceCueCount; ++i) cues[i] = static_cast<double>(e.evidence.cue_nats[i]);
  // The wheel deadband the output shaping applies, per wheel, forward and backward.
  const dockcore::WheelDeadband& db = core_->deadband();
  const std::size_t wheels = dockcore::drive_wheel_count(core_->config().drive.kind);
  double db_fwd[dockcore::kMaxDriveWheels];
  double db_rev[dockcore::kMaxDriveWheels];
  for (std::size_t i = 0; i < wheels; ++i) {
    db_fwd[i] = static_cast<double>(db.floor_radps(i, false));
    db_rev[i] = static_cast<double>(db.floor_radps(i, true));
  }
  w.str("type", "status")
      .uint("stamp_us", now_us)
      .str("state", dockcore::to_string(s.state))
      .uint("state_code", static_cast<unsigned>(s.state))
      .uint("phase", s.phase)
      .str("phase_name", s.state == TaskState::kAlign ? controller_->phase_name(s.phase) : "")
      .uint("fault", static_cast<unsigned>(s.fault))
      .str("fault_name", dockcore::to_string(s.fault))
      .uint("watchdog_fault", static_cast<unsigned>(watchdog_fault))
      .uint("retries", s.retries)
      .uint("dock_id", s.dock_id)
      .boolean("dock_valid", s.dock_valid)
      .real("dock_x_m", static_cast<double>(s.dock_pose.x_m), 4)
      .real("dock_y_m", static_cast<double>(s.dock_pose.y_m), 4)
      .real("dock_yaw_deg", deg(s.dock_pose.yaw_rad), 2)
      .str("last_command", dockcore::to_string(s.last_command))
      .str("last_result", to_string_result(s.last_result))
      .boolean("charge_enable", s.charge_enable)
      .boolean("contact", fb_.charging_contact)
      .real("charge_current_a", static_cast<double>(fb_.battery_current_a), 2)
      .real("battery_v", static_cast<double>(fb_.battery_voltage_v), 2)
      .real("soc", static_cast<double>(fb_.soc), 3)
      .boolean("estop", fb_.estop)
      .boolean("lidar_stale", lidar_stale())
      .boolean("chassis_stale", chassis_stale())
      .real("odom_x_m", static_cast<double>(odom_pose().x_m), 4)
      .real("odom_y_m", static_cast<double>(odom_pose().y_m), 4)
      .real("odom_yaw_deg", deg(odom_pose().yaw_rad), 2)
      .real("cmd_vx_mps", static_cast<double>(core_->drive_cmd().vx_mps), 3)
      .real("cmd_wz_radps", static_cast<double>(core_->drive_cmd().wz_radps), 3)
      .reals("deadband_fwd_radps", db_fwd, wheels, 2)
      .reals("deadband_rev_radps", db_rev, wheels, 2)
      .uint("deadband_raises", db.raises())
      .boolean("teaching", teach_.active())
      .boolean("taught", state_.find(s.dock_id) != nullptr)
      .uint("ticks", stats_.ticks)
      .uint("tick_worst_us", stats_.worst_period_us)
      .uint("tick_overruns", stats_.overruns)
      .uint("tick_work_worst_us", stats_.worst_work_us)
      .uint("scans", counters_.scans)
      .uint("detections", counters_.detections)
      .uint("lidar_crc_errors", lc.crc_errors)
      .uint("lidar_resyncs", lc.resyncs)
      .uint("lidar_dropped_bytes", lc.dropped_bytes)
      .uint("lidar_foreign_datagrams", lc.foreign_datagrams)
      .uint("lidar_reconnects", lc.reconnects)
      .uint("lidar_late_scans", core_->inputs().late_scans())
      .str("lidar_intensity", dockcore::to_string(core_->intensity().verdict()))
      .uint("can_bad_frames", cc.bad_frames)
      .uint("can_send_failures", cc.send_failures)
      .uint("commands", counters_.commands)
      .uint("commands_rejected", commands_rejected_total())
      .uint("resumes", counters_.resumes)
      .uint("can_host_rejected", host_.can_rejected())
      .uint("udp_not_allowed", host_.udp_not_allowed())
      .uint("config_reloads", counters_.config_reloads)
      .uint("config_reloads_rejected", counters_.config_reloads_rejected)
      .boolean("config_reload_pending", pending_cfg_ != nullptr)
      .boolean("det_found", e.found)
      .real("det_evidence_nats", static_cast<double>(e.evidence.total_nats), 1)
      .reals("det_cues_nats", cues, dockcore::kEvidenceCueCount, 1)
      .str("det_reject", e.found ? "none" : dockcore::to_string(e.reject))
      .str("det_code", code_reading(*core_))
      .sint("det_code_dock", code_dock_id())
      .real("dock_evidence_nats", static_cast<double>(core_->filter().evidence_nats()), 1)
      .boolean("dock_confirmed", core_->filter().confirmed());
  // The camera's groups go in only when they fit (the status must stay one datagram); each is dropped whole. The
  // camera part of the status (camera_fields) always has them.
  camera_groups(w, true);
}

void Daemon::camera_fields(JsonWriter& w) const {
  camera_groups(w, false);
}

void Daemon::camera_groups(JsonWriter& w, bool only_if_fits) const {
  const auto group = [&w, only_if_fits](auto&& write) {
    const std::size_t m = w.mark();
    write();
    if (only_if_fits && !w.ok()) w.rollback(m);
  };
  // The tag fusion's counters (docs/camera.md, "Status").
  if (io_.tags != nullptr) {
    group([&] {
      w.uint("tag_fused", counters_.tags[0]).uints("tag_refused", counters_.tags + 1, dockcore::kTagStatusCount - 1);
    });
  }
  // The stall watchdog's flag only, as for the lidar: the count is in the watchdog event.
  if (io_.camera_frames != nullptr) group([&] { w.boolean("camera_stalled", camera_stalled_); });
  // The own camera's fields (camera-check reports the rest).
  if (io_.camera_status != nullptr) {
    const dockcore::hal::CameraStatus c = io_.camera_status->camera_status();
    group([&] {
      w.boolean("camera_connected", c.connected)
          .uint("camera_frames", c.capture.frames)
          .uint("camera_dropped", c.capture.dropped)
          .uint("camera_late", c.capture.late)
          .uint("camera_corrupt", c.capture.corrupt)
          .uint("camera_reconnects", c.capture.reconnects)
          .sint("camera_tag_id", c.tag_id);
    });
  }
}

}  // namespace dockd
