#include "dockcore/control/odometry.hpp"

#include <cmath>

namespace dockcore {

bool Odometry::add_wheels(const DriveGeometry& geometry, const WheelSpeeds& measured, std::uint64_t stamp_us) {
  if (stamp_us == 0 || stamp_us == stamp_us_) return false;
  const Twist2 tw = wheels_to_twist(geometry, measured);
  if (valid_ && stamp_us > stamp_us_) {
    const std::uint64_t gap = stamp_us - stamp_us_;
    const Real dt = static_cast<Real>(gap < kMaxGapUs ? gap : 0u) * static_cast<Real>(1e-6);
    const Real vx = (twist_.vx_mps + tw.vx_mps) / 2;
    const Real vy = (twist_.vy_mps + tw.vy_mps) / 2;
    const Real wz = (twist_.wz_radps + tw.wz_radps) / 2;
    const Real yaw_mid = pose_.yaw_rad + wz * dt / 2;
    pose_.x_m += (vx * std::cos(yaw_mid) - vy * std::sin(yaw_mid)) * dt;
    pose_.y_m += (vx * std::sin(yaw_mid) + vy * std::cos(yaw_mid)) * dt;
    pose_.yaw_rad = wrap_angle(pose_.yaw_rad + wz * dt);
  }
  twist_ = tw;
  record(stamp_us);
  return true;
}

bool Odometry::add_pose(const Pose2& pose, const Twist2& twist, std::uint64_t stamp_us) {
  if (stamp_us == 0 || stamp_us == stamp_us_) return false;
  pose_ = pose;
  twist_ = twist;
  record(stamp_us);
  return true;
}

void Odometry::record(std::uint64_t stamp_us) {
  valid_ = true;
  stamp_us_ = stamp_us;
  history_[next_] = Sample{stamp_us, pose_};
  next_ = (next_ + 1) % kHistory;
}

Pose2 Odometry::pose_at(std::uint64_t stamp_us, bool* in_gap) const {
  const Sample* best = nullptr;
  for (const Sample& s : history_) {
    if (s.stamp_us == 0 || s.stamp_us > stamp_us) continue;
    if (best == nullptr || s.stamp_us > best->stamp_us) best = &s;
  }
  if (in_gap != nullptr) *in_gap = valid_ && (best == nullptr || stamp_us - best->stamp_us > kMaxGapUs);
  return best != nullptr ? best->pose : pose_;
}

}  // namespace dockcore
