#pragma once
/// @file The docking controller interface: dock estimate + camera target + odometry + time in, body twist out.
/// Every controller (seed000, seed004, seed003, smooth) implements DockingController; the task manager drives one
/// and turns its twist into wheel speeds with the kinematics module. No heap: controllers are plain members.

#include <cstdint>

#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"

namespace dockcore {

/// Body velocity in the robot frame: x forward, y left, yaw rate counter-clockwise.
struct Twist2 {
  Real vx_mps = 0;
  Real vy_mps = 0;  ///< Always 0 for differential drives.
  Real wz_radps = 0;
};

/// A camera's view of the dock target (seed 003): pixel coordinates from any vision process.
struct CameraTarget {
  bool valid = false;
  Real u_px = 0;  ///< Column of the target centre.
  Real v_px = 0;  ///< Row of the target centre.
  Real confidence = 0;       ///< 0..1 as reported by the vision process.
  std::uint64_t stamp_us = 0;///< Time of the image, same clock as ControlInput::now_us.
};

/// Pinhole intrinsics and mounting of the camera, for controllers that use it.
struct CameraModel {
  Real fx_px = 500;
  Real cx_px = 320;
  Real image_width_px = 640;
  Pose2 mount{};  ///< Camera optical axis (x forward) in the robot frame.
};

/// Everything a controller sees on one control tick (50 Hz in dockd).
struct ControlInput {
  std::uint64_t now_us = 0;  ///< Monotonic time of this tick.
  Real dt_s = 0;             ///< Time since the previous tick (> 0).
  bool dock_valid = false;   ///< A current (filtered) dock estimate exists.
  /// The estimate rests on at least two agreeing detections (DockInput::confirmed). One detection alone may be
  /// clutter: a controller may approach it more cautiously.
  bool dock_confirmed = true;
  Pose2 dock_in_robot{};     ///< Dock frame (origin at the contacts, x out of the face) in the robot frame.
  Mat3 dock_covariance = Mat3::Zero();
  std::uint64_t dock_stamp_us = 0;  ///< Time of the scan behind the estimate.
  Pose2 odom_pose{};         ///< Robot in the odometry frame.
  Twist2 measured_twist{};   ///< From wheel odometry.
  CameraTarget camera{};
  const ScanView* scan = nullptr;  ///< Latest scan (lidar frame), may be null. Valid for this call only.
  Pose2 lidar_mount{};       ///< Lidar in the robot frame.
  bool contact = false;      ///< Charging contacts closed (chassis report).
  bool charging = false;     ///< Charging current flowing (chassis report).
  /// Aim this far beside the dock's axis, m along the dock frame's y: the task manager's lateral search on retries
  /// (TaskParams::retry_lateral_step_m). `smooth` honours it; the seeds' controllers keep their published method.
  Real aim_lateral_m = 0;
};

/// How a controller's run is going.
enum class ControlStatus : std::uint8_t {
  kRunning = 0,  ///< Keep calling step().
  kArrived = 1,  ///< At the contacts (contact closed or the controller's own success test): it commands zero.
  kLost = 2,     ///< The target is not visible; the controller commands zero and waits (the task manager decides).
  kFailed = 3,   ///< The controller cannot continue from here (e.g. its geometry says retry from staging).
};

const char* to_string(ControlStatus s);

struct ControlOutput {
  Twist2 cmd{};                              ///< Body twist to command, before kinematics and saturation.
  ControlStatus status = ControlStatus::kRunning;
  std::uint8_t phase = 0;                    ///< Controller-specific sub-state (stable codes, see phase_name()).
};

/// A docking controller. Implementations hold only fixed-size state; reset() before every run.
class DockingController {
 public:
  /// Short stable name ("seed000", "seed004", "seed003", "smooth").
  virtual const char* name() const = 0;
  /// Name of a phase code returned in ControlOutput::phase. Never null.
  virtual const char* phase_name(std::uint8_t phase) const = 0;
  /// Forgets the previous run. O(1).
  virtual void reset() = 0;
  /// One control tick. Must return a zero twist whenever status != kRunning. O(1) (bounded per tick).
  virtual ControlOutput step(const ControlInput& in) = 0;

 protected:
  // Not virtual and protected: controllers are never deleted through this interface (no heap in core), and a
  // virtual destructor would pull operator delete into the core library.
  ~DockingController() = default;
};

}  // namespace dockcore
