#pragma once
/// @file dockd's own camera — V4L2 capture and AprilTag detection (docs/camera.md) — in the configuration: the
/// sub-tables [camera.device], [camera.intrinsics], [camera.mount] and [camera.tag] of [camera], read and checked
/// here as one block (every key, unit, default and range in docs/camera.md). [camera.device] turns the capture on;
/// intrinsics and the tag size are then required. Missing or inconsistent keys are ConfigErrors naming the key.

#include <cstdint>
#include <string>
#include <vector>

#include "dockcore/controllers.hpp"
#include "dockcore/drivers/apriltag_detector.hpp"
#include "dockcore/drivers/toml_reader.hpp"
#include "dockcore/drivers/v4l2_camera.hpp"

namespace dockd {

class ConfigError;
struct DockdConfig;

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
};

using ConfigReader = dockcore::drivers::toml_reader::Reader<ConfigError>;

/// Appends the handlers of [camera]'s sub-tables (device, intrinsics, mount, tag) to `h`, storing into `c`.
void add_camera_device_keys(const ConfigReader& p, dockcore::drivers::toml_reader::Handlers& h, CameraDeviceConfig& c);

/// After the whole file is read: required keys, cross-key checks (principal point inside the image, fx/fy ratio,
/// YUYV width, reconnect delays), and the seed003 controller's camera model taken from the camera (an explicit
/// controller.seed003 camera key that disagrees with it is an error). Throws ConfigError. O(1).
void finish_camera_device(const ConfigReader& p, const toml::source_region& root, DockdConfig& c);

/// Appends the names of the camera keys that differ (every one of them is restart-only: the device is opened and the
/// detector built once at start).
void camera_device_restart_changes(const CameraDeviceConfig& a, const CameraDeviceConfig& b, std::vector<std::string>& out);

}  // namespace dockd
