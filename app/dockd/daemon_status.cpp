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
  const dockcore::StripeRead r = dockcore::read_reflector_stripes(scan, core.lidar_mount(), core.estimator().profile(),
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
  const StatusValues v = status_values(now_us);
  write_status(w, v);
  // The camera's groups, then the mount calibration, go in only when they fit (the status must stay one datagram);
  // each is dropped whole. The camera part of the status (camera_fields) always has the camera's, the counters part
  // the mount calibration.
  write_camera_groups(w, camera_values(), true);
  w.optional_group([&] { write_mount(w, v); });
}

void Daemon::camera_fields(JsonWriter& w) const {
  write_camera_groups(w, camera_values(), false);
}

void Daemon::counter_fields(JsonWriter& w, std::uint64_t now_us) const {
  write_counters_part(w, status_values(now_us));
}

StatusValues Daemon::status_values(std::uint64_t now_us) const {
  const dockcore::TaskStatus& s = last_out_.status;
  const FaultCode watchdog_fault = chassis_stale() ? FaultCode::kChassisStale
                                   : lidar_stale() ? FaultCode::kLidarStale
                                                   : FaultCode::kNone;
  const dockcore::hal::LidarCounters& lc = io_.lidar->counters();
  const dockcore::hal::ChassisCounters& cc = io_.chassis->counters();
  // The latest scan's detection decision: its evidence and each cue (for a miss, the best refused candidate's).
  const dockcore::DockEstimate& e = core_->last_estimate();
  // The wheel deadband the output shaping applies, per wheel, forward and backward.
  const dockcore::WheelDeadband& db = core_->deadband();
  StatusValues v;
  v.stamp_us = now_us;
  v.state = dockcore::to_string(s.state);
  v.state_code = static_cast<std::uint8_t>(s.state);
  v.phase = s.phase;
  v.phase_name = s.state == TaskState::kAlign ? controller_->phase_name(s.phase) : "";
  v.fault = static_cast<std::uint16_t>(s.fault);
  v.fault_name = dockcore::to_string(s.fault);
  v.watchdog_fault = static_cast<std::uint16_t>(watchdog_fault);
  v.retries = s.retries;
  v.dock_id = s.dock_id;
  v.dock_valid = s.dock_valid;
  v.dock_x_m = static_cast<double>(s.dock_pose.x_m);
  v.dock_y_m = static_cast<double>(s.dock_pose.y_m);
  v.dock_yaw_deg = deg(s.dock_pose.yaw_rad);
  v.last_command = dockcore::to_string(s.last_command);
  v.last_result = to_string_result(s.last_result);
  v.charge_enable = s.charge_enable;
  v.contact = fb_.charging_contact;
  v.charge_current_a = static_cast<double>(fb_.battery_current_a);
  v.battery_v = static_cast<double>(fb_.battery_voltage_v);
  v.soc = static_cast<double>(fb_.soc);
  v.estop = fb_.estop;
  v.lidar_stale = lidar_stale();
  v.chassis_stale = chassis_stale();
  v.odom_x_m = static_cast<double>(odom_pose().x_m);
  v.odom_y_m = static_cast<double>(odom_pose().y_m);
  v.odom_yaw_deg = deg(odom_pose().yaw_rad);
  v.cmd_vx_mps = static_cast<double>(core_->drive_cmd().vx_mps);
  v.cmd_wz_radps = static_cast<double>(core_->drive_cmd().wz_radps);
  v.wheels = dockcore::drive_wheel_count(core_->config().drive.kind);
  for (std::size_t i = 0; i < v.wheels; ++i) {
    v.deadband_fwd_radps[i] = static_cast<double>(db.floor_radps(i, false));
    v.deadband_rev_radps[i] = static_cast<double>(db.floor_radps(i, true));
  }
  v.deadband_raises = db.raises();
  v.mount_swings = core_->task_manager().calibrations();
  v.mount_calibration = dockcore::to_string(core_->task_manager().last_calibration().status);
  v.mount_x_m = static_cast<double>(core_->lidar_mount().x_m);
  v.mount_y_m = static_cast<double>(core_->lidar_mount().y_m);
  v.teaching = teach_.active();
  v.taught = state_.find(s.dock_id) != nullptr;
  v.ticks = stats_.ticks;
  v.tick_worst_us = stats_.worst_period_us;
  v.tick_overruns = stats_.overruns;
  v.tick_work_worst_us = stats_.worst_work_us;
  v.scans = counters_.scans;
  v.detections = counters_.detections;
  v.lidar_crc_errors = lc.crc_errors;
  v.lidar_resyncs = lc.resyncs;
  v.lidar_dropped_bytes = lc.dropped_bytes;
  v.lidar_foreign_datagrams = lc.foreign_datagrams;
  v.lidar_reconnects = lc.reconnects;
  v.lidar_late_scans = core_->inputs().late_scans();
  v.lidar_intensity = dockcore::to_string(core_->intensity().verdict());
  v.can_bad_frames = cc.bad_frames;
  v.can_send_failures = cc.send_failures;
  v.commands = counters_.commands;
  v.commands_rejected = commands_rejected_total();
  v.resumes = counters_.resumes;
  v.can_host_rejected = host_.can_rejected();
  v.udp_not_allowed = host_.udp_not_allowed();
  v.replies_too_long = counters_.replies_too_long;
  v.config_reloads = counters_.config_reloads;
  v.config_reloads_rejected = counters_.config_reloads_rejected;
  v.learned_saves = counters_.learned_saves;
  v.learned_save_failures = counters_.learned_save_failures;
  v.config_reload_pending = pending_cfg_ != nullptr;
  v.det_found = e.found;
  v.det_evidence_nats = static_cast<double>(e.evidence.total_nats);
  for (std::size_t i = 0; i < dockcore::kEvidenceCueCount; ++i) {
    v.det_cues_nats[i] = static_cast<double>(e.evidence.cue_nats[i]);
  }
  v.det_reject = e.found ? "none" : dockcore::to_string(e.reject);
  v.det_code = code_reading(*core_);
  v.det_code_dock = code_dock_id();
  v.dock_evidence_nats = static_cast<double>(core_->filter().evidence_nats());
  v.dock_confirmed = core_->filter().confirmed();
  return v;
}

CameraValues Daemon::camera_values() const {
  CameraValues v;
  v.has_tags = io_.tags != nullptr;
  for (std::size_t i = 0; i < dockcore::kTagStatusCount; ++i) v.tags[i] = counters_.tags[i];
  v.has_stall_watch = io_.camera_frames != nullptr;
  v.stalled = camera_stalled_;
  v.has_camera = io_.camera_status != nullptr;
  if (v.has_camera) v.camera = io_.camera_status->camera_status();
  return v;
}

}  // namespace dockd
