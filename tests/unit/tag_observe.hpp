#pragma once
// Simulated camera tag detections for the tag fusion tests: the exact tag pose a camera on a robot sees, plus noise
// drawn at the covariance model's σ (dockcore/perception/tag_measurement.hpp).
#include <cmath>
#include <cstdint>

#include "dockcore/geometry.hpp"
#include "dockcore/perception/tag_measurement.hpp"
#include "docksim/rng.hpp"

namespace dockcore_test {

using dockcore::Mat3;
using dockcore::Pose2;
using dockcore::TagFusionParams;
using dockcore::TagObservation;
using dockcore::Vec2;
using dockcore::Vec3;

/// A camera tag detection of the dock's tag from a robot at `robot` (world frame) with the dock at `dock`: the exact
/// pose (inverse of the chain tag_to_dock_measurement undoes), plus noise drawn at the model's σ for `sigma_px`
/// when `rng` is given (lateral, depth, and a turn about the camera's vertical axis).
inline TagObservation observe_tag(const Pose2& robot, const Pose2& dock, const TagFusionParams& p, docksim::Rng* rng,
                                  double sigma_px, std::uint64_t stamp_us) {
  auto rz = [](dockcore::Real a) { return dockcore::axis_rotation(2, a); };
  Mat3 upright = Mat3::Zero();  // tag x, y, z in the dock frame for a tag looking out along the dock's +x
  upright(1, 0) = 1;
  upright(2, 1) = -1;
  upright(0, 2) = -1;
  const Mat3 r_wc = rz(robot.yaw_rad) * dockcore::camera_rotation(p.mount);
  const Vec2 c2 = robot.transform(Vec2(p.mount.x_m, p.mount.y_m));
  const Vec3 t_wc(c2.x(), c2.y(), p.mount.z_m);
  const Mat3 r_wt = rz(dock.yaw_rad) * rz(p.dock_tag.yaw_rad) * upright;
  const Vec2 t2 = dock.transform(Vec2(p.dock_tag.x_m, p.dock_tag.y_m));
  const Vec3 t_wt(t2.x(), t2.y(), p.dock_tag.z_m);
  TagObservation o;
  o.id = p.dock_tag.id;
  o.decision_margin = 80;
  o.stamp_us = stamp_us;
  o.rotation = r_wc.transpose() * r_wt;
  o.translation_m = r_wc.transpose() * (t_wt - t_wc);
  if (rng != nullptr) {
    const double z = o.translation_m.z(), f = p.fx_px, s = p.tag_size_m;
    const double cos_view = std::fmax(0.3, std::fabs(o.rotation.col(2).dot(o.translation_m)) / o.translation_m.norm());
    o.translation_m.x() += rng->normal() * z * sigma_px / (2 * f);
    o.translation_m.y() += rng->normal() * z * sigma_px / (2 * f);
    o.translation_m.z() += rng->normal() * z * z * sigma_px / (std::sqrt(2.0) * f * s);
    const double d = rng->normal() * 2 * z * z * sigma_px / (f * s * s * cos_view);
    // About the optical frame's y (down): a level camera's vertical.
    const Mat3 ry = dockcore::axis_rotation(1, static_cast<dockcore::Real>(d));
    o.rotation = ry * o.rotation;
  }
  return o;
}

/// `o` with its corners: the tag's corners (dockcore::kTagCornerX/Y, side p.tag_size_m) projected through o's
/// rotation and translation into unit-focal image coordinates, exactly.
inline TagObservation with_corners(TagObservation o, const TagFusionParams& p) {
  const double h = static_cast<double>(p.tag_size_m) / 2;
  for (int k = 0; k < 4; ++k) {
    const Vec3 c = o.rotation * Vec3(static_cast<dockcore::Real>(dockcore::kTagCornerX[k] * h),
                                     static_cast<dockcore::Real>(dockcore::kTagCornerY[k] * h), 0) +
                   o.translation_m;
    o.corners[k] = Vec2(c.x() / c.z(), c.y() / c.z());
  }
  o.has_corners = true;
  return o;
}

}  // namespace dockcore_test
