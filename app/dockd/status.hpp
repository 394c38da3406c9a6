#pragma once
/// @file The status object (docs/dockd.md, "Status fields"): every value it carries, and its writer. Daemon gathers
/// the values from its members at one instant and write_status() writes them, so the status can also be written from
/// any values a test chooses — its longest form must fit one datagram (hal::kMaxHostReply) with the reply's prefix.
/// No allocation; every call is O(bytes written).

#include <cstddef>
#include <cstdint>

#include "dockcore/control/kinematics.hpp"
#include "dockcore/hal/camera.hpp"
#include "dockcore/perception/dock_pose_estimator.hpp"
#include "dockcore/perception/tag_measurement.hpp"
#include "json_writer.hpp"

namespace dockd {

/// A status real of this magnitude or more, in its unit, is written as null: no reading of a docking robot comes near
/// (10^6 m, degrees, volts, amps, rad/s or nats), and it bounds every real's printed width.
constexpr double kStatusRealLimit = 1e6;

/// Every value of the main status object, in its order. Strings are static names (never null, except phase_name:
/// null writes ""). Integer types are those of the values' sources.
struct StatusValues {
  std::uint64_t stamp_us = 0;
  const char* state = "";
  std::uint8_t state_code = 0;
  std::uint8_t phase = 0;
  const char* phase_name = "";
  std::uint16_t fault = 0;
  const char* fault_name = "";
  std::uint16_t watchdog_fault = 0;
  std::uint8_t retries = 0;
  std::uint16_t dock_id = 0;
  bool dock_valid = false;
  double dock_x_m = 0, dock_y_m = 0, dock_yaw_deg = 0;
  const char* last_command = "";
  const char* last_result = "";
  bool charge_enable = false;
  bool contact = false;
  double charge_current_a = 0, battery_v = 0, soc = 0;
  bool estop = false, lidar_stale = false, chassis_stale = false;
  double odom_x_m = 0, odom_y_m = 0, odom_yaw_deg = 0;
  double cmd_vx_mps = 0, cmd_wz_radps = 0;
  std::size_t wheels = 0;  ///< Entries of the deadband arrays written (≤ kMaxDriveWheels).
  double deadband_fwd_radps[dockcore::kMaxDriveWheels] = {};
  double deadband_rev_radps[dockcore::kMaxDriveWheels] = {};
  std::uint32_t deadband_raises = 0;
  std::uint32_t mount_swings = 0;       ///< Calibration swings ended since the core was configured.
  const char* mount_calibration = "";   ///< The last swing's result (MountCalibrationStatus name).
  double mount_x_m = 0, mount_y_m = 0;  ///< The lidar mount in use (the configured one moved by the swing).
  bool teaching = false, taught = false;
  std::uint64_t ticks = 0, tick_worst_us = 0, tick_overruns = 0, tick_work_worst_us = 0;
  std::uint32_t scans = 0, detections = 0;
  std::uint32_t lidar_crc_errors = 0, lidar_resyncs = 0, lidar_dropped_bytes = 0, lidar_foreign_datagrams = 0;
  std::uint32_t lidar_reconnects = 0, lidar_late_scans = 0;
  const char* lidar_intensity = "";
  std::uint32_t can_bad_frames = 0, can_send_failures = 0;
  std::uint32_t commands = 0, commands_rejected = 0, resumes = 0, can_host_rejected = 0, udp_not_allowed = 0;
  std::uint32_t replies_too_long = 0;
  std::uint32_t config_reloads = 0, config_reloads_rejected = 0;
  std::uint32_t learned_saves = 0, learned_save_failures = 0;
  bool config_reload_pending = false;
  bool det_found = false;
  double det_evidence_nats = 0;
  double det_cues_nats[dockcore::kEvidenceCueCount] = {};
  const char* det_reject = "";
  const char* det_code = "";
  int det_code_dock = -1;
  double dock_evidence_nats = 0;
  bool dock_confirmed = false;
};

/// The camera part's values: the tag fusion's counters, the own camera's stall flag and its state, each group
/// present only when dockd has that input.
struct CameraValues {
  bool has_tags = false;
  std::uint32_t tags[dockcore::kTagStatusCount] = {};  ///< Index dockcore::TagStatus; [0] fused, the rest refused.
  bool has_stall_watch = false;
  bool stalled = false;
  bool has_camera = false;
  dockcore::hal::CameraStatus camera{};
};

/// Writes the main status fields of `v` into `w` (the caller adds any prefix and finishes it), its counters
/// (write_counters) last, left out whole when they do not fit `w` (which then stays ok). O(bytes written).
void write_status(JsonWriter& w, const StatusValues& v);

/// Writes the counters of `v` (ticks, scans, lidar, CAN, host commands, reloads): the status's counters part, and
/// the group the main status drops when full. O(bytes written).
void write_counters(JsonWriter& w, const StatusValues& v);

/// Writes the task manager's lidar mount calibration of `v`: swings, the last one's result and the mount in use (in
/// the counters part after the counters; dockd adds it to the main status after the camera groups when it fits).
/// O(bytes written).
void write_mount(JsonWriter& w, const StatusValues& v);

/// Writes the counters part of the status: write_counters(), write_mount(), then the learned file's counters (files
/// written, writes that failed; only here). O(bytes written).
void write_counters_part(JsonWriter& w, const StatusValues& v);

/// Writes the camera groups present in `v`; with `only_if_fits` each group that does not fit `w` is left out whole
/// (and `w` stays ok). O(bytes written).
void write_camera_groups(JsonWriter& w, const CameraValues& v, bool only_if_fits);

}  // namespace dockd
