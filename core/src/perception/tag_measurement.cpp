#include "dockcore/perception/tag_measurement.hpp"

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

/// Where the tag's corners are in the dock frame (the upright tag at its place on the dock).
void tag_corners_in_dock(const TagFusionParams& p, Vec3 out[4]) {
  const Mat3 r_dt = axis_rotation(2, p.dock_tag.yaw_rad) * dock_from_upright_tag();
  const Vec3 p_dt(p.dock_tag.x_m, p.dock_tag.y_m, p.dock_tag.z_m);
  const Real h = p.tag_size_m / 2;
  for (int k = 0; k < 4; ++k) out[k] = p_dt + r_dt * Vec3(kTagCornerX[k] * h, kTagCornerY[k] * h, 0);
}

/// Reprojection residuals (px) of the corners for the dock at `d`, and their Jacobian in (x, y, yaw) when `jac` is
/// given. False when a corner is not in front of the camera.
bool corner_residuals(const Vec3 in_dock[4], const Vec2 corners[4], const TagFusionParams& p, const Mat3& r_or,
                      const Vec3& t_rc, const Pose2& d, Eigen::Matrix<Real, 8, 1>* res,
                      Eigen::Matrix<Real, 8, 3>* jac) {
  const Mat3 r_rd = axis_rotation(2, d.yaw_rad);
  const Vec3 t_rd(d.x_m, d.y_m, 0);
  for (Eigen::Index k = 0; k < 4; ++k) {
    const Vec3 turned = r_rd * in_dock[k];
    const Vec3 q = r_or * (turned + t_rd - t_rc);  // optical frame
    if (!(q.z() > static_cast<Real>(1e-6))) return false;
    const Real iz = 1 / q.z();
    (*res)(2 * k) = p.fx_px * (q.x() * iz - corners[k].x());
    (*res)(2 * k + 1) = p.fx_px * (q.y() * iz - corners[k].y());
    if (jac != nullptr) {
      Eigen::Matrix<Real, 2, 3> dproj;  // d(projection, px) / d(optical point)
      dproj << p.fx_px * iz, 0, -p.fx_px * q.x() * iz * iz, 0, p.fx_px * iz, -p.fx_px * q.y() * iz * iz;
      Mat3 dq = Mat3::Zero();  // d(robot point) / d(x, y, yaw)
      dq(0, 0) = 1;
      dq(1, 1) = 1;
      dq(0, 2) = -turned.y();
      dq(1, 2) = turned.x();
      jac->block<2, 3>(2 * k, 0) = dproj * r_or * dq;
    }
  }
  return true;
}

/// The other minimum of a planar target's pose: the tag's normal mirrored about the line of sight from the camera
/// to the tag's centre, the centre kept.
Pose2 mirror_about_line_of_sight(const Pose2& d, const TagFusionParams& p) {
  const Vec2 offset(p.dock_tag.x_m, p.dock_tag.y_m);
  const Vec2 centre = d.transform(offset);
  const Real to_camera = std::atan2(p.mount.y_m - centre.y(), p.mount.x_m - centre.x());
  const Real normal = d.yaw_rad + p.dock_tag.yaw_rad;
  const Real yaw = wrap_angle(2 * to_camera - normal - p.dock_tag.yaw_rad);
  const Pose2 turned{0, 0, yaw};
  const Vec2 origin = centre - turned.transform(offset);
  return Pose2{origin.x(), origin.y(), yaw};
}

}  // namespace

bool fit_dock_to_tag_corners(const Vec2 corners[4], const TagFusionParams& p, const Pose2& start, TagCornerFit* out) {
  Vec3 in_dock[4];
  tag_corners_in_dock(p, in_dock);
  const Mat3 r_or = camera_rotation(p.mount).transpose();
  const Vec3 t_rc(p.mount.x_m, p.mount.y_m, p.mount.z_m);
  Eigen::Matrix<Real, 8, 1> res;
  Eigen::Matrix<Real, 8, 3> jac;
  Pose2 d = start;
  if (!corner_residuals(in_dock, corners, p, r_or, t_rc, d, &res, &jac)) return false;
  Real cost = res.squaredNorm();
  std::int32_t it = 0;
  while (it < kTagFitMaxIterations) {
    ++it;
    Mat3 normal_inv;
    if (!invert_sym3(jac.transpose() * jac, &normal_inv)) break;
    const Vec3 step = -(normal_inv * (jac.transpose() * res));
    if (!step.allFinite()) break;
    // Halve a step that does not lower the cost: the start may be far from the minimum (the mirrored pose).
    bool lowered = false;
    Vec3 s = step;
    Eigen::Matrix<Real, 8, 1> trial_res;
    for (int h = 0; h < 8 && !lowered; ++h, s /= 2) {
      const Pose2 trial{d.x_m + s(0), d.y_m + s(1), wrap_angle(d.yaw_rad + s(2))};
      if (corner_residuals(in_dock, corners, p, r_or, t_rc, trial, &trial_res, nullptr) &&
          trial_res.squaredNorm() < cost) {
        d = trial;
        lowered = true;
      }
    }
    if (!lowered) break;
    const Real previous = cost;
    corner_residuals(in_dock, corners, p, r_or, t_rc, d, &res, &jac);
    cost = res.squaredNorm();
    // Converged: the cost no longer moves at the scalar's precision.
    if (previous - cost <= previous * static_cast<Real>(1e-6)) break;
  }
  const Real rms = std::sqrt(cost / 8);
  if (!std::isfinite(d.x_m) || !std::isfinite(d.y_m) || !std::isfinite(d.yaw_rad) || !std::isfinite(rms)) return false;
  out->dock_in_robot = d;
  out->rms_px = rms;
  out->iterations = it;
  return true;
}

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
  Mat3 r_rd = r_rt * r_dt.transpose();
  Vec3 o = r_rd * p_dt;  // dock origin → tag centre, robot frame
  const Vec3 p_rd = p_rt - o;
  Pose2 dock{p_rd.x(), p_rd.y(), std::atan2(r_rd(1, 0), r_rd(0, 0))};

  Real corner_rms_px = -1;
  if (obs.has_corners) {
    // Both minima of the planar pose as starts; the lower reprojection error wins.
    TagCornerFit best;
    bool have = false;
    for (const Pose2& start : {dock, mirror_about_line_of_sight(dock, p)}) {
      TagCornerFit f;
      if (fit_dock_to_tag_corners(obs.corners, p, start, &f) && (!have || f.rms_px < best.rms_px)) {
        best = f;
        have = true;
      }
    }
    if (have) {
      dock = best.dock_in_robot;
      corner_rms_px = best.rms_px;
      r_rd = axis_rotation(2, dock.yaw_rad);
      o = r_rd * p_dt;
    }
  }

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

  out->dock_in_robot = dock;
  out->covariance = j * c_tag * j.transpose();
  out->depth_m = z;
  out->corner_rms_px = corner_rms_px;
  return TagStatus::kFused;
}

}  // namespace dockcore
