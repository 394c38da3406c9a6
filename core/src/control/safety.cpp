#include "dockcore/control/safety.hpp"

#include <cmath>

namespace dockcore {

const char* to_string(FaultCode f) {
  switch (f) {
    case FaultCode::kNone: return "none";
    case FaultCode::kDetectionFailed: return "detection_failed";
    case FaultCode::kDistanceDeviation: return "distance_deviation";
    case FaultCode::kAngleDeviation: return "angle_deviation";
    case FaultCode::kObstacleTimeout: return "obstacle_timeout";
    case FaultCode::kTargetLost: return "target_lost";
    case FaultCode::kChargeNotConfirmed: return "charge_not_confirmed";
    case FaultCode::kContactsLost: return "contacts_lost";
    case FaultCode::kChassisStale: return "chassis_stale";
    case FaultCode::kLidarStale: return "lidar_stale";
    case FaultCode::kUndockFailed: return "undock_failed";
    case FaultCode::kBadCommand: return "bad_command";
    case FaultCode::kAlignFailed: return "align_failed";
    case FaultCode::kTaskTimeout: return "task_timeout";
    case FaultCode::kContactsNotReached:
      return "contacts_not_reached";
  }
  return "unknown";
}

FootprintParams square_footprint() { return FootprintParams{}; }

FootprintParams circular_footprint() {
  FootprintParams p;
  p.shape = FootprintShape::kCircular;
  p.radius_m = static_cast<Real>(0.275);
  p.check_length_m = static_cast<Real>(0.3);
  p.check_width_m = static_cast<Real>(0.5);
  p.circumscribed_radius_m = static_cast<Real>(0.275);
  return p;
}

void ObstacleChecker::configure(const FootprintParams& footprint, const DockProfile* profile) {
  fp_ = footprint;
  // Every zone check() tests (the check boxes, the body, the rotation circle) lies within this of the centre.
  const Real box_x = body_front_m() + fp_.check_length_m;
  const Real half_w = fp_.check_width_m * static_cast<Real>(0.5);
  const Real box_reach = std::sqrt(box_x * box_x + half_w * half_w);
  const Real body_reach = fp_.shape == FootprintShape::kCircular
                              ? fp_.radius_m
                              : std::sqrt(fp_.half_length_m * fp_.half_length_m + fp_.half_width_m * fp_.half_width_m);
  reach_m_ = box_reach > body_reach ? box_reach : body_reach;
  reach_m_ = reach_m_ > fp_.circumscribed_radius_m ? reach_m_ : fp_.circumscribed_radius_m;
  have_profile_ = profile != nullptr && profile->vertex_count >= 2;
  if (have_profile_) {
    profile_ = *profile;
    profile_max_x_m_ = profile_.vertices_m[0].x();
    for (std::size_t i = 1; i < profile_.vertex_count; ++i) {
      if (profile_.vertices_m[i].x() > profile_max_x_m_) profile_max_x_m_ = profile_.vertices_m[i].x();
    }
  } else {
    profile_max_x_m_ = 0;
  }
}

Real body_front_m(const FootprintParams& fp) {
  return fp.shape == FootprintShape::kCircular ? fp.radius_m : fp.half_length_m;
}

Real body_half_width_m(const FootprintParams& fp) {
  return fp.shape == FootprintShape::kCircular ? fp.radius_m : fp.half_width_m;
}

namespace {

bool in_sector(const AngleSector& s, Real a) {
  if (s.min_rad <= s.max_rad) return a >= s.min_rad && a <= s.max_rad;
  return a >= s.min_rad || a <= s.max_rad;  // wraps through pi
}

}  // namespace

bool ObstacleChecker::is_inside_body(const Vec2& p) const {
  if (fp_.shape == FootprintShape::kCircular) return p.norm() <= fp_.radius_m;
  return std::fabs(p.x()) <= fp_.half_length_m && std::fabs(p.y()) <= fp_.half_width_m;
}

bool ObstacleChecker::is_self_point(const Vec2& p, Real lidar_bearing_rad) const {
  // Only configured structure is the robot: a body-shaped filter alone would hide an obstacle that comes within the
  // margin or that the robot drives into (HIL: a disc 1.5 cm from the bumper was driven through).
  const Real a = wrap_angle(lidar_bearing_rad);
  bool sector = false;
  const std::size_t n = fp_.self_sector_count < kMaxSelfSectors ? fp_.self_sector_count : kMaxSelfSectors;
  for (std::size_t i = 0; i < n && !sector; ++i) sector = in_sector(fp_.self_sectors[i], a);
  if (!sector) return false;
  if (fp_.shape == FootprintShape::kCircular) return p.norm() <= fp_.radius_m + fp_.self_margin_m;
  return std::fabs(p.x()) <= fp_.half_length_m + fp_.self_margin_m &&
         std::fabs(p.y()) <= fp_.half_width_m + fp_.self_margin_m;
}

bool ObstacleChecker::is_dock_point(const Vec2& p_robot, const Pose2& dock_in_robot) const {
  if (!have_profile_) return false;
  const Vec2 q = dock_in_robot.inverse_transform(p_robot);
  // The dock zone: the dock's face plane and everything behind it near the dock axis (the wall it stands on).
  if (q.x() <= profile_max_x_m_ + fp_.dock_margin_m && std::fabs(q.y()) <= fp_.dock_zone_half_width_m) return true;
  // The dock body itself where it sticks out (wings): distance to the polyline, every segment (hidden ones too:
  // mixed pixels at the edges land near them).
  const Real m2 = fp_.dock_margin_m * fp_.dock_margin_m;
  for (std::size_t i = 0; i + 1 < profile_.vertex_count; ++i) {
    const Vec2& a = profile_.vertices_m[i];
    const Vec2 ab = profile_.vertices_m[i + 1] - a;
    const Real len2 = ab.squaredNorm();
    Real t = len2 > 0 ? (q - a).dot(ab) / len2 : static_cast<Real>(0);
    if (t < 0) t = 0;
    if (t > 1) t = 1;
    if ((a + t * ab - q).squaredNorm() <= m2) return true;
  }
  return false;
}

ObstacleFlags ObstacleChecker::check(const ScanView& scan, const Pose2& lidar_mount, const Pose2* dock_in_robot) const {
  ObstacleFlags f;
  if (scan.count == 0 || scan.ranges_m == nullptr || !(std::fabs(scan.angle_increment_rad) > 0) ||
      !std::isfinite(scan.angle_min_rad) || !std::isfinite(scan.angle_increment_rad)) {
    return f;
  }
  f.valid = true;
  const std::size_t n = scan.count < kMaxScanPoints ? scan.count : kMaxScanPoints;
  const Real front = body_front_m();
  const Real half_w = fp_.check_width_m * static_cast<Real>(0.5);
  const Real r_rot2 = fp_.circumscribed_radius_m * fp_.circumscribed_radius_m;
  // A return r from the lidar lies at least r - |mount| from the robot's centre: beyond every zone's reach it can flag
  // nothing, so it is skipped before its trigonometry (most beams of a room). The margin keeps rounding from deciding.
  const Real skip_beyond_m =
      reach_m_ + std::sqrt(lidar_mount.x_m * lidar_mount.x_m + lidar_mount.y_m * lidar_mount.y_m) +
      static_cast<Real>(0.001);
  bool have_nearest = false;
  for (std::size_t i = 0; i < n; ++i) {
    const Real r = scan.ranges_m[i];
    if (!is_valid_range(r) || r < fp_.min_range_m || r > skip_beyond_m) continue;
    const Real a = scan.angle_rad(i);
    const Vec2 p = lidar_mount.transform(Vec2(r * std::cos(a), r * std::sin(a)));
    const bool lateral = std::fabs(p.y()) < half_w;
    // Inside the outline: touching or overlapping the robot. It blocks the half it is in (and turning, through
    // in_rot: the circumscribed radius contains the body).
    const bool in_body = is_inside_body(p);
    const bool in_fwd = (lateral && p.x() > front && p.x() <= front + fp_.check_length_m) || (in_body && p.x() >= 0);
    const bool in_back = (lateral && p.x() < -front && p.x() >= -front - fp_.check_length_m) || (in_body && p.x() <= 0);
    const bool in_rot = p.squaredNorm() < r_rot2;
    if (!in_fwd && !in_back && !in_rot) continue;  // most points stop here: no profile test
    if (is_self_point(p, a)) {
      ++f.self_points;
      continue;
    }
    if (dock_in_robot != nullptr && is_dock_point(p, *dock_in_robot)) {
      ++f.dock_points;
      continue;
    }
    if (in_body) ++f.body_points;
    if (in_fwd) {
      ++f.forward_points;
      const Real ahead = p.x() - front;
      if (!have_nearest || ahead < f.nearest_forward_m) f.nearest_forward_m = ahead;
      have_nearest = true;
    }
    if (in_back) ++f.backward_points;
    if (in_rot) ++f.rotation_points;
  }
  f.forward = f.forward_points >= fp_.min_points;
  f.backward = f.backward_points >= fp_.min_points;
  f.rotation = f.rotation_points >= fp_.min_points;
  return f;
}

bool motion_blocked(const Twist2& cmd, const ObstacleFlags& flags, const MotionGateParams& gate) {
  const bool fwd = cmd.vx_mps > gate.min_speed_mps;
  const bool back = cmd.vx_mps < -gate.min_speed_mps;
  const bool lat = std::fabs(cmd.vy_mps) > gate.min_speed_mps;
  const bool rot = std::fabs(cmd.wz_radps) >= gate.rotate_min_wz_radps && std::fabs(cmd.vx_mps) <= gate.rotate_max_vx_mps;
  if (!flags.valid) return fwd || back || lat || std::fabs(cmd.wz_radps) >= gate.rotate_min_wz_radps;
  if (fwd && flags.forward) return true;
  if (back && flags.backward) return true;
  if (lat && (flags.forward || flags.rotation)) return true;
  if (rot && flags.rotation) return true;
  return false;
}

Twist2 permitted_motion(const Twist2& cmd, const ObstacleFlags& flags, const MotionGateParams& gate, bool keep_turn,
                        bool* blocked) {
  const bool stop = motion_blocked(cmd, flags, gate);
  if (blocked != nullptr) *blocked = stop;
  if (!stop) return cmd;
  Twist2 turn{};
  turn.wz_radps = cmd.wz_radps;
  // A turn too slow to count as a rotation would pass the gate unchecked: it is stopped with the rest.
  if (!keep_turn || !(std::fabs(turn.wz_radps) >= gate.rotate_min_wz_radps) || motion_blocked(turn, flags, gate)) {
    return Twist2{};
  }
  return turn;
}

FaultCode check_pose_deviation(const Pose2& detected_in_odom, const Pose2& expected_in_odom, Real distance_m,
                               Real start_distance_m, const DeviationParams& params) {
  const Real dx = detected_in_odom.x_m - expected_in_odom.x_m;
  const Real dy = detected_in_odom.y_m - expected_in_odom.y_m;
  const Real jump_m = std::sqrt(dx * dx + dy * dy);
  Real limit_m = params.check_distance_error_tolerance_m;
  if (start_distance_m + params.distance_growth_margin_m > limit_m) {
    limit_m = start_distance_m + params.distance_growth_margin_m;
  }
  // Non-finite values fail the comparisons below on purpose: `!(x <= tol)` faults on NaN.
  if (!(jump_m <= params.push_distance_tolerance_m) || !(distance_m <= limit_m)) return FaultCode::kDistanceDeviation;
  const Real dyaw = wrap_angle(detected_in_odom.yaw_rad - expected_in_odom.yaw_rad);
  if (!(std::fabs(dyaw) <= params.check_angle_error_tolerance_rad)) return FaultCode::kAngleDeviation;
  return FaultCode::kNone;
}

}  // namespace dockcore
