#pragma once
/// @file Safety checks for docking: obstacles in the robot's path from a lidar scan (seed 004's footprint check),
/// and pose deviation (seed 004's faults 178/179: the robot pushed or too far away).
///
/// Obstacle check (seed 004, Table 3). All geometry in the robot frame (x forward, y left, origin at the rotation
/// centre). A scan point is ignored when it is
///  - the robot itself: a return on a beam inside one of the configured self sectors (lidar-frame bearings where
///    the lidar sees the robot's own structure: lidar posts, a bumper in the scan plane) that lies inside the body
///    outline grown by self_margin_m. Only configured, static structure is the robot: a return anywhere else is
///    never taken for it, however close — an obstacle that comes within the margin of the body or inside its
///    outline (the robot touching or driving into it) stays visible and blocks (docs/task-manager.md, "Obstacles").
///    The default configures no sector: the lidar sees none of the robot (mounted on top, as in the simulator);
///  - the dock: within dock_margin_m of the dock profile's polyline placed at the dock estimate, or in the dock zone:
///    at or behind the dock's face plane (dock-frame x <= profile's largest x + dock_margin_m) within
///    dock_zone_half_width_m of the dock axis — the wall the dock stands against, which the robot must come close
///    to in order to touch the contacts (Nav2 likewise excludes the dock's last 0.3 m from its collision check).
/// Of the remaining points:
///  - forward-blocked: body front < x <= body front + check_length_m and |y| < check_width_m / 2. The seed measures
///    the 0.3 m "in x"; from the robot centre that would lie inside its own 0.37 m half-length square body, so the
///    area starts at the body's front edge. Also any point inside the body outline with x >= 0: something the
///    robot already touches or overlaps must not be driven further into.
///  - backward-blocked: the same area mirrored behind the body's rear edge (undocking, backing off), and points
///    inside the body with x <= 0.
///  - rotation-blocked: closer than circumscribed_radius_m to the rotation centre (a turning corner would hit it).
/// A direction is blocked when at least min_points points fall in its area (one stray return is noise).
/// Cost O(B · S): B beams, S profile segments (only points within the circumscribed radius or the check areas reach
/// the profile test). No heap.

#include <cstdint>
#include <limits>

#include "dockcore/control/controller.hpp"
#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "dockcore/task/faults.hpp"

namespace dockcore {

/// A bearing interval in the lidar frame, [min_rad, max_rad] within (-pi, pi]; min_rad > max_rad wraps through pi
/// (a sector behind a forward-facing lidar).
struct AngleSector {
  Real min_rad = 0;
  Real max_rad = 0;
};

/// Most self sectors a footprint can hold (four lidar posts).
constexpr std::size_t kMaxSelfSectors = 4;

/// Body outline used by the obstacle check.
enum class FootprintShape : std::uint8_t {
  kSquare = 0,    ///< Rectangle half_length_m x half_width_m about the rotation centre.
  kCircular = 1,  ///< Disc of radius_m about the rotation centre.
};

/// Footprint and obstacle-check parameters. Defaults: seed 004's square robot (Table 3: obstacle_check_area_length
/// 0.3 m, obstacle_check_area_width 0.5 m, circumscribed_radius 0.45 m; the body half-length 0.37 m follows from a
/// 0.5 m wide body with that circumscribed radius). circular_footprint() gives the seed's round robot.
struct FootprintParams {
  FootprintShape shape = FootprintShape::kSquare;
  Real half_length_m = static_cast<Real>(0.37);  ///< Square body: centre to front edge and to rear edge (m).
  Real half_width_m = static_cast<Real>(0.25);   ///< Square body: centre to each side (m).
  Real radius_m = static_cast<Real>(0.275);      ///< Circular body radius (m).
  Real check_length_m = static_cast<Real>(0.3);  ///< Forward/backward check area depth beyond the body edge (m).
  Real check_width_m = static_cast<Real>(0.5);   ///< Forward/backward check area full width (m).
  Real circumscribed_radius_m = static_cast<Real>(0.45);  ///< Rotation check radius about the centre (m).
  /// Range noise allowance on the robot's own structure: inside a self sector, returns inside the body grown by
  /// this are the robot itself (m). Outside the self sectors it has no effect.
  Real self_margin_m = static_cast<Real>(0.02);
  /// Lidar-frame bearings where the lidar sees the robot's own (static) structure; the first self_sector_count
  /// entries are used. Measure them on the robot (returns inside the body on an empty floor). Default none.
  AngleSector self_sectors[kMaxSelfSectors] = {};
  std::uint8_t self_sector_count = 0;
  Real dock_margin_m = static_cast<Real>(0.05);  ///< Points this close to the dock polyline are the dock (m).
  Real dock_zone_half_width_m = static_cast<Real>(0.6);  ///< Half-width of the zone at/behind the dock face (m).
  Real min_range_m = static_cast<Real>(0.02);    ///< Closer returns are ignored (lidar blind zone) (m).
  std::uint16_t min_points = 2;                  ///< Points in an area that make it blocked.
};

/// Seed 004's square robot (the FootprintParams defaults). O(1).
FootprintParams square_footprint();
/// Seed 004's circular robot: check area 0.3 x 0.5 m, circumscribed (= body) radius 0.275 m. O(1).
FootprintParams circular_footprint();
/// Distance from the rotation centre to the body's front (and rear) edge: half-length, or radius. O(1).
Real body_front_m(const FootprintParams& fp);
/// Distance from the rotation centre to the body's side edges: half-width, or radius. O(1).
Real body_half_width_m(const FootprintParams& fp);

/// Result of one obstacle check.
struct ObstacleFlags {
  bool valid = false;     ///< A scan was checked. When false every direction counts as blocked (fail safe).
  bool forward = false;   ///< Forward motion blocked.
  bool backward = false;  ///< Backward motion blocked.
  bool rotation = false;  ///< In-place rotation blocked.
  std::uint16_t forward_points = 0;
  std::uint16_t backward_points = 0;
  std::uint16_t rotation_points = 0;
  std::uint16_t dock_points = 0;  ///< Points ignored as the dock or the dock zone.
  std::uint16_t self_points = 0;  ///< Points ignored as the robot's own body (self sectors only).
  std::uint16_t body_points = 0;  ///< Obstacle points inside the body outline (the robot touches or overlaps them).
  /// Smallest x beyond the body front among forward points (0 when none; negative: inside the body outline).
  Real nearest_forward_m = 0;
};

/// Scan-based obstacle check. Holds the footprint and a copy of the dock profile (no references kept).
class ObstacleChecker {
 public:
  /// Sets the footprint and the dock outline to exclude (null: no dock exclusion). O(vertices).
  void configure(const FootprintParams& footprint, const DockProfile* profile);

  /// Checks one scan. `lidar_mount`: lidar in the robot frame. `dock_in_robot`: current dock estimate, or null when
  /// there is none (no dock exclusion). A scan with count 0 or a zero increment gives valid = false. Cost: see file.
  ObstacleFlags check(const ScanView& scan, const Pose2& lidar_mount, const Pose2* dock_in_robot) const;

  /// Classifies one point (robot frame); exposed for tests. O(S).
  bool is_dock_point(const Vec2& p_robot, const Pose2& dock_in_robot) const;
  /// True when a return at p_robot on a beam of lidar-frame bearing `lidar_bearing_rad` is the robot itself: the
  /// bearing lies in a configured self sector and p_robot inside the body grown by self_margin_m. O(sectors).
  bool is_self_point(const Vec2& p_robot, Real lidar_bearing_rad) const;
  /// True when p_robot lies inside the body outline (not grown). O(1).
  bool is_inside_body(const Vec2& p_robot) const;

  const FootprintParams& footprint() const { return fp_; }
  /// Distance from the rotation centre to the body's front (and rear) edge. O(1).
  Real body_front_m() const { return dockcore::body_front_m(fp_); }

 private:
  FootprintParams fp_{};
  DockProfile profile_{};
  bool have_profile_ = false;
  Real profile_max_x_m_ = 0;
  Real reach_m_ = std::numeric_limits<Real>::infinity();  // farthest any check zone lies from the centre (configure)
};

/// When a commanded twist counts as a rotation for the rotation check: |wz| at least `min_wz_radps` while |vx| is
/// at most `max_vx_mps` (turning in place or nearly; curved forward motion is covered by the forward area).
struct MotionGateParams {
  Real rotate_min_wz_radps = static_cast<Real>(0.05);
  Real rotate_max_vx_mps = static_cast<Real>(0.05);
  Real min_speed_mps = static_cast<Real>(0.001);  ///< |vx|, |vy| at or below this is not a translation.
};

/// True when `cmd` would move into a blocked direction of `flags` (invalid flags block any motion). Lateral motion
/// (vy) of holonomic robots is treated like forward motion: it is blocked when forward or rotation is blocked.
/// O(1).
bool motion_blocked(const Twist2& cmd, const ObstacleFlags& flags, const MotionGateParams& gate);

/// The part of `cmd` that `flags` let through: `cmd` when motion_blocked() is false; otherwise, when `keep_turn` is
/// set, its turn alone (vx = vy = 0) if that is an in-place rotation of at least gate.rotate_min_wz_radps that the
/// rotation check allows; otherwise zero. Invalid flags give zero for any motion. `blocked`, if given, receives
/// motion_blocked(cmd, flags, gate). O(1).
Twist2 permitted_motion(const Twist2& cmd, const ObstacleFlags& flags, const MotionGateParams& gate, bool keep_turn,
                        bool* blocked = nullptr);

/// Pose-deviation thresholds (seed 004 Table 3 plus the push test).
struct DeviationParams {
  /// Seed check_distance_error_tolerance: the robot may be at most this far from the dock during alignment (m).
  Real check_distance_error_tolerance_m = static_cast<Real>(2.0);
  /// When the task started farther than the tolerance, the robot may get this much farther than at the start (m).
  Real distance_growth_margin_m = static_cast<Real>(0.3);
  /// The dock seen by the lidar may lie at most this far from where odometry expects it (a push moves it) (m).
  Real push_distance_tolerance_m = static_cast<Real>(0.3);
  /// Seed check_angle_error_tolerance (30°): the dock's yaw seen by the lidar may differ at most this much from
  /// where odometry expects it (the robot turned without its wheels seeing it) (rad).
  Real check_angle_error_tolerance_rad = deg_to_rad(static_cast<Real>(30));
  /// Consecutive failing detections that raise the fault, each within the push tolerances of the previous one
  /// (mapped into the odometry frame). A pushed robot's detections all agree with each other; a single wrong
  /// detection (clutter taken for the dock) does not repeat at the same place. 1: fault on the first. Keep it below
  /// DockFilterParams::reinit_after, or the filter adopts the pushed pose before the test fires. One detection
  /// suffices when the room moved as it implies (SceneVerdict::kMoved).
  std::uint8_t confirm_detections = 2;
};

/// Pose deviation test on one fresh detection. `detected_in_odom`: the detection mapped through the odometry pose at
/// its scan time; `expected_in_odom`: the dock where the filter (odometry) expects it; `distance_m`: robot-to-dock
/// distance from the detection; `start_distance_m`: the distance when the task acquired the dock.
/// Returns kDistanceDeviation (178), kAngleDeviation (179) or kNone; 178 wins when both apply. O(1).
FaultCode check_pose_deviation(const Pose2& detected_in_odom, const Pose2& expected_in_odom, Real distance_m,
                               Real start_distance_m, const DeviationParams& params);

}  // namespace dockcore
