#include "dockcore/tag_measurement.hpp"

namespace dockcore {
namespace {

/// Columns: the optical frame's x (right), y (down), z (forward) in the camera body frame (x forward, y left, z up).
Mat3 body_from_optical() {
  Mat3 r = Mat3::Zero();
  r(1, 0) = -1;
  r(2, 1) = -1;
  r(0, 2) = 1;
  return r;
}

/// Columns: the tag frame's x (columns), y (rows, down), z (into the tag) in the dock frame, for a tag flat on the
/// dock face looking out along the dock's +x.
Mat3 dock_from_upright_tag() {
  Mat3 r = Mat3::Zero();
  r(1, 0) = 1;
  r(2, 1) = -1;
  r(0, 2) = -1;
  return r;
}

bool is_rotation(const Mat3& r) {
  const Real tol = static_cast<Real>(1e-3);
  const Real det = r(0, 0) * (r(1, 1) * r(2, 2) - r(1, 2) * r(2, 1)) -
                   r(0, 1) * (r(1, 0) * r(2, 2) - r(1, 2) * r(2, 0)) +
                   r(0, 2) * (r(1, 0) * r(2, 1) - r(1, 1) * r(2, 0));
  return ((r.transpose() * r) - Mat3::Identity()).cwiseAbs().maxCoeff() < tol && std::fabs(det - 1) < tol;
}

}  // namespace

const char* to_string(TagStatus s) {
  switch (s) {
    case TagStatus::kFused:
      return "fused";
    case TagStatus::kWrongId:
      return "wrong_id";
    case TagStatus::kInvalid:
      return "invalid";
    case TagStatus::kBehind:
      return "behind";
    case TagStatus::kFar:
      return "far";
    case TagStatus::kWeak:
      return "weak";
    case TagStatus::kStale:
      return "stale";
    case TagStatus::kOutOfOrder:
      return "out_of_order";
    case TagStatus::kGated:
      return "gated";
  }
  return "unknown";
}

Mat3 camera_rotation(const CameraMount3& m) {
  return axis_rotation(2, m.yaw_rad) * axis_rotation(1, m.pitch_rad) * axis_rotation(0, m.roll_rad) * body_from_optical();
}

TagStatus tag_to_dock_measurement(const TagObservation& obs, const TagFusionParams& p, TagMeasurement* out) {
  if (!obs.rotation.allFinite() || !obs.translation_m.allFinite() || !std::isfinite(obs.decision_margin) ||
      !is_rotation(obs.rotation) || !(p.fx_px > 0) || !(p.tag_size_m > 0) || !(p.sigma_px > 0) ||
      !(p.sigma_scale > 0)) {
    return TagStatus::kInvalid;
  }
  const Vec3& t = obs.translation_m;
  const Real z = t.z();
  // In front of the camera, and seen from its printed side: the tag's z (into it) points away from the camera.
  if (!(z > 0) || !(obs.rotation.col(2).dot(t) > 0)) return TagStatus::kBehind;
  if (z > p.max_range_m) return TagStatus::kFar;
  if (obs.decision_margin < p.min_decision_margin) return TagStatus::kWeak;

  // robot ← camera ← tag ← dock.
  const Mat3 r_ro = camera_rotation(p.mount);
  const Vec3 t_rc(p.mount.x_m, p.mount.y_m, p.mount.z_m);
  const Mat3 r_rt = r_ro * obs.rotation;
  const Vec3 p_rt = t_rc + r_ro * t;
  const Mat3 r_dt = axis_rotation(2, p.dock_tag.yaw_rad) * dock_from_upright_tag();
  const Vec3 p_dt(p.dock_tag.x_m, p.dock_tag.y_m, p.dock_tag.z_m);
  const Mat3 r_rd = r_rt * r_dt.transpose();
  const Vec3 o = r_rd * p_dt;  // dock origin → tag centre, robot frame
  const Vec3 p_rd = p_rt - o;

  // The noise model (file comment), in the optical frame, then rotated into the robot frame.
  const Real sig = p.sigma_px * p.sigma_scale;
  const Real f = p.fx_px;
  const Real s = p.tag_size_m;
  const Real sigma_lat = z * sig / (2 * f);
  const Real sigma_depth = z * z * sig / (std::sqrt(static_cast<Real>(2)) * f * s);
  const Real cos_view = std::fabs(obs.rotation.col(2).dot(t)) / t.norm();
  const Real cos_floor = static_cast<Real>(0.3);
  const Real sigma_yaw = 2 * z * z * sig / (f * s * s * (cos_view > cos_floor ? cos_view : cos_floor));
  Mat3 d_opt = Mat3::Zero();
  d_opt(0, 0) = sigma_lat * sigma_lat;
  d_opt(1, 1) = sigma_lat * sigma_lat;
  d_opt(2, 2) = sigma_depth * sigma_depth;
  const Mat3 c_pos = r_ro * d_opt * r_ro.transpose();
  Mat3 c_tag = Mat3::Zero();
  c_tag.block<2, 2>(0, 0) = c_pos.block<2, 2>(0, 0);
  c_tag(2, 2) = sigma_yaw * sigma_yaw;
  // The dock origin sits at −o from the tag: a yaw error δ moves it by δ·(o_y, −o_x).
  Mat3 j = Mat3::Identity();
  j(0, 2) = o.y();
  j(1, 2) = -o.x();

  out->dock_in_robot = Pose2{p_rd.x(), p_rd.y(), std::atan2(r_rd(1, 0), r_rd(0, 0))};
  out->covariance = j * c_tag * j.transpose();
  out->depth_m = z;
  return TagStatus::kFused;
}

}  // namespace dockcore
