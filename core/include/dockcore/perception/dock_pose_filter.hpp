#pragma once
/// @file Temporal filter for the dock pose on SE(2), fed with wheel odometry between scans.
///
/// The dock does not move, so the filter estimates one static pose: the dock in the odometry frame. Each detection
/// (dock in the robot frame) is mapped through the robot's odometry pose at the scan time and fused by a Kalman
/// update with the yaw innovation wrapped to (-pi, pi]. Odometry drift is the process noise: the estimate's
/// covariance grows with the distance and angle the robot travels. A Mahalanobis gate rejects jumps (a bad
/// detection, or the robot pushed so odometry no longer matches); after `reinit_after` consecutive rejections the
/// filter restarts from the newest detection and reports it. A second source, a camera's tag pose (update_tag), goes
/// through the same mapping, gate and Kalman update but adds no evidence to the sequential test and restarts the
/// filter only while it rests on tags alone (docs/camera.md, "Fusion"). Cost O(1) per call; no heap.

#include <cstdint>

#include "dockcore/geometry.hpp"

namespace dockcore {

struct DockFilterParams {
  Real pos_noise_per_m = static_cast<Real>(0.01);     ///< Position σ added per metre travelled (m/√m).
  Real yaw_noise_per_rad = static_cast<Real>(0.02);   ///< Yaw σ added per radian turned (rad/√rad).
  Real yaw_noise_per_m = static_cast<Real>(0.01);     ///< Yaw σ added per metre travelled (rad/√m).
  Real min_meas_sigma_m = static_cast<Real>(0.002);   ///< Floor on a detection's position σ (model errors).
  Real min_meas_sigma_rad = static_cast<Real>(0.0035);///< Floor on a detection's yaw σ (~0.2°).
  Real gate_chi2 = static_cast<Real>(16.27);          ///< Mahalanobis² gate, χ²(3) at 99.9 %.
  std::uint8_t reinit_after = 3;                      ///< Consecutive gated detections that restart the filter.
  /// Sequential test: the filtered dock is confirmed once the detections it fused since it (re)started add up to
  /// this much evidence (DockEstimate::evidence, nats) over at least two scans. Were the scans independent, a
  /// dock-less scene would pass with probability at most e^-this (6e-6 at 12); docs/performance.md gives the rates
  /// measured on real recordings.
  Real confirm_evidence_nats = static_cast<Real>(12);
};

/// Outcome of one update.
enum class FilterUpdate : std::uint8_t {
  kInitialised = 0,  ///< First detection (or after reset()): the filter starts from it.
  kFused = 1,        ///< Detection passed the gate and was fused.
  kGated = 2,        ///< Detection rejected as a jump; the estimate is unchanged.
  kReinitialised = 3,///< Too many consecutive jumps: the filter restarted from this detection.
  kInvalid = 4,      ///< Non-finite input; nothing changed.
};

class DockPoseFilter {
 public:
  explicit DockPoseFilter(const DockFilterParams& params = DockFilterParams{}) : params_(params) {}

  /// Forgets the dock. O(1).
  void reset();
  /// Grows the covariance by the odometry motion since the previous call (first call only records the pose).
  /// `odom_pose`: robot in the odometry frame. O(1).
  void predict(const Pose2& odom_pose);
  /// Fuses a detection: `dock_in_robot` with covariance `cov_robot` (x, y, yaw in the robot frame), taken when the
  /// robot was at `odom_pose`, at time `stamp_us`, with the estimator's evidence for it (`evidence_nats`, the sum of
  /// its cues; 0 when unknown). Calls predict(odom_pose) first. O(1).
  FilterUpdate update(const Pose2& dock_in_robot, const Mat3& cov_robot, const Pose2& odom_pose, std::uint64_t stamp_us,
                      Real evidence_nats = 0);

  /// Fuses a tag measurement (dock pose in the robot frame from a camera's tag, TagMeasurement) like update(), with
  /// three differences: it adds no evidence and does not count as a scan for confirmed(); its consecutive gated
  /// measurements restart the filter only while no lidar detection has been fused since the filter (re)started (the
  /// lidar, when present, is not overruled by the camera); and a filter it starts counts no scans. O(1).
  FilterUpdate update_tag(const Pose2& dock_in_robot, const Mat3& cov_robot, const Pose2& odom_pose,
                          std::uint64_t stamp_us);

  bool initialised() const { return initialised_; }
  /// Dock pose in the odometry frame and its covariance. Meaningful only when initialised().
  const Pose2& dock_in_odom() const { return dock_odom_; }
  const Mat3& covariance_odom() const { return cov_odom_; }
  /// The dock pose as seen from a robot at `odom_pose`, with covariance in the robot frame. O(1).
  Pose2 dock_in_robot(const Pose2& odom_pose, Mat3* cov_robot = nullptr) const;
  /// Time of the last fused (or initialising) detection.
  std::uint64_t last_update_us() const { return last_update_us_; }
  std::uint32_t fused() const { return fused_; }
  std::uint32_t gated() const { return gated_; }
  std::uint32_t reinitialisations() const { return reinits_; }
  /// Tag measurements fused (update_tag: kInitialised, kFused, kReinitialised) and gated.
  std::uint32_t tag_fused() const { return tag_fused_; }
  std::uint32_t tag_gated() const { return tag_gated_; }
  /// A lidar detection has been fused since the filter (re)started (a tag start counts none). O(1).
  bool lidar_since_start() const { return fused_since_start_ > 0; }
  /// Mahalanobis² of the most recent innovation (gated or not).
  Real last_mahalanobis2() const { return last_d2_; }
  /// The sequential test's sum: evidence of the detections fused since the filter (re)started, nats.
  Real evidence_nats() const { return evidence_nats_; }
  /// Detections fused since the filter (re)started (the initialising one included).
  std::uint32_t fused_since_start() const { return fused_since_start_; }
  /// The sequential test passed: at least two fused detections whose evidence reaches confirm_evidence_nats.
  bool confirmed() const {
    return initialised_ && fused_since_start_ >= 2 && evidence_nats_ >= params_.confirm_evidence_nats;
  }

 private:
  void start(const Pose2& z, const Mat3& rz, std::uint64_t stamp_us, Real evidence_nats);
  /// The measurement mapped into the odometry frame with its floored covariance (after predict). O(1).
  void to_odom(const Pose2& dock_in_robot, const Mat3& cov_robot, const Pose2& odom_pose, Pose2* z, Mat3* rz) const;
  /// Mahalanobis² of z against the estimate into last_d2_; false when the innovation covariance is singular. O(1).
  bool innovation(const Pose2& z, const Mat3& rz, Vec3* nu, Mat3* s_inv);
  /// The Kalman update with innovation nu. O(1).
  void correct(const Vec3& nu, const Mat3& s_inv, const Mat3& rz);

  DockFilterParams params_;
  bool initialised_ = false;
  bool have_odom_ = false;
  Pose2 last_odom_{};
  Pose2 dock_odom_{};
  Mat3 cov_odom_ = Mat3::Zero();
  std::uint64_t last_update_us_ = 0;
  std::uint8_t consecutive_gated_ = 0;
  std::uint32_t fused_ = 0;
  std::uint32_t gated_ = 0;
  std::uint32_t reinits_ = 0;
  Real last_d2_ = 0;
  Real evidence_nats_ = 0;
  std::uint32_t fused_since_start_ = 0;
  std::uint8_t consecutive_tag_gated_ = 0;
  std::uint32_t tag_fused_ = 0;
  std::uint32_t tag_gated_ = 0;
};

}  // namespace dockcore
