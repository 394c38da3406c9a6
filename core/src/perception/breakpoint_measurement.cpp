#include "dockcore/perception/breakpoint_measurement.hpp"

#include <cmath>

namespace dockcore {
namespace {

/// A vertex of a moved copy may lie this far from the built-in's, m (a profile file written to the millimetre).
constexpr Real kOutlineTolM = static_cast<Real>(0.001);
/// The breakpoint dock's slot depth (its range step), m.
constexpr Real kSlotDepthM = static_cast<Real>(0.06);

bool finite(Real v) {
  return std::isfinite(v);
}

/// Variance of a point read at (range r, beam angle a) normal to a line with unit normal n (file comment): its range
/// noise along the beam, its one-beam quantisation across it, and the chance (h·tan φ over the beam spacing, at most
/// 1) that its beam met the slot's side wall instead of its bottom, short by up to h - min_jump, uniformly.
Real normal_variance(Real r, Real a, const Vec2& n, Real var_r, Real dtheta, Real min_jump_m) {
  const Vec2 u(std::cos(a), std::sin(a));
  const Vec2 across(-u.y(), u.x());
  const Real along_n = u.dot(n);
  const Real across_n = across.dot(n);
  Real v = var_r * along_n * along_n + r * r * dtheta * dtheta / 12 * across_n * across_n;
  const Real cos_phi = std::fabs(along_n);
  const Real spacing = r * dtheta;
  const Real wall = kSlotDepthM - min_jump_m;
  if (cos_phi > 0 && spacing > 0 && wall > 0) {
    const Real tan_phi = std::sqrt(1 - cos_phi * cos_phi) / cos_phi;
    const Real p_wall = kSlotDepthM * tan_phi / spacing;
    v += (p_wall < 1 ? p_wall : 1) * wall * wall / 12;
  }
  return v;
}

}  // namespace

bool breakpoint_outline_frame(const DockProfile& profile, Pose2* native_in_dock) {
  DockProfile b;
  if (builtin_profile("breakpoint", b) != ProfileError::kOk) return false;
  const std::size_t n = b.vertex_count;
  if (profile.vertex_count != n || n < 2) return false;
  const Vec2 db = b.vertices_m[n - 1] - b.vertices_m[0];
  const Vec2 dp = profile.vertices_m[n - 1] - profile.vertices_m[0];
  const Real yaw = wrap_angle(std::atan2(dp.y(), dp.x()) - std::atan2(db.y(), db.x()));
  const Pose2 rot{0, 0, yaw};
  const Vec2 t = profile.vertices_m[0] - rot.transform(b.vertices_m[0]);
  const Pose2 frame{t.x(), t.y(), yaw};
  for (std::size_t i = 0; i < n; ++i) {
    if (!((frame.transform(b.vertices_m[i]) - profile.vertices_m[i]).norm() <= kOutlineTolM)) return false;
  }
  if (native_in_dock != nullptr) *native_in_dock = frame;
  return true;
}

BreakpointParams breakpoint_params_for_scan(Real angle_increment_rad, const BreakpointParams& seed) {
  BreakpointParams p = seed;
  if (!(angle_increment_rad > 0) || !finite(angle_increment_rad)) return p;
  const Real per_deg = deg_to_rad(1) / angle_increment_rad;
  const Real offset = std::round(5 * per_deg);
  const Real spacing = std::round(7 * per_deg);
  p.neighbour_offset_idx = static_cast<std::uint16_t>(offset < 1 ? 1 : (offset > 1000 ? 1000 : offset));
  p.max_pair_spacing_idx = static_cast<std::uint16_t>(spacing < 2 ? 2 : (spacing > 1000 ? 1000 : spacing));
  return p;
}

bool breakpoint_measurement(const BreakpointDetection& d, Real angle_increment_rad, const Pose2& lidar_mount,
                            Real range_sigma_m, Pose2* dock_in_robot, Mat3* covariance, Real min_jump_m) {
  Vec2 centre;
  if (!d.dock_position_lidar(centre)) return false;
  if (!finite(angle_increment_rad) || !finite(range_sigma_m) || !finite(lidar_mount.x_m) || !finite(lidar_mount.y_m) ||
      !finite(lidar_mount.yaw_rad) || !finite(d.left_range_m) || !finite(d.right_range_m) ||
      !finite(d.left_angle_rad) || !finite(d.right_angle_rad)) {
    return false;
  }
  const Vec2 left(d.left_range_m * std::cos(d.left_angle_rad), d.left_range_m * std::sin(d.left_angle_rad));
  const Vec2 right(d.right_range_m * std::cos(d.right_angle_rad), d.right_range_m * std::sin(d.right_angle_rad));
  const Vec2 along = right - left;  // the dock's +y axis, in the lidar frame
  const Real b = along.norm();
  if (!(b > static_cast<Real>(1e-6))) return false;
  const Vec2 normal(along.y() / b, -along.x() / b);  // the dock's +x axis (out of the face)
  const Real yaw_lidar = std::atan2(normal.y(), normal.x());

  const Real var_r = range_sigma_m * range_sigma_m;
  const Real dtheta = angle_increment_rad > 0 ? angle_increment_rad : 0;
  const Real var_yaw = (normal_variance(d.left_range_m, d.left_angle_rad, normal, var_r, dtheta, min_jump_m) +
                        normal_variance(d.right_range_m, d.right_angle_rad, normal, var_r, dtheta, min_jump_m)) /
                       (b * b);
  const Real rc = d.centre_range_m;
  const Vec2 u(std::cos(d.centre_angle_rad), std::sin(d.centre_angle_rad));
  const Vec2 across(-u.y(), u.x());
  const Mat2 c_lidar = var_r * u * u.transpose() + rc * rc * dtheta * dtheta / 8 * across * across.transpose();
  const Real cm = std::cos(lidar_mount.yaw_rad);
  const Real sm = std::sin(lidar_mount.yaw_rad);
  Mat2 rm;
  rm << cm, -sm, sm, cm;
  const Mat2 c_robot = rm * c_lidar * rm.transpose();

  const Vec2 p = lidar_mount.transform(centre);
  *dock_in_robot = Pose2{p.x(), p.y(), wrap_angle(lidar_mount.yaw_rad + yaw_lidar)};
  Mat3 c = Mat3::Zero();
  c.topLeftCorner<2, 2>() = c_robot;
  c(2, 2) = var_yaw;
  *covariance = c;
  return true;
}

}  // namespace dockcore
