#pragma once
/// @file Odometry: the robot's pose in the odometry frame from the chassis's feedback, and a short history of it so a
/// scan or a camera frame is placed where the robot was at its own stamp, not where it is when it is read.
///
/// Two kinds of chassis feed it (docs/architecture.md, "The control tick"):
/// - a base that reports measured wheel speeds (the CAN wheel-feedback frames): add_wheels() integrates them with the
///   configured drive geometry, midpoint rule on the previous and the new twist;
/// - a base that integrates its own odometry and reports the pose (the simulator's chassis firmware, many ROS bases):
///   add_pose() keeps it as given.
/// Feedback is placed by its stamp. A gap longer than kMaxGapUs is not integrated across: the wheels' history is
/// unknown there. No heap; 64 samples of history.

#include <cstddef>
#include <cstdint>

#include "dockcore/control/kinematics.hpp"
#include "dockcore/geometry.hpp"

namespace dockcore {

class Odometry {
 public:
  /// Samples kept for pose_at(): 1.3 s of 50 Hz feedback.
  static constexpr std::size_t kHistory = 64;
  /// Longest feedback interval integrated, µs.
  static constexpr std::uint64_t kMaxGapUs = 200000;

  /// Forgets everything: pose at the origin, no feedback yet. O(kHistory).
  void reset() { *this = Odometry{}; }

  /// Measured wheel speeds (rad/s, `geometry`'s order and count) at `stamp_us` (µs, the scans' clock). Advances the
  /// pose over the interval since the previous feedback when it is newer and at most kMaxGapUs long, then keeps the
  /// new twist and records the pose. A stamp of 0 or equal to the previous one is no new feedback: false, nothing
  /// changes. An older stamp (a clock step) restarts the interval without integrating. O(1).
  bool add_wheels(const DriveGeometry& geometry, const WheelSpeeds& measured, std::uint64_t stamp_us);

  /// A pose and body twist the base integrated itself, at `stamp_us`. Same stamp rules as add_wheels(). O(1).
  bool add_pose(const Pose2& pose, const Twist2& twist, std::uint64_t stamp_us);

  /// Feedback has arrived since the last reset(). O(1).
  bool valid() const { return valid_; }
  /// Pose after the newest feedback (origin before any). O(1).
  const Pose2& pose() const { return pose_; }
  /// Body twist of the newest feedback, m/s and rad/s. O(1).
  const Twist2& twist() const { return twist_; }
  /// Stamp of the newest feedback, µs (0 before any). O(1).
  std::uint64_t stamp_us() const { return stamp_us_; }
  /// The pose of the newest sample not after `stamp_us`; the current pose when no kept sample is that old (the
  /// history covers kHistory feedbacks) or before any feedback. `in_gap`, if given, receives whether feedback has
  /// arrived but that sample is missing or more than kMaxGapUs before `stamp_us`: something stamped then falls in a
  /// gap of the feedback (a host that read none for a while, a chassis outage), and the pose given is the one before
  /// the gap, however far the robot moved during it. O(kHistory).
  Pose2 pose_at(std::uint64_t stamp_us, bool* in_gap = nullptr) const;

 private:
  struct Sample {
    std::uint64_t stamp_us = 0;
    Pose2 pose{};
  };
  void record(std::uint64_t stamp_us);

  Pose2 pose_{};
  Twist2 twist_{};
  bool valid_ = false;
  std::uint64_t stamp_us_ = 0;
  Sample history_[kHistory] = {};
  std::size_t next_ = 0;
};

}  // namespace dockcore
