// camera-check tag-pose (see tag_pose.hpp).
#include "tag_pose.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "dockcore/drivers/camera_pipeline.hpp"
#include "dockcore/geometry.hpp"
#include "dockcore/perception/tag_measurement.hpp"
#include "docksim/rendered_camera.hpp"
#include "docksim/rng.hpp"
#include "docksim/tag_render.hpp"

namespace camera_check {

using dockcore::Mat3;
using dockcore::Pose2;
using dockcore::Real;
using dockcore::Vec2;
using dockcore::Vec3;

namespace {

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size())))];
}

double rms(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x * x;
  return v.empty() ? std::nan("") : std::sqrt(s / static_cast<double>(v.size()));
}

}  // namespace

int run_tag_pose(const TagPoseOptions& o, dockcore::drivers::TagDetectorOptions det, double fx_px) {
  if (o.frames == 0 || o.distance_m <= 0 || fx_px <= 0 || det.tag_size_m <= 0) {
    std::fprintf(stderr, "camera-check tag-pose: --frames, --distance, --fx and --tag-size must be > 0\n");
    return 2;
  }
  const int family_id = 3;
  docksim::TagPatternImage tag_image;
  std::string err;
  if (!docksim::make_tag_pattern(det.family, family_id, det.tag_size_m, tag_image, err)) {
    std::fprintf(stderr, "camera-check tag-pose: %s\n", err.c_str());
    return 2;
  }
  const docksim::TagPattern& pattern = tag_image.pattern;
  docksim::PinholeView view;
  view.fx_px = view.fy_px = fx_px;
  view.width_px = o.width_px;
  view.height_px = o.height_px;
  view.cx_px = (o.width_px - 1) / 2.0;
  view.cy_px = (o.height_px - 1) / 2.0;
  det.intrinsics = dockcore::drivers::CameraIntrinsics{fx_px, fx_px, view.cx_px, view.cy_px};
  auto detector = dockcore::drivers::TagDetector::create(det, err);
  if (!detector) {
    std::fprintf(stderr, "camera-check tag-pose: %s\n", err.c_str());
    return 2;
  }
  // The robot: camera 0.2 m ahead of its centre at the tag's height (0.2 m), level; the tag on the dock face, 0.2 m
  // above the contacts.
  dockcore::TagFusionParams p;
  p.mount.x_m = static_cast<Real>(0.2);
  p.mount.z_m = static_cast<Real>(0.2);
  p.fx_px = static_cast<Real>(fx_px);
  p.tag_size_m = static_cast<Real>(det.tag_size_m);
  p.dock_tag.id = family_id;
  p.dock_tag.z_m = static_cast<Real>(0.2);
  p.sigma_px = static_cast<Real>(o.sigma_px);
  docksim::Rng rng(o.seed);
  std::vector<std::uint8_t> img(static_cast<std::size_t>(o.width_px) * o.height_px);
  std::vector<double> lat_mm, depth_mm, yaw_deg, z_lat, z_yaw, in_dock_mm, corner_err_px, fit_rms_px;
  std::uint32_t found = 0;
  for (std::uint32_t i = 0; i < o.frames; ++i) {
    // The dock in the robot frame: ahead at distance + mount, offset sideways, turned.
    const double yaw = dockcore::kPi + rng.uniform(-1, 1) * o.yaw_deg * dockcore::kPi / 180;
    const Pose2 dock{static_cast<Real>(o.distance_m + 0.2), static_cast<Real>(rng.uniform(-1, 1) * o.lateral_m),
                     static_cast<Real>(yaw)};
    docksim::place_tag_in_view(view, p.mount, dock, p.dock_tag);
    view.background = static_cast<std::uint8_t>(100 + rng.uniform(0, 60));
    docksim::render_tag(pattern, view, img.data(), o.width_px);
    docksim::blur_grey(img.data(), o.width_px, o.height_px, o.width_px, o.blur_px);
    for (std::uint8_t& px : img)
      px = static_cast<std::uint8_t>(std::clamp(std::lround(px + rng.normal() * o.noise_grey), 0L, 255L));
    dockcore::drivers::TagDetection d[4];
    const std::size_t n = detector->detect(img.data(), o.width_px, o.height_px, o.width_px, d, 4);
    const dockcore::drivers::TagDetection* tag = nullptr;
    for (std::size_t k = 0; k < n && tag == nullptr; ++k) {
      if (d[k].id == family_id && d[k].has_pose) tag = &d[k];
    }
    if (tag == nullptr) continue;
    dockcore::TagObservation obs = dockcore::drivers::tag_observation(*tag, 0);
    obs.has_corners = o.corner_fit;
    // The detector's corner error against the rendered truth (the noise the pose is estimated from).
    for (int k = 0; k < 4; ++k) {
      const double h = det.tag_size_m / 2;
      double u = 0, v = 0;
      docksim::project_tag_point(view, dockcore::kTagCornerX[k] * h, dockcore::kTagCornerY[k] * h, u, v);
      corner_err_px.push_back(tag->corners_px[k][0] - u);
      corner_err_px.push_back(tag->corners_px[k][1] - v);
    }
    dockcore::TagMeasurement m;
    if (dockcore::tag_to_dock_measurement(obs, p, &m) != dockcore::TagStatus::kFused) continue;
    ++found;
    const double ey = static_cast<double>(m.dock_in_robot.y_m - dock.y_m);
    const double ex = static_cast<double>(m.dock_in_robot.x_m - dock.x_m);
    const double eyaw = static_cast<double>(dockcore::wrap_angle(m.dock_in_robot.yaw_rad - dock.yaw_rad));
    lat_mm.push_back(1000 * ey);
    // Where the robot stands sideways in the dock frame, as the measurement says and in truth: the yaw error's lever.
    in_dock_mm.push_back(1000 * static_cast<double>(m.dock_in_robot.inverse().y_m - dock.inverse().y_m));
    depth_mm.push_back(1000 * ex);
    yaw_deg.push_back(eyaw * 180 / dockcore::kPi);
    z_lat.push_back(ey / std::sqrt(static_cast<double>(m.covariance(1, 1))));
    z_yaw.push_back(eyaw / std::sqrt(static_cast<double>(m.covariance(2, 2))));
    if (m.corner_rms_px >= 0) fit_rms_px.push_back(static_cast<double>(m.corner_rms_px));
  }
  auto abs_all = [](std::vector<double> v) {
    for (double& x : v) x = std::fabs(x);
    return v;
  };
  // The information bound of the yaw of a tag seen face-on: each corner moves by f·(s/2)²/Z² px per rad across the
  // line of sight (the perspective difference of the left and right edges), so with corner noise σ_c the yaw's σ is
  // at least σ_c·Z² / (2·f·(s/2)²) = 2·σ_c·Z² / (f·s²) (docs/camera.md, "Choosing the tag size").
  const double corner_rms_px = rms(corner_err_px);
  const double bound_deg =
      2 * corner_rms_px * o.distance_m * o.distance_m / (fx_px * det.tag_size_m * det.tag_size_m) * 180 / dockcore::kPi;
  char fit_rms[32] = "null";  // no corner fit: nothing to report
  if (!fit_rms_px.empty()) std::snprintf(fit_rms, sizeof fit_rms, "%.3f", percentile(fit_rms_px, 0.5));
  std::printf(
      "{\"type\":\"tag_pose\",\"frames\":%u,\"found\":%u,\"distance_m\":%g,\"tag_size_m\":%g,\"fx_px\":%g,"
      "\"noise_grey\":%g,\"blur_px\":%g,\"decimate\":%g,\"lateral_p50_mm\":%.2f,\"lateral_p95_mm\":%.2f,"
      "\"depth_p95_mm\":%.2f,\"robot_in_dock_lateral_p95_mm\":%.1f,\"yaw_p50_deg\":%.3f,\"yaw_p95_deg\":%.3f,\"sigma_"
      "px\":%g,"
      "\"lateral_rms_over_model_sigma\":%.2f,\"yaw_rms_over_model_sigma\":%.2f,\"corner_fit\":%s,"
      "\"corner_error_rms_px\":%.3f,\"yaw_face_on_bound_deg\":%.3f,\"fit_rms_p50_px\":%s,\"yaw_max_deg\":%.2f}\n",
      o.frames, found, o.distance_m, det.tag_size_m, fx_px, o.noise_grey, o.blur_px, det.quad_decimate,
      percentile(abs_all(lat_mm), 0.5), percentile(abs_all(lat_mm), 0.95), percentile(abs_all(depth_mm), 0.95),
      percentile(abs_all(in_dock_mm), 0.95), percentile(abs_all(yaw_deg), 0.5), percentile(abs_all(yaw_deg), 0.95),
      o.sigma_px, rms(z_lat), rms(z_yaw), o.corner_fit ? "true" : "false", corner_rms_px, bound_deg, fit_rms,
      percentile(abs_all(yaw_deg), 1.0));
  return found > 0 ? 0 : 1;
}

}  // namespace camera_check
