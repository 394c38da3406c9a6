#pragma once
// Camera simulation of seed 003's vision process, at a frame rate and with a delivery latency. Two models of what
// a frame yields:
// - target level (the default): one target point on the dock (e.g. a marker above the charging contacts) projected
//   through dockcore::CameraModel, with pixel noise and frame dropouts. 2D world: only the column u is geometric;
//   the row v is a constant;
// - rendered (a FrameCamera): an image of the dock's tag at the camera's true pose, run through a tag detector; the
//   frame gives the detected target and the tag's pose.
// Host-side; deterministic for a given seed (docksim::Rng only).
#include <cstdint>
#include <deque>
#include <utility>

#include "dockcore/control/controller.hpp"
#include "dockcore/geometry.hpp"
#include "dockcore/perception/tag_measurement.hpp"
#include "docksim/lidar_sim.hpp"
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

/// What one frame gives: seed 003's target (invalid when nothing was found) and, from a rendered camera, the
/// target tag's pose.
struct CameraFrameOutput {
  dockcore::CameraTarget target{};
  bool has_tag = false;
  dockcore::TagObservation tag{};
};

/// A camera that sees through images: renders the frame at the camera's true pose and runs a detector on it.
/// Implemented outside dockcore_sim (the detector is libapriltag's: tools/sim/vision). One per run: not shared
/// between threads.
class FrameCamera {
 public:
  virtual ~FrameCamera() = default;
  /// The frame captured with the robot at `robot_world`; `dock_visible` false: the dock and its tag are hidden.
  /// `occluders` (optional): what may stand between the camera and the dock, in the world frame (not the dock or
  /// its wall); the 2D world's objects are taken to be taller than the camera, so each hides whole image columns.
  /// Noise comes from `rng`. Stamps are left 0 (the caller stamps the frame).
  virtual CameraFrameOutput capture(const dockcore::Pose2& robot_world, bool dock_visible, const World* occluders,
                                    Rng& rng) = 0;
};

/// A camera producing frames at rate_hz, delivered latency_s later.
class CameraSim {
 public:
  /// `frame_camera` (optional, not owned, must outlive this): rendered frames instead of the target-level model.
  CameraSim(const CameraSimParams& p, std::uint64_t seed, FrameCamera* frame_camera = nullptr)
      : p_(p), rng_(seed), frame_camera_(frame_camera) {}

  /// Advances to time t_us: captures a frame when one is due (from `robot_world`; `visible` false = the target is
  /// hidden; `occluders` as FrameCamera::capture, used by rendered frames only) and delivers every frame whose latency
  /// has passed. Call at least once per frame period. O(1) amortised (plus a render and a detection per rendered
  /// frame).
  void update(std::uint64_t t_us, const dockcore::Pose2& robot_world, const dockcore::Vec2& target_world, bool visible,
              const World* occluders = nullptr);
  /// True when update(t_us, ...) will capture a frame (so a caller builds a frame's inputs only then). O(1).
  bool frame_due(std::uint64_t t_us) const { return t_us >= next_capture_us_; }
  /// The most recently delivered frame (invalid until the first one; an empty frame is delivered as invalid with
  /// its stamp).
  const dockcore::CameraTarget& latest() const { return latest_; }
  /// The oldest delivered tag pose not yet taken (stamped with its frame's capture). False when none.
  bool pop_tag(dockcore::TagObservation& tag);
  /// Frames delivered so far, and those that carried a valid target.
  std::uint64_t frames_delivered() const { return frames_delivered_; }
  std::uint64_t frames_with_target() const { return frames_with_target_; }
  const CameraSimParams& params() const { return p_; }

 private:
  struct InFlight {
    CameraFrameOutput frame;
  };
  CameraSimParams p_;
  Rng rng_;
  FrameCamera* frame_camera_ = nullptr;
  std::uint64_t next_capture_us_ = 0;
  std::deque<InFlight> in_flight_;
  std::deque<dockcore::TagObservation> tags_;
  dockcore::CameraTarget latest_{};
  std::uint64_t frames_delivered_ = 0;
  std::uint64_t frames_with_target_ = 0;
};

}  // namespace docksim
