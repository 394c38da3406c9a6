// dockd: the status object's writer, from values the daemon (or a test) gathered.
#include "status.hpp"

#include <cmath>
#include <limits>

namespace dockd {

namespace {

/// `v`, or NaN (written as null) at kStatusRealLimit or beyond.
double reading(double v) {
  return std::fabs(v) < kStatusRealLimit ? v : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

void write_status(JsonWriter& w, const StatusValues& v) {
  double db_fwd[dockcore::kMaxDriveWheels];
  double db_rev[dockcore::kMaxDriveWheels];
  const std::size_t wheels = v.wheels < dockcore::kMaxDriveWheels ? v.wheels : dockcore::kMaxDriveWheels;
  for (std::size_t i = 0; i < wheels; ++i) {
    db_fwd[i] = reading(v.deadband_fwd_radps[i]);
    db_rev[i] = reading(v.deadband_rev_radps[i]);
  }
  double cues[dockcore::kEvidenceCueCount];
  for (std::size_t i = 0; i < dockcore::kEvidenceCueCount; ++i) cues[i] = reading(v.det_cues_nats[i]);
  w.str("type", "status")
      .uint("stamp_us", v.stamp_us)
      .str("state", v.state)
      .uint("state_code", v.state_code)
      .uint("phase", v.phase)
      .str("phase_name", v.phase_name)
      .uint("fault", v.fault)
      .str("fault_name", v.fault_name)
      .uint("watchdog_fault", v.watchdog_fault)
      .uint("retries", v.retries)
      .uint("dock_id", v.dock_id)
      .boolean("dock_valid", v.dock_valid)
      .real("dock_x_m", reading(v.dock_x_m), 4)
      .real("dock_y_m", reading(v.dock_y_m), 4)
      .real("dock_yaw_deg", reading(v.dock_yaw_deg), 2)
      .str("last_command", v.last_command)
      .str("last_result", v.last_result)
      .boolean("charge_enable", v.charge_enable)
      .boolean("contact", v.contact)
      .real("charge_current_a", reading(v.charge_current_a), 2)
      .real("battery_v", reading(v.battery_v), 2)
      .real("soc", reading(v.soc), 3)
      .boolean("estop", v.estop)
      .boolean("lidar_stale", v.lidar_stale)
      .boolean("chassis_stale", v.chassis_stale)
      .real("odom_x_m", reading(v.odom_x_m), 4)
      .real("odom_y_m", reading(v.odom_y_m), 4)
      .real("odom_yaw_deg", reading(v.odom_yaw_deg), 2)
      .real("cmd_vx_mps", reading(v.cmd_vx_mps), 3)
      .real("cmd_wz_radps", reading(v.cmd_wz_radps), 3)
      .reals("deadband_fwd_radps", db_fwd, wheels, 2)
      .reals("deadband_rev_radps", db_rev, wheels, 2)
      .uint("deadband_raises", v.deadband_raises)
      .boolean("teaching", v.teaching)
      .boolean("taught", v.taught)
      .str("lidar_intensity", v.lidar_intensity)
      .boolean("config_reload_pending", v.config_reload_pending)
      .boolean("det_found", v.det_found)
      .real("det_evidence_nats", reading(v.det_evidence_nats), 1)
      .reals("det_cues_nats", cues, dockcore::kEvidenceCueCount, 1)
      .str("det_reject", v.det_reject)
      .str("det_code", v.det_code)
      .sint("det_code_dock", v.det_code_dock)
      .real("dock_evidence_nats", reading(v.dock_evidence_nats), 1)
      .boolean("dock_confirmed", v.dock_confirmed);
  // The counters are the status's widest group (up to 20 digits each): left out whole when they do not fit, so the
  // task, the dock and the detection always reach the host. The counters part always carries them.
  w.optional_group([&] { write_counters(w, v); });
}

void write_mount(JsonWriter& w, const StatusValues& v) {
  w.uint("mount_swings", v.mount_swings)
      .str("mount_calibration", v.mount_calibration)
      .real("mount_x_m", reading(v.mount_x_m), 4)
      .real("mount_y_m", reading(v.mount_y_m), 4);
}

void write_counters_part(JsonWriter& w, const StatusValues& v) {
  write_counters(w, v);
  write_mount(w, v);
  w.uint("learned_saves", v.learned_saves).uint("learned_save_failures", v.learned_save_failures);
}

void write_counters(JsonWriter& w, const StatusValues& v) {
  w.uint("ticks", v.ticks)
      .uint("tick_worst_us", v.tick_worst_us)
      .uint("tick_overruns", v.tick_overruns)
      .uint("tick_work_worst_us", v.tick_work_worst_us)
      .uint("scans", v.scans)
      .uint("detections", v.detections)
      .uint("lidar_crc_errors", v.lidar_crc_errors)
      .uint("lidar_resyncs", v.lidar_resyncs)
      .uint("lidar_dropped_bytes", v.lidar_dropped_bytes)
      .uint("lidar_foreign_datagrams", v.lidar_foreign_datagrams)
      .uint("lidar_reconnects", v.lidar_reconnects)
      .uint("lidar_late_scans", v.lidar_late_scans)
      .uint("can_bad_frames", v.can_bad_frames)
      .uint("can_send_failures", v.can_send_failures)
      .uint("commands", v.commands)
      .uint("commands_rejected", v.commands_rejected)
      .uint("resumes", v.resumes)
      .uint("can_host_rejected", v.can_host_rejected)
      .uint("udp_not_allowed", v.udp_not_allowed)
      .uint("replies_too_long", v.replies_too_long)
      .uint("config_reloads", v.config_reloads)
      .uint("config_reloads_rejected", v.config_reloads_rejected);
}

void write_camera_groups(JsonWriter& w, const CameraValues& v, bool only_if_fits) {
  const auto group = [&w, only_if_fits](auto&& write) {
    if (only_if_fits) {
      w.optional_group(write);
    } else {
      write();
    }
  };
  // The tag fusion's counters (docs/camera.md, "Status").
  if (v.has_tags) {
    group([&] { w.uint("tag_fused", v.tags[0]).uints("tag_refused", v.tags + 1, dockcore::kTagStatusCount - 1); });
  }
  // The stall watchdog's flag only, as for the lidar: the count is in the watchdog event.
  if (v.has_stall_watch) group([&] { w.boolean("camera_stalled", v.stalled); });
  // The own camera's fields (camera-check reports the rest).
  if (v.has_camera) {
    const dockcore::hal::CameraStatus& c = v.camera;
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
