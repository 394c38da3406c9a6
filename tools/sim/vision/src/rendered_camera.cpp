// The simulator's rendered camera (see docksim/rendered_camera.hpp).
#include "docksim/rendered_camera.hpp"

#include <algorithm>
#include <cmath>

#include "dockcore/drivers/camera_pipeline.hpp"
#include "docksim/sim_run.hpp"

namespace docksim {

using dockcore::Real;

bool make_tag_pattern(const std::string& family, int id, double size_m, TagPatternImage& out, std::string& error) {
  out = TagPatternImage{};
  if (!(size_m > 0)) {
    error = "tag size must be > 0";
    return false;
  }
  // One pixel per code cell: the smallest square image the tag fits in is its side in cells.
  std::vector<std::uint8_t> cells(64 * 64, 0);
  std::uint32_t black_cells = 0;
  std::uint32_t side = 0;
  for (std::uint32_t n = 4; n <= 64 && side == 0; ++n) {
    if (dockcore::drivers::draw_tag_upright(family, id, 1, 0, 0, cells.data(), n, n, n, &black_cells)) side = n;
  }
  if (side == 0 || black_cells == 0) {
    error = "cannot draw tag " + std::to_string(id) + " of family '" + family + "'";
    return false;
  }
  cells.resize(static_cast<std::size_t>(side) * side);
  out.cells = std::move(cells);
  out.pattern = TagPattern{out.cells.data(), side, size_m / black_cells};
  return true;
}

std::unique_ptr<RenderedTagCamera> RenderedTagCamera::create(const Scenario& sc, std::string& error) {
  std::unique_ptr<RenderedTagCamera> c(new RenderedTagCamera());
  const CameraSpec& cam = sc.camera;
  if (!make_tag_pattern(sc.dock_tag.family, sc.dock_tag.id, sc.dock_tag.size_m, c->tag_, error)) {
    error = "dock.tag: " + error;
    return nullptr;
  }
  PinholeView& v = c->view_;
  v.fx_px = v.fy_px = static_cast<double>(cam.model.fx_px);
  v.cx_px = static_cast<double>(cam.model.cx_px);
  v.cy_px = cam.cy_px;
  v.width_px = static_cast<std::uint32_t>(cam.model.image_width_px);
  v.height_px = cam.height_px;
  v.background = 128;
  const dockcore::TagFusionParams tag = tag_fusion_params(sc);
  c->mount_ = tag.mount;
  c->dock_world_ = sc.dock_pose;
  c->dock_tag_ = tag.dock_tag;
  c->blur_px_ = cam.blur_px;
  c->exposure_q8_ = static_cast<int>(std::lround(cam.exposure * 256));
  c->tag_id_ = sc.dock_tag.id;

  dockcore::drivers::TagDetectorOptions o;
  o.family = sc.dock_tag.family;
  o.tag_size_m = sc.dock_tag.size_m;
  o.intrinsics = dockcore::drivers::CameraIntrinsics{v.fx_px, v.fy_px, v.cx_px, v.cy_px};
  o.quad_decimate = cam.decimate;
  c->detector_ = dockcore::drivers::TagDetector::create(o, error);
  if (!c->detector_) {
    error = "robot.camera / dock.tag: " + error;
    return nullptr;
  }
  c->image_.assign(static_cast<std::size_t>(v.width_px) * v.height_px, v.background);
  // The noise table: twice a frame's pixels, so any offset below one frame reads a whole frame's worth. Drawn from a
  // fixed stream (a texture, not a run's randomness: each frame's offset comes from the run's stream).
  Rng table_rng(0x4E4F495345ull);
  c->noise_.resize(2 * c->image_.size());
  for (std::int8_t& n : c->noise_) {
    n = static_cast<std::int8_t>(std::clamp(std::lround(table_rng.normal() * cam.noise_grey), -127L, 127L));
  }
  return c;
}

CameraFrameOutput RenderedTagCamera::capture(const dockcore::Pose2& robot_world, bool dock_visible,
                                             const World* occluders, Rng& rng) {
  // One draw per frame whatever happens, so the run's stream does not depend on what the camera saw.
  const auto offset = static_cast<std::size_t>(rng.uniform() * static_cast<double>(image_.size()));
  CameraFrameOutput out;
  if (!dock_visible) return out;
  const dockcore::Pose2 cam2 = robot_world.compose(dockcore::Pose2{mount_.x_m, mount_.y_m, mount_.yaw_rad});
  const dockcore::CameraMount3 camera_world{cam2.x_m, cam2.y_m, mount_.z_m, cam2.yaw_rad, 0, 0};
  place_tag_in_view(view_, camera_world, dock_world_, dock_tag_);
  PixelRect box;
  const auto blur_margin = static_cast<std::uint32_t>(std::ceil(3 * blur_px_)) + 2;
  if (!tag_pixel_bounds(tag_.pattern, view_, blur_margin, box)) return out;
  std::fill(image_.begin(), image_.end(), view_.background);
  render_tag(tag_.pattern, view_, image_.data(), view_.width_px, &box);
  if (occluders != nullptr && !occluders->segments.empty()) occlude_columns(*occluders, cam2, box);
  blur_grey(image_.data(), view_.width_px, view_.height_px, view_.width_px, blur_px_, &box);
  const std::int8_t* noise = noise_.data() + offset;
  // Exposure scales the light that reaches the sensor (saturating at white), then the sensor adds its noise.
  const int gain_q8 = exposure_q8_;
  for (std::size_t i = 0; i < image_.size(); ++i) {
    const int exposed = std::min(255, (image_[i] * gain_q8 + 128) >> 8);
    image_[i] = static_cast<std::uint8_t>(std::clamp(exposed + noise[i], 0, 255));
  }
  dockcore::drivers::TagDetection dets[4];
  const std::size_t n = detector_->detect(image_.data(), view_.width_px, view_.height_px, view_.width_px, dets, 4);
  dockcore::drivers::TagFrameResult r;
  if (dockcore::drivers::select_target_tag(
          dets, n, tag_id_, dockcore::drivers::CameraPipelineOptions{}.full_confidence_margin, 0, &r) == nullptr)
    return out;
  out.target = r.target;
  out.has_tag = r.has_pose;
  out.tag = r.tag;
  return out;
}

void RenderedTagCamera::occlude_columns(const World& occluders, const dockcore::Pose2& camera_world,
                                        const PixelRect& box) {
  // The tag's plane in the world, seen from above: through the tag's centre, normal along the dock's x axis.
  const dockcore::Vec2 tag = dock_world_.transform(dockcore::Vec2(dock_tag_.x_m, dock_tag_.y_m));
  const dockcore::Vec2 normal(std::cos(dock_world_.yaw_rad), std::sin(dock_world_.yaw_rad));
  const dockcore::Vec2 origin(camera_world.x_m, camera_world.y_m);
  for (std::uint32_t c = box.col0; c < box.col1; ++c) {
    // The column's ray in the camera body frame (x forward, y left), then in the world.
    const double left = -(c - view_.cx_px) / view_.fx_px;
    const dockcore::Vec2 body(static_cast<Real>(1 / std::hypot(1.0, left)),
                              static_cast<Real>(left / std::hypot(1.0, left)));
    const dockcore::Vec2 dir = dockcore::Pose2{0, 0, camera_world.yaw_rad}.transform(body);
    const double along = static_cast<double>(normal.dot(dir));
    if (std::fabs(along) < 1e-6) continue;
    const double to_tag = static_cast<double>(normal.dot(tag - origin)) / along;
    double range = 0;
    if (to_tag > 0 && occluders.raycast(origin, dir, to_tag, &range)) {
      for (std::uint32_t r = box.row0; r < box.row1; ++r) image_[static_cast<std::size_t>(r) * view_.width_px + c] = 60;
    }
  }
}

}  // namespace docksim
