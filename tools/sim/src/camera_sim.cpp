#include "docksim/camera_sim.hpp"

#include <cmath>

namespace docksim {

using dockcore::Real;

dockcore::CameraTarget project_target(const CameraSimParams& p, const dockcore::Pose2& robot_world,
                                      const dockcore::Vec2& target_world) {
  dockcore::CameraTarget t;
  const dockcore::Pose2 cam = robot_world.compose(p.model.mount);
  const dockcore::Vec2 q = cam.inverse_transform(target_world);  // camera frame: x along the optical axis, y left
  const double x = static_cast<double>(q.x()), y = static_cast<double>(q.y());
  if (!(x >= p.min_depth_m && x <= p.max_depth_m)) return t;
  // Image u grows to the right; robot/camera y grows to the left.
  const double u = static_cast<double>(p.model.cx_px) - static_cast<double>(p.model.fx_px) * y / x;
  if (u < 0 || u > static_cast<double>(p.model.image_width_px)) return t;
  t.valid = true;
  t.u_px = static_cast<Real>(u);
  t.v_px = static_cast<Real>(p.v_px);
  t.confidence = 1;
  return t;
}

void CameraSim::update(std::uint64_t t_us, const dockcore::Pose2& robot_world, const dockcore::Vec2& target_world,
                       bool visible, const World* occluders) {
  const std::uint64_t period_us = static_cast<std::uint64_t>(std::llround(1e6 / p_.rate_hz));
  const std::uint64_t latency_us = static_cast<std::uint64_t>(std::llround(p_.latency_s * 1e6));
  if (t_us >= next_capture_us_) {
    InFlight f{CameraFrameOutput{}};
    if (frame_camera_ != nullptr) {
      f.frame = frame_camera_->capture(robot_world, visible, occluders, rng_);
    } else {
      dockcore::CameraTarget& c = f.frame.target;
      c = visible ? project_target(p_, robot_world, target_world) : dockcore::CameraTarget{};
      // Draws happen for every frame, in a fixed order, so the stream does not depend on visibility.
      const double noise = rng_.normal() * p_.sigma_px;
      const bool dropped = rng_.bernoulli(p_.dropout_prob);
      if (c.valid) {
        c.u_px = static_cast<Real>(static_cast<double>(c.u_px) + noise);
        if (dropped) c = dockcore::CameraTarget{};
      }
    }
    f.frame.target.stamp_us = t_us;
    f.frame.tag.stamp_us = t_us;
    in_flight_.push_back(f);
    next_capture_us_ += period_us;
    if (next_capture_us_ <= t_us) next_capture_us_ = t_us + period_us;
  }
  while (!in_flight_.empty() && in_flight_.front().frame.target.stamp_us + latency_us <= t_us) {
    const InFlight& f = in_flight_.front();
    latest_ = f.frame.target;
    ++frames_delivered_;
    if (latest_.valid) ++frames_with_target_;
    if (f.frame.has_tag) tags_.push_back(f.frame.tag);
    in_flight_.pop_front();
  }
}

bool CameraSim::pop_tag(dockcore::TagObservation& tag) {
  if (tags_.empty()) return false;
  tag = tags_.front();
  tags_.pop_front();
  return true;
}

}  // namespace docksim
