#include "dockcore/perception/dock_pose_filter.hpp"

namespace dockcore {
void DockPoseFilter::reset() {
  initialised_ = false;
  have_odom_ = false;
  consecutive_gated_ = 0;
  evidence_nats_ = 0;
  fused_since_start_ = 0;
  consecutive_tag_gated_ = 0;
}

void DockPoseFilter::predict(const Pose2& odom_pose) {
  if (!finite_pose(odom_pose)) return;
  if (have_odom_ && initialised_) {
    const Real dx = odom_pose.x_m - last_odom_.x_m;
    const Real dy = odom_pose.y_m - last_odom_.y_m;
    const Real ds = std::sqrt(dx * dx + dy * dy);
    const Real dth = std::fabs(wrap_angle(odom_pose.yaw_rad - last_odom_.yaw_rad));
    const Real qp = params_.pos_noise_per_m * params_.pos_noise_per_m * ds;
    const Real qy = params_.yaw_noise_per_rad * params_.yaw_noise_per_rad * dth +
                    params_.yaw_noise_per_m * params_.yaw_noise_per_m * ds;
    cov_odom_(0, 0) += qp;
    cov_odom_(1, 1) += qp;
    cov_odom_(2, 2) += qy;
  }
  last_odom_ = odom_pose;
  have_odom_ = true;
}

void DockPoseFilter::start(const Pose2& z, const Mat3& rz, std::uint64_t stamp_us, Real evidence_nats) {
  evidence_nats_ = evidence_nats;
  fused_since_start_ = 1;
  dock_odom_ = z;
  cov_odom_ = rz;
  initialised_ = true;
  consecutive_gated_ = 0;
  consecutive_tag_gated_ = 0;
  last_update_us_ = stamp_us;
}

void DockPoseFilter::to_odom(const Pose2& dock_in_robot, const Mat3& cov_robot, const Pose2& odom_pose, Pose2* z,
                             Mat3* rz) const {
  // Detection mapped into the odometry frame, with its covariance rotated alongside.
  *z = odom_pose.compose(dock_in_robot);
  const Mat3 rot = axis_rotation(2, odom_pose.yaw_rad);
  *rz = rot * cov_robot * rot.transpose();
  const Real floor_p = params_.min_meas_sigma_m * params_.min_meas_sigma_m;
  const Real floor_y = params_.min_meas_sigma_rad * params_.min_meas_sigma_rad;
  (*rz)(0, 0) += floor_p;
  (*rz)(1, 1) += floor_p;
  (*rz)(2, 2) += floor_y;
}

bool DockPoseFilter::innovation(const Pose2& z, const Mat3& rz, Vec3* nu, Mat3* s_inv) {
  *nu = Vec3(z.x_m - dock_odom_.x_m, z.y_m - dock_odom_.y_m, wrap_angle(z.yaw_rad - dock_odom_.yaw_rad));
  const Mat3 s = cov_odom_ + rz;
  if (!invert_sym3(s, s_inv)) return false;
  last_d2_ = nu->dot(*s_inv * *nu);
  return true;
}

void DockPoseFilter::correct(const Vec3& nu, const Mat3& s_inv, const Mat3& rz) {
  const Mat3 k = cov_odom_ * s_inv;
  const Vec3 dx = k * nu;
  dock_odom_.x_m += dx.x();
  dock_odom_.y_m += dx.y();
  dock_odom_.yaw_rad = wrap_angle(dock_odom_.yaw_rad + dx.z());
  // Joseph form keeps the covariance symmetric and positive under rounding (matters for the float build).
  const Mat3 ikh = Mat3::Identity() - k;
  cov_odom_ = ikh * cov_odom_ * ikh.transpose() + k * rz * k.transpose();
}

FilterUpdate DockPoseFilter::update(const Pose2& dock_in_robot, const Mat3& cov_robot, const Pose2& odom_pose,
                                    std::uint64_t stamp_us, Real evidence_nats) {
  if (!finite_pose(dock_in_robot) || !finite_pose(odom_pose) || !cov_robot.allFinite() || !std::isfinite(evidence_nats)) {
    return FilterUpdate::kInvalid;
  }
  predict(odom_pose);
  Pose2 z;
  Mat3 rz;
  to_odom(dock_in_robot, cov_robot, odom_pose, &z, &rz);
  if (!initialised_) {
    start(z, rz, stamp_us, evidence_nats);
    ++fused_;
    return FilterUpdate::kInitialised;
  }
  Vec3 nu;
  Mat3 s_inv;
  if (!innovation(z, rz, &nu, &s_inv)) return FilterUpdate::kInvalid;
  if (!(last_d2_ <= params_.gate_chi2)) {
    if (++consecutive_gated_ >= params_.reinit_after) {
      ++reinits_;
      start(z, rz, stamp_us, evidence_nats);
      return FilterUpdate::kReinitialised;
    }
    ++gated_;
    return FilterUpdate::kGated;
  }
  correct(nu, s_inv, rz);
  consecutive_gated_ = 0;
  last_update_us_ = stamp_us;
  ++fused_;
  ++fused_since_start_;
  evidence_nats_ += evidence_nats;
  return FilterUpdate::kFused;
}

FilterUpdate DockPoseFilter::update_tag(const Pose2& dock_in_robot, const Mat3& cov_robot, const Pose2& odom_pose,
                                        std::uint64_t stamp_us) {
  if (!finite_pose(dock_in_robot) || !finite_pose(odom_pose) || !cov_robot.allFinite()) return FilterUpdate::kInvalid;
  predict(odom_pose);
  Pose2 z;
  Mat3 rz;
  to_odom(dock_in_robot, cov_robot, odom_pose, &z, &rz);
  // A filter started (or restarted) by a tag: no evidence, no scan; the lidar's detections confirm it.
  auto start_from_tag = [&]() {
    start(z, rz, stamp_us, 0);
    fused_since_start_ = 0;
    ++tag_fused_;
  };
  if (!initialised_) {
    start_from_tag();
    return FilterUpdate::kInitialised;
  }
  Vec3 nu;
  Mat3 s_inv;
  if (!innovation(z, rz, &nu, &s_inv)) return FilterUpdate::kInvalid;
  if (!(last_d2_ <= params_.gate_chi2)) {
    if (!lidar_since_start() && ++consecutive_tag_gated_ >= params_.reinit_after) {
      ++reinits_;
      start_from_tag();
      return FilterUpdate::kReinitialised;
    }
    ++tag_gated_;
    return FilterUpdate::kGated;
  }
  correct(nu, s_inv, rz);
  consecutive_tag_gated_ = 0;
  last_update_us_ = stamp_us;
  ++tag_fused_;
  return FilterUpdate::kFused;
}

Pose2 DockPoseFilter::dock_in_robot(const Pose2& odom_pose, Mat3* cov_robot) const {
  const Pose2 d = odom_pose.inverse().compose(dock_odom_);
  if (cov_robot != nullptr) {
    const Mat3 rot = axis_rotation(2, -odom_pose.yaw_rad);
    *cov_robot = rot * cov_odom_ * rot.transpose();
  }
  return d;
}

}  // namespace dockcore
