#pragma once
/// @file A fiducial tag's pose (an AprilTag on the dock, from a camera's tag detector) as a dock-pose measurement in
/// the robot frame, with a covariance from a pixel-noise model (docs/camera.md, "Fusion").
///
/// Frames. The camera's optical frame: z along the optical axis, x right, y down (as in the image). The tag frame
/// (libapriltag's estimate_tag_pose): origin at the tag's centre, x along its columns, y along its rows (down, as
/// printed), z out of its back — a tag facing the camera squarely has the identity rotation. The camera mount: the
/// camera body (x forward along the optical axis, y left, z up) at (x, y, z) in the robot frame, turned by yaw about
/// z, then pitch about y (positive = looking down), then roll about its x (the optical axis). The tag on the dock:
/// its centre at (x, y, z) in the dock frame (origin at the charging contacts, x out of the dock face, z up) and its
/// face turned by yaw about the dock's z; yaw 0 is a tag flat on the dock face looking out along the dock's +x.
///
/// The dock pose is the 3D chain robot ← camera ← tag ← dock projected to the plane: x, y of the dock origin and the
/// heading of the dock's x axis. Covariance model (per tag, σ_px the corner noise, f = fx_px, s = tag_size_m, Z the
/// tag's depth along the optical axis, θ its yaw to the line of sight): lateral σ = Z·σ_px / (2f) (the centre of four
/// corners), depth σ = Z²·σ_px / (√2·f·s) (the apparent side w = f·s/Z from four edges), yaw σ = 2·Z²·σ_px /
/// (f·s²·max(cos θ, 0.3)) (the difference of the left and right edge lengths). These are scaled by
/// `sigma_scale` and propagated through the tag's offset from the dock origin. No heap; O(1).

#include <cstdint>

#include "dockcore/geometry.hpp"

namespace dockcore {

/// A camera's pose on the robot, in 3D (see the file comment for the angle order).
struct CameraMount3 {
  Real x_m = 0;
  Real y_m = 0;
  Real z_m = 0;
  Real yaw_rad = 0;    ///< About the robot's z, counter-clockwise; 0 = looking forward.
  Real pitch_rad = 0;  ///< Positive = looking down.
  Real roll_rad = 0;   ///< About the optical axis.
};

/// Where the dock's tag sits on the dock (a per-dock setting) and which id it carries.
struct DockTag {
  std::int32_t id = -1;  ///< The tag id on this dock; −1: the dock has no tag (tag detections are ignored).
  Real x_m = 0;          ///< Tag centre in the dock frame.
  Real y_m = 0;
  Real z_m = 0;
  Real yaw_rad = 0;  ///< The tag's face about the dock's z; 0 = facing along the dock's +x.
};

/// Tag fusion: the camera, the dock's tag, the noise model and the time bounds. Defaults from the rendered-frame
/// measurements of docs/camera.md ("Fusion").
struct TagFusionParams {
  CameraMount3 mount{};                      ///< The camera on the robot (dockd: [camera.mount]).
  Real fx_px = 600;                          ///< Focal length in pixels (dockd: [camera.intrinsics] fx_px). > 0.
  Real tag_size_m = static_cast<Real>(0.1);  ///< Side of the tag's black square (dockd: [camera.tag] size_m). > 0.
  DockTag dock_tag{};                        ///< The active dock's tag (dockd: its [[docks]] entry).
  /// Effective corner noise of the detector, px: the model's one free parameter (see the file comment). Measured
  /// on rendered frames with noise and blur, corners refined and fitted: `camera-check tag-pose`.
  Real sigma_px = static_cast<Real>(0.04);
  Real sigma_scale = 1;                       ///< Multiplies every σ of the model (inflate for a poorer camera).
  Real min_decision_margin = 0;               ///< Detections with a smaller decision margin are refused (kWeak).
  Real max_range_m = static_cast<Real>(3.0);  ///< Tags farther than this along the optical axis are refused (kFar).
  /// A tag frame older than the newest scan by more than this is refused (kStale): its odometry pose is the oldest
  /// data fused, and odometry history is short. s.
  Real max_lag_s = static_cast<Real>(0.05);
};

/// Corner k of a tag in the tag frame, in half sides: (kTagCornerX[k], kTagCornerY[k])·size/2 (libapriltag's order,
/// the one its pose estimate pairs with the detected corners).
constexpr Real kTagCornerX[4] = {-1, 1, 1, -1};
constexpr Real kTagCornerY[4] = {1, 1, -1, -1};

/// One tag detection as a camera's detector gives it.
struct TagObservation {
  std::int32_t id = -1;
  Real decision_margin = 0;           ///< The detector's decode quality.
  std::uint64_t stamp_us = 0;         ///< Capture time of the frame, on the host's monotonic clock.
  Mat3 rotation = Mat3::Identity();   ///< Tag frame → camera optical frame.
  Vec3 translation_m = Vec3::Zero();  ///< Tag centre in the camera optical frame, m.
  /// With the corners the dock pose is fitted to them (tag_to_dock_measurement); without, rotation and translation
  /// are used as given.
  bool has_corners = false;
  /// The detected corners in the ideal pinhole image, in unit-focal coordinates ((u − cx)/fx, (v − cy)/fy, lens
  /// distortion removed), in the kTagCornerX/Y order.
  Vec2 corners[4] = {Vec2::Zero(), Vec2::Zero(), Vec2::Zero(), Vec2::Zero()};
};

/// Why a tag detection was or was not turned into a measurement, or fused.
enum class TagStatus : std::uint8_t {
  kFused = 0,       ///< Fused into the dock filter (or started it).
  kWrongId = 1,     ///< Not the active dock's tag (or the dock has none).
  kInvalid = 2,     ///< Non-finite, not a rotation, or a bad camera model (fx_px, tag_size_m ≤ 0).
  kBehind = 3,      ///< The tag is not in front of the camera (z ≤ 0), or seen from its back.
  kFar = 4,         ///< Farther than max_range_m.
  kWeak = 5,        ///< Decision margin below min_decision_margin.
  kStale = 6,       ///< Older than the newest scan by more than max_lag_s, or in a gap of the odometry.
  kOutOfOrder = 7,  ///< Not newer than the previous tag frame given.
  kGated = 8,       ///< Rejected by the filter's Mahalanobis gate.
};
constexpr std::size_t kTagStatusCount = 9;
/// Stable name of a status ("fused", "wrong_id", …). O(1).
const char* to_string(TagStatus s);

/// A tag detection turned into a dock pose in the robot frame.
struct TagMeasurement {
  Pose2 dock_in_robot{};
  Mat3 covariance = Mat3::Zero();  ///< Of (x, y, yaw) in the robot frame.
  Real depth_m = 0;                ///< The tag's depth along the optical axis.
  Real corner_rms_px = -1;         ///< RMS reprojection error of the corner fit; −1: no fit (no corners).
};

/// A dock pose fitted to a tag's corners.
struct TagCornerFit {
  Pose2 dock_in_robot{};
  Real rms_px = 0;  ///< RMS over the 8 corner coordinates of (projected − detected), px (fx_px per unit focal).
  std::int32_t iterations = 0;
};

/// Gauss–Newton iterations at most per start of fit_dock_to_tag_corners.
constexpr std::int32_t kTagFitMaxIterations = 20;

/// Fits the dock pose (x, y, yaw in the robot frame) to the tag's four `corners` (TagObservation::corners) by
/// Gauss–Newton on their reprojection error, starting at `start`. The rest of the chain is taken as known: the
/// dock stands upright on the floor the robot drives on, the camera's mount (height, pitch, roll) and the tag's place
/// on the dock and size are as configured, so 3 unknowns are fitted to 8 coordinates. False (out untouched) when a
/// corner is behind the camera at the start or the result is not finite. O(kTagFitMaxIterations).
bool fit_dock_to_tag_corners(const Vec2 corners[4], const TagFusionParams& params, const Pose2& start,
                             TagCornerFit* out);

/// The camera optical frame → robot frame rotation for `mount`. O(1).
Mat3 camera_rotation(const CameraMount3& mount);

/// Turns `obs` into a dock-pose measurement (the id is not checked here). Returns kFused for a usable measurement
/// (written to `out`), else kInvalid, kBehind, kFar or kWeak and leaves `out` alone. With corners, the pose is
/// fit_dock_to_tag_corners started from the given pose and from its mirror image about the line of sight (the other
/// minimum of a planar target's pose), whichever fits the corners better. O(1).
TagStatus tag_to_dock_measurement(const TagObservation& obs, const TagFusionParams& params, TagMeasurement* out);

}  // namespace dockcore
