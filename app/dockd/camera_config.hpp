#pragma once
/// @file dockd's own camera — V4L2 capture and AprilTag detection (docs/camera.md) — in the configuration: what
/// the sub-tables [camera.device], [camera.intrinsics], [camera.mount] and [camera.tag] of [camera] hold (read and
/// checked as one block by camera_config_keys.hpp; every key, unit, default and range in docs/camera.md).

#include <cstdint>
#include <string>
#include <vector>

#include "dockcore/control/controllers.hpp"
#include "dockcore/drivers/apriltag_detector.hpp"
#include "dockcore/drivers/v4l2_camera.hpp"

namespace dockd {

/// The camera's pose on the robot: position in the robot frame and its optical axis' yaw, pitch and roll.
struct CameraMount {
  double x_m = 0, y_m = 0, z_m = 0;
  double yaw_rad = 0;    ///< About the robot's z (counter-clockwise seen from above); 0 = looking forward.
  double pitch_rad = 0;  ///< Positive = looking down.
  double roll_rad = 0;   ///< About the optical axis.
};

struct CameraDeviceConfig {
  bool enabled = false;  ///< [camera.device] given: dockd captures and detects itself.
  dockcore::drivers::V4l2CameraOptions capture{};
  dockcore::drivers::TagDetectorOptions tag{};  ///< Family, size, tuning and (copied in) the intrinsics.
  CameraMount mount{};
  double full_confidence_margin = 100;  ///< Decision margin reported as confidence 1.
  /// No frame from the camera for this long → camera_stalled (a status flag and an event; the docking goes on with
  /// the lidar). Checked on every control tick.
  std::uint32_t stall_ms = 200;
};

}  // namespace dockd
