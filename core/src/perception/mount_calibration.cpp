#include "dockcore/perception/mount_calibration.hpp"

#include <cmath>

namespace dockcore {

const char* to_string(MountCalibrationStatus s) {
  switch (s) {
    case MountCalibrationStatus::kNone:
      return "none";
    case MountCalibrationStatus::kOk:
      return "ok";
    case MountCalibrationStatus::kTooFewDetections:
      return "too_few_detections";
    case MountCalibrationStatus::kTooNarrow:
      return "too_narrow";
    case MountCalibrationStatus::kPoorFit:
      return "poor_fit";
    case MountCalibrationStatus::kTooFar:
      return "too_far";
    case MountCalibrationStatus::kInterrupted:
      return "interrupted";
  }
  return "unknown";
}

void MountCalibration::begin(const Pose2& mount, const Pose2& odom_start) {
  mount_ = mount;
  odom_start_ = odom_start;
  // The robot's centre in the lidar frame, as the mount puts it.
  const Vec2 centre = mount.inverse_transform(Vec2(0, 0));
  centre_x_m_ = centre.x();
  centre_y_m_ = centre.y();
  n_ = 0;
  su_ = sz_ = suu_ = suz_ = szz_ = 0;
  min_bearing_rad_ = max_bearing_rad_ = 0;
}

void MountCalibration::add(const Pose2& dock_in_lidar, const Pose2& odom_at_scan) {
  // Where the dock would be seen had the robot only turned: its centre's odometry translation since the start,
  // taken into the lidar frame, is added back. The translation is millimetres, so the mount's configured turn and
  // the odometry's heading are exact enough for it.
  const Vec2 moved(odom_at_scan.x_m - odom_start_.x_m, odom_at_scan.y_m - odom_start_.y_m);
  const Real c = std::cos(odom_at_scan.yaw_rad + mount_.yaw_rad);
  const Real s = std::sin(odom_at_scan.yaw_rad + mount_.yaw_rad);
  const Real x = dock_in_lidar.x_m + c * moved.x() + s * moved.y();
  const Real y = dock_in_lidar.y_m - s * moved.x() + c * moved.y();
  const Real dx = x - centre_x_m_;
  const Real u = y - centre_y_m_;
  // Relative to the first detection's: z is the squared distance from the centre, nearly the same for every
  // detection, and the sums of the differences keep their digits in a float build.
  const Real z = dx * dx + u * u;
  const Real bearing = std::atan2(u, dx);
  if (n_ == 0) {
    z0_ = z;
    bearing0_rad_ = bearing;
  }
  const Real dz = z - z0_;
  const Real db = wrap_angle(bearing - bearing0_rad_);
  su_ += u;
  sz_ += dz;
  suu_ += u * u;
  suz_ += u * dz;
  szz_ += dz * dz;
  min_bearing_rad_ = db < min_bearing_rad_ ? db : min_bearing_rad_;
  max_bearing_rad_ = db > max_bearing_rad_ ? db : max_bearing_rad_;
  if (n_ < 0xFFFF) ++n_;
}

MountCalibrationResult MountCalibration::solve(Real max_correction_m) const {
  MountCalibrationResult r;
  r.mount = mount_;
  r.detections = n_;
  r.sweep_rad = max_bearing_rad_ - min_bearing_rad_;
  if (n_ < kMinDetections) {
    r.status = MountCalibrationStatus::kTooFewDetections;
    return r;
  }
  if (r.sweep_rad < kMinSweepRad) {
    r.status = MountCalibrationStatus::kTooNarrow;
    return r;
  }
  // Least squares of dz = a·u + b: a = 2·c, c the centre's sideways offset from the configured one.
  const Real n = static_cast<Real>(n_);
  const Real mu = su_ / n;
  const Real mz = sz_ / n;
  const Real cuu = suu_ - n * mu * mu;
  const Real cuz = suz_ - n * mu * mz;
  const Real czz = szz_ - n * mz * mz;
  if (!(cuu > 0)) {
    r.status = MountCalibrationStatus::kTooNarrow;
    return r;
  }
  const Real a = cuz / cuu;
  const Real offset = a / 2;
  // The fit's residual in z is 2ρ times the distance from the circle (ρ its radius).
  const Real rss = czz - a * cuz;
  const Real rho_sq = z0_ + mz - a * mu + offset * offset;
  const Real rho = rho_sq > 0 ? std::sqrt(rho_sq) : static_cast<Real>(0);
  r.rms_m = rho > 0 ? std::sqrt((rss > 0 ? rss : static_cast<Real>(0)) / n) / (2 * rho) : static_cast<Real>(0);
  if (!(rho > 0) || !(r.rms_m <= kMaxRmsM)) {
    r.status = MountCalibrationStatus::kPoorFit;
    return r;
  }
  // The centre seen `offset` to the lidar's left puts the lidar that far to its own right.
  r.lateral_error_m = -offset;
  if (!(std::fabs(r.lateral_error_m) <= max_correction_m)) {
    r.status = MountCalibrationStatus::kTooFar;
    return r;
  }
  const Real c = std::cos(mount_.yaw_rad);
  const Real s = std::sin(mount_.yaw_rad);
  r.mount.x_m = mount_.x_m - s * r.lateral_error_m;
  r.mount.y_m = mount_.y_m + c * r.lateral_error_m;
  r.status = MountCalibrationStatus::kOk;
  return r;
}

}  // namespace dockcore
