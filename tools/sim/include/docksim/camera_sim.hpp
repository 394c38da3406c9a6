#pragma once
// Pinhole camera simulation of seed 003's vision process: one target point on the dock (e.g. a marker above the
// charging contacts) projected through dockcore::CameraModel, with pixel noise, frame dropouts, a frame rate and a
// delivery latency. 2D world: only the column u is geometric; the row v is a constant.
// Host-side; deterministic for a given seed (docksim::Rng only).
#include <cstdint>
#include <deque>

#include "dockcore/controller.hpp"
#include "dockcore/geometry.hpp"
#include "docksim/rng.hpp"

namespace docksim {

/// Camera simulation parameters (scenario [robot.camera]).
struct CameraSimParams {
  dockcore::CameraModel model{};  ///< Intrinsics (fx, cx, width) and mount in the robot frame.
  double rate_hz = 20.0;          ///< Frames per second (> 0).
  double latency_s = 0.05;        ///< Frame capture to delivery.
  double sigma_px = 1.0;          ///< 1-sigma Gaussian noise on u.
  double dropout_prob = 0.0;      ///< Chance a frame carries no detection.
  double min_depth_m = 0.05;      ///< Target nearer than this along the optical axis is not detected.
  double max_depth_m = 4.0;       ///< ... or farther than this.
  double v_px = 240.0;            ///< Row reported for the target.
};

/// Noise-free projection of `target_world` for a robot at `robot_world`. valid = false when the target is behind
/// the camera, outside [min_depth, max_depth] or outside the image columns [0, width]. stamp_us = 0. O(1).
dockcore::CameraTarget project_target(const CameraSimParams& p, const dockcore::Pose2& robot_world,
                                      const dockcore::Vec2& target_world);

/// A camera producing frames at rate_hz, delivered latency_s later.
class CameraSim {
 public:
  CameraSim(const CameraSimParams& p, std::uint64_t seed) : p_(p), rng_(seed) {}

  /// Advances to time t_us: captures a frame when one is due (from `robot_world`; `visible` false = the target is
  /// hidden) and delivers every frame whose latency has passed. Call at least once per frame period. O(1) amortised.
  void update(std::uint64_t t_us, const dockcore::Pose2& robot_world, const dockcore::Vec2& target_world, bool visible);
  /// The most recently delivered frame (invalid until the first one; an empty frame is delivered as invalid with
  /// its stamp).
  const dockcore::CameraTarget& latest() const { return latest_; }
  const CameraSimParams& params() const { return p_; }

 private:
  CameraSimParams p_;
  Rng rng_;
  std::uint64_t next_capture_us_ = 0;
  std::deque<dockcore::CameraTarget> in_flight_;
  dockcore::CameraTarget latest_{};
};

}  // namespace docksim
