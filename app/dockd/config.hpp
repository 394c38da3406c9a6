#pragma once
/// @file dockd's configuration: one TOML file (docs/dockd.md lists every key with unit, default and range).
/// Errors — unknown key, wrong type, value out of range, unknown profile, duplicate dock id — are ConfigError
/// exceptions whose message starts with "<file>:<line>:<column>: " (1-based, the key or value at fault).
/// Start-up only: heap and exceptions are fine here.

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "camera_config.hpp"
#include "dockcore/control/controllers.hpp"
#include "dockcore/control/kinematics.hpp"
#include "dockcore/control/safety.hpp"
#include "dockcore/control/wheel_deadband.hpp"
#include "dockcore/dockcore.hpp"
#include "dockcore/drivers/can_link.hpp"
#include "dockcore/drivers/lidar_driver.hpp"
#include "dockcore/drivers/udp_camera.hpp"
#include "dockcore/drivers/udp_host_link.hpp"
#include "dockcore/geometry.hpp"
#include "dockcore/perception/dock_pose_estimator.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "dockcore/perception/reflector_read.hpp"
#include "dockcore/perception/tag_measurement.hpp"
#include "dockcore/task/input_watch.hpp"
#include "dockcore/task/task_manager.hpp"

namespace dockd {

using dockcore::Pose2;

class ConfigError : public std::runtime_error {
 public:
  ConfigError(const std::string& message, int line = 0, int column = 0)
      : std::runtime_error(message), line_(line), column_(column) {}
  int line() const { return line_; }      ///< 1-based; 0 when not tied to a position.
  int column() const { return column_; }  ///< 1-based; 0 when not tied to a position.

 private:
  int line_;
  int column_;
};

/// One dock of the dock database ([[docks]]).
struct DockEntry {
  std::uint16_t id = 0;                 ///< 0..31 (the task manager's accepted-id mask).
  std::string profile_ref = "plate-v";  ///< Built-in name or profile file path (as written).
  dockcore::DockProfile profile{};
  /// Configured docked-pose target: where the dock appears in the robot frame when the robot is docked. Absent =
  /// the nominal pose from the pads (pad_reach_m ahead, facing the robot). A taught target (state file) wins.
  bool has_target = false;
  Pose2 target{};
  /// The dock's AprilTag (docs/camera.md, "Fusion"): id −1 = none. Its place is in this dock's frame (before a
  /// taught or configured target corrects the frame; dockd maps it with the profile).
  dockcore::DockTag tag{};
  /// Which detector finds this dock (the parameter table's docks.detector); checked against the profile.
  dockcore::DockDetector detector = dockcore::DockDetector::kEstimator;
};

enum class LogLevel : std::uint8_t { kError = 0, kWarn = 1, kInfo = 2, kDebug = 3 };
/// "error" | "warn" | "info" | "debug"; false otherwise.
bool parse_log_level(const std::string& s, LogLevel& out);

struct DockdConfig {
  std::string source;  ///< File it came from.

  // [lidar]
  dockcore::drivers::LidarDriverOptions lidar{};
  Pose2 lidar_mount{};

  // [can]
  std::string can_interface = "can0";
  dockcore::drivers::CanLinkOptions can{};
  double status_rate_hz = 10.0;  ///< CAN + UDP status stream rate (plus one on every change).

  // [robot]
  dockcore::DriveGeometry drive{};
  dockcore::DriveLimits limits{};
  dockcore::FootprintParams footprint{};
  double pad_reach_m = 0.225;
  bool pads_rear = false;

  // [[docks]] / [dock]
  std::vector<DockEntry> docks;
  std::uint16_t default_dock_id = 0;  ///< Used when a dock command names no dock.

  // [controller]
  std::string controller = "smooth";
  dockcore::Seed000Params seed000{};
  dockcore::Seed004Params seed004{};
  dockcore::Seed003Params seed003{};
  dockcore::SmoothParams smooth{};

  // [task], [estimator]
  dockcore::TaskParams task{};
  dockcore::EstimatorParams estimator{};

  // [host]
  bool host_enabled = true;
  dockcore::drivers::UdpHostLinkOptions host{};

  // [camera]
  bool camera_enabled = false;  ///< The UDP datagram input (external detectors).
  dockcore::drivers::UdpCameraOptions camera{};
  /// [camera.device], [camera.intrinsics], [camera.mount], [camera.tag]: dockd's own capture and detector
  /// (camera_config.hpp, docs/camera.md). target_id and max_age_ms above apply to it too.
  CameraDeviceConfig camera_device{};
  /// [camera.fusion]: the tag covariance model and time bound (the parameter table); the camera's mount, focal
  /// length and tag size come from [camera.mount], [camera.intrinsics], [camera.tag], the tag's place from [[docks]].
  dockcore::TagFusionParams tag_fusion{};

  // [record]
  std::string record_dir;                      ///< "" = no session record.
  std::uint64_t record_max_bytes = 16u << 20;  ///< Per file before rotation.
  std::uint32_t record_max_files = 8;          ///< Rotated files kept per log.
  /// Also record every call into the core (DIR/loop.rec, for `dock-sim replay`); it stops growing at
  /// record_max_bytes × record_max_files.
  bool record_loop = false;

  // [watchdog]
  dockcore::WatchdogParams watchdog{};         ///< [watchdog]: the core's input watch (the parameter table).
  dockcore::WheelDeadbandParams deadband{};    ///< [robot.deadband]: the drive's wheel deadband (the parameter table).
  dockcore::IntensityCheckParams intensity{};  ///< [intensity]: the lidar intensity check (the parameter table).
  std::uint32_t systemd_watchdog_divider = 2;  ///< WATCHDOG=1 every WatchdogSec / this.

  // [state]
  std::string state_file = "/var/lib/dockcore/dockd.state";
  std::uint16_t teach_scans = 20;   ///< Default scans averaged by teach.
  double teach_timeout_s = 10.0;    ///< Teach gives up when it has not collected its scans within this.

  // [log]
  LogLevel log_level = LogLevel::kInfo;

  /// The dock with `id`, or nullptr.
  const DockEntry* find_dock(std::uint16_t id) const;
};

/// How dockd reads a dock's reflector stripes (teach, and the code in the status): the estimator's inlier gate,
/// reflector threshold, blind zone and inlier floor. O(1).
dockcore::StripeReadParams stripe_read_params(const DockdConfig& c);

/// Input caps (docs/reliability.md, "Security"): beyond them the file is refused with a ConfigError, so no config or
/// profile file can make dockd (or --check-config, or a SIGHUP reload) use unbounded memory or block.
constexpr std::size_t kMaxConfigBytes = 1u << 20;        ///< Config file / text, bytes.
constexpr std::size_t kMaxProfileFileBytes = 64u << 10;  ///< A dock profile file, bytes.
constexpr std::size_t kMaxAllowlistEntries = 64;         ///< host.allowlist entries.
/// [[docks]] entries are bounded by their unique ids 0..31: at most 32.

/// Parses config TOML held in `text`. `source_name` names it in messages and anchors relative profile paths.
/// Throws ConfigError. O(text size).
DockdConfig parse_config_toml(const std::string& text, const std::string& source_name);
/// Reads and parses a config file. Throws ConfigError (also when it cannot be read, is not a regular file or is
/// larger than kMaxConfigBytes).
DockdConfig load_config_file(const std::string& path);

/// The restart-only keys (docs/dockd.md, "Config reload") whose values differ between `running` and `next`, as
/// "section.key" names in file order; empty when `next` can be applied at runtime. O(config size).
std::vector<std::string> restart_only_changes(const DockdConfig& running, const DockdConfig& next);

/// The nominal docked-pose target for the configured pads: the dock at (pad_reach, 0) facing the robot (yaw π);
/// rear pads: (−pad_reach, 0), yaw 0. O(1).
Pose2 nominal_docked_target(const DockdConfig& c);

/// The profile the estimator must use so that a robot whose dock appears at `target` when docked is told the
/// nominal target instead: vertices mapped by nominal⁻¹ ∘ target (so the controllers' fixed docked pose lands
/// where the taught or configured one is). Identity when target == nominal. O(vertices).
dockcore::DockProfile profile_for_target(const dockcore::DockProfile& profile, const Pose2& nominal,
                                         const Pose2& target);

}  // namespace dockd
