#pragma once
/// @file SceneCheck: did the room move the way odometry says? The push test's second opinion (docs/task-manager.md,
/// "Push test").
///
/// A detection far from where odometry expects the dock is either a push (the robot was moved and odometry did not
/// see it) or another object taken for the dock (furniture beside it, seen while the dock is hidden). One scan tells
/// them apart: after a push everything the lidar saw before has moved by the same correction, while after a false
/// detection the room stands where odometry puts it. So the points of a reference scan (the latest scan whose
/// detection agreed with the expectation), kept in the odometry frame, are predicted into the current scan under
/// both hypotheses, and each hypothesis scores the points it explains (a return within the range tolerance) minus
/// the points it contradicts (a return well beyond the predicted surface, or no return on that beam and both its
/// neighbours: free space where the hypothesis puts something). A nearer return is an occlusion and a lone missing
/// return a dropout; they count for neither. A wall parallel to a shove looks the same under both; the dock, the
/// furniture and the wall's ends decide.
///
/// No heap; set_reference() O(count), judge() O(kCapacity).

#include <cstddef>
#include <cstdint>

#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"

namespace dockcore {

/// Which hypothesis the current scan supports.
enum class SceneVerdict : std::uint8_t {
  kUnknown = 0,  ///< No reference, too few points compared, or neither hypothesis clearly ahead.
  kStill,        ///< The room stands where odometry puts it: the robot was not moved.
  kMoved,        ///< The room moved by the correction: the robot was moved (a push).
};

/// "unknown" / "still" / "moved". Never null.
const char* to_string(SceneVerdict v);

/// The check's thresholds.
struct SceneCheckParams {
  Real range_tolerance_m = static_cast<Real>(0.05);     ///< A predicted point is explained within this, m, ...
  Real range_tolerance_frac = static_cast<Real>(0.02);  ///< ... plus this share of its range.
  Real max_range_m = static_cast<Real>(6.0);            ///< Reference returns beyond this are not kept, m.
  std::uint16_t min_margin_points = 10;  ///< A verdict needs this many more net points than the other hypothesis.
  /// kStill also needs this share explained of the points that vote on it (explained or contradicted: an occluded
  /// point says nothing, and someone standing near the lidar hides much of the room).
  Real min_explained_share = static_cast<Real>(0.5);
  std::uint16_t min_compared = 20;  ///< kStill needs at least this many reference points seen in the scan.
  /// How far a far detection's yaw may be off, rad: the blur push_readings() allows each partial reading of a
  /// detection.
  Real reading_blur_rad = static_cast<Real>(0.1745);
};

/// Points each hypothesis explains and contradicts (judge()'s detail, for reports and tests).
struct SceneVotes {
  std::uint16_t compared = 0;         ///< Reference points predicted onto a beam with a return (still hypothesis).
  std::uint16_t still_explained = 0;  ///< Explained under "odometry is right".
  std::uint16_t still_contradicted = 0;
  std::uint16_t moved_explained = 0;  ///< Explained under "the room moved by the correction".
  std::uint16_t moved_contradicted = 0;
};

/// Where the dock was expected, in the odometry frame: a disc about its origin that holds its outline. Under "still",
/// a reference point in it that the scan reads beyond counts for neither hypothesis: the dock not being seen where it
/// was is what brought a detection elsewhere to be judged, whether the dock was hidden or moved, so it cannot also
/// tell which.
struct ExpectedDock {
  Vec2 centre_odom_m{0, 0};
  Real radius_m = 0;
};

/// A turn on the spot by `yaw_rad` of the robot at `robot_in_odom`, as the odometry-frame correction it makes: the room
/// turns about the robot. O(1).
Pose2 turn_about(const Pose2& robot_in_odom, Real yaw_rad);

/// The pushes a detection off its expectation may mean, as odometry-frame corrections for SceneCheck::judge(), written
/// to `out`; returns how many (1 to 3). Always the full correction, detected ∘ expected⁻¹. One detection's yaw at range
/// is noisy enough to blur a pure shove and its position a turn on the spot, so also each partial reading the
/// detection allows: the shift alone when the detection's turn is within params.reading_blur_rad (the turn may then
/// be noise), and the turn alone, about the robot at `robot_in_odom`, when it lands the expectation within
/// 5 cm + range × reading_blur_rad of the detection. A reading the detection does not allow would be judged anyway
/// and could only blur the verdict: a turn of a degree explains no detection a metre along the wall, yet it ties
/// with "still" however clearly the room stood still. O(1).
std::size_t push_readings(const Pose2& expected_in_odom, const Pose2& detected_in_odom, const Pose2& robot_in_odom,
                          const SceneCheckParams& params, Pose2 out[3]);

/// Reference scan and the two-hypothesis test. Fixed capacity: kCapacity points, taken at an even stride.
class SceneCheck {
 public:
  static constexpr std::size_t kCapacity = 180;

  /// Forgets the reference. O(1).
  void clear() { count_ = 0; }
  /// Keeps up to kCapacity of `scan`'s returns (an even stride over the returns) as the reference, in the odometry
  /// frame: the lidar at `odom_pose` ∘ `lidar_mount`. Returns beyond params.max_range_m are left out. O(scan.count).
  void set_reference(const ScanView& scan, const Pose2& lidar_mount, const Pose2& odom_pose,
                     const SceneCheckParams& params);
  /// How many points set_reference() would keep from `scan` (its returns within params.max_range_m, at most
  /// kCapacity). O(scan.count).
  static std::size_t points_kept(const ScanView& scan, const SceneCheckParams& params);
  /// Reference points kept. O(1).
  std::size_t reference_points() const { return count_; }
  /// Judges `scan`, taken at `odom_pose`, against the reference: "still" predicts each reference point where it was
  /// (odometry right), "moved" at correction ∘ point for each of the `n` candidate corrections (a push by an
  /// odometry-frame correction: the one the detection implies, detected ∘ expected⁻¹, and the readings of it that a
  /// noisy detection blurs, e.g. its shift alone or its turn alone), the best of them counting. kStill needs
  /// min_compared points, min_explained_share of the points that vote on it explained, and a margin over every
  /// candidate. `docks`: the `n_docks` places the dock may be hidden at (ExpectedDock): the expectation, and where
  /// the filter followed the dock before something else restarted it. The last `probes` of the n candidates are pushes
  /// "still" must also beat but that never make a kMoved verdict (shoves the room could show, not the one a detection
  /// implies). `votes`, if given, receives the counts (moved: the best candidate's, probes included). n ≥ 1,
  /// probes < n. O(n · kCapacity).
  SceneVerdict judge(const ScanView& scan, const Pose2& lidar_mount, const Pose2& odom_pose, const Pose2* corrections,
                     std::size_t n, const SceneCheckParams& params, SceneVotes* votes = nullptr, std::size_t probes = 0,
                     const ExpectedDock* docks = nullptr, std::size_t n_docks = 0) const;

 private:
  Vec2 points_odom_m_[kCapacity];
  std::size_t count_ = 0;
};

}  // namespace dockcore
