#pragma once
/// @file Reading dockd's camera block ([camera.device], [camera.intrinsics], [camera.mount], [camera.tag];
/// camera_config.hpp, docs/camera.md) with the config's TOML reader. [camera.device] turns the capture on; the
/// intrinsics and the tag size are then required. Missing or inconsistent keys are ConfigErrors naming the key.
/// Used by config.cpp only (the reader is dockd_lib's private dependency).

#include <string>
#include <vector>

#include "camera_config.hpp"
#include "dockcore/params/toml_reader.hpp"

namespace dockd {

class ConfigError;
struct DockdConfig;

using ConfigReader = dockcore::params::toml_reader::Reader<ConfigError>;

/// Appends the handlers of [camera]'s sub-tables (device, intrinsics, mount, tag) to `h`, storing into `c`.
void add_camera_device_keys(const ConfigReader& p, dockcore::params::toml_reader::Handlers& h, CameraDeviceConfig& c);

/// After the whole file is read: required keys, cross-key checks (principal point inside the image, fx/fy ratio,
/// YUYV width, stall window against the frame rate, reconnect delays), and the seed003 controller's camera model taken
/// from the camera (an explicit controller.seed003 camera key that disagrees with it is an error). Throws ConfigError.
/// O(1).
void finish_camera_device(const ConfigReader& p, const toml::source_region& root, DockdConfig& c);

/// Appends the names of the camera keys that differ (every one of them is restart-only: the device is opened and the
/// detector built once at start).
void camera_device_restart_changes(const CameraDeviceConfig& a, const CameraDeviceConfig& b,
                                   std::vector<std::string>& out);

}  // namespace dockd
