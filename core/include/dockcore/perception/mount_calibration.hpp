#pragma once
/// @file MountCalibration: where the lidar really sits sideways on the robot, measured by turning on the spot in front
/// of the dock (docs/task-manager.md, "Mount calibration").
///
/// A lidar bracket a centimetre off its configured pose puts every approach that centimetre beside the contacts.
/// Turning in place, the robot turns about its own centre, and the dock, standing still, moves in the lidar's view on
/// a circle about that centre: the circle's centre is the robot's centre in the lidar frame, whatever the lidar's
/// mount. Its sideways coordinate is fixed by the arc the dock sweeps to either side (about a millimetre from a ±25°
/// swing 0.6 m from a dock); its coordinate along the line of sight only by the arc's slight bend (centimetres), so
/// that one is kept as configured. A wheel that slips or stands while turning moves the centre: the odometry's
/// translation is taken out of each detection first.
///
/// Detections are dock poses in the lidar frame; only their positions are used (the dock's yaw from one scan is
/// noisier than the arc). No heap; add() O(1), solve() O(1).

#include <cstdint>

#include "dockcore/geometry.hpp"

namespace dockcore {

/// How a calibration swing ended.
enum class MountCalibrationStatus : std::uint8_t {
  kNone = 0,          ///< No swing finished since configure().
  kOk = 1,            ///< Measured; the mount was moved sideways by MountCalibrationResult::lateral_error_m.
  kTooFewDetections,  ///< Fewer than MountCalibration::kMinDetections detections during the swing.
  kTooNarrow,         ///< The dock's bearing swept less than MountCalibration::kMinSweepRad.
  kPoorFit,           ///< The detections lie farther than MountCalibration::kMaxRmsM (RMS) from any circle.
  kTooFar,            ///< The measured offset exceeds the allowed correction: the configured mount is kept.
  kInterrupted,       ///< The swing was stopped (an obstacle, or it took too long): nothing measured.
};

/// "none", "ok", "too_few_detections", "too_narrow", "poor_fit", "too_far", "interrupted". Never null.
const char* to_string(MountCalibrationStatus s);

/// One swing's result.
struct MountCalibrationResult {
  MountCalibrationStatus status = MountCalibrationStatus::kNone;
  /// The lidar's sideways offset from the mount the swing started with, along the lidar's own y axis, m (+ left).
  /// Measured for kOk and kTooFar, 0 otherwise.
  Real lateral_error_m = 0;
  /// The mount the swing started with, moved by lateral_error_m along the lidar's y axis (kOk); else unchanged.
  Pose2 mount{};
  Real rms_m = 0;      ///< Detections' RMS distance from the fitted circle, m.
  Real sweep_rad = 0;  ///< Range of the dock's bearing from the turning centre over the swing, rad.
  std::uint16_t detections = 0;
};

class MountCalibration {
 public:
  static constexpr std::uint16_t kMinDetections = 8;
  /// The swing must sweep the dock's bearing by at least this much; a narrow arc hardly fixes its centre.
  static constexpr Real kMinSweepRad = static_cast<Real>(0.5235987756);  // 30°
  /// A robot that really turned about one point leaves the detections within a few millimetres of a circle.
  static constexpr Real kMaxRmsM = static_cast<Real>(0.005);

  /// Starts a swing from the mount the detections will be made with (lidar in the robot frame) and the robot's
  /// odometry pose now. Forgets any earlier detections. O(1).
  void begin(const Pose2& mount, const Pose2& odom_start);

  /// One detection of the swing: the dock in the lidar frame (the estimate's dock-in-robot pose taken back through
  /// the mount given to begin()) and the robot's odometry pose at its scan. O(1).
  void add(const Pose2& dock_in_lidar, const Pose2& odom_at_scan);

  /// The lidar's sideways position from the detections so far, with at most max_correction_m (> 0) of change
  /// accepted. O(1).
  MountCalibrationResult solve(Real max_correction_m) const;

  std::uint16_t detections() const { return n_; }

 private:
  Pose2 mount_{};
  Pose2 odom_start_{};
  Real centre_x_m_ = 0;  ///< The robot's centre along the lidar's x axis, from the mount (kept as configured).
  Real centre_y_m_ = 0;  ///< ... and across it, as configured: the origin of the sums below.
  std::uint16_t n_ = 0;
  // Sums for the circle through the points about (centre_x_m_, centre_y_m_ + c): with u = y − centre_y_m_ and
  // z = (x − centre_x_m_)² + u², every point satisfies z = 2·c·u + (ρ² − c²), a straight line in (u, z).
  // z is taken relative to the first detection's (z0_), the bearings relative to its bearing.
  Real su_ = 0, sz_ = 0, suu_ = 0, suz_ = 0, szz_ = 0;
  Real z0_ = 0, bearing0_rad_ = 0;
  Real min_bearing_rad_ = 0, max_bearing_rad_ = 0;
};

}  // namespace dockcore
