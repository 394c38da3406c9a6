#pragma once
// Scene generation for benchmarks and tests: a dock against a wall plus random clutter, dock-less clutter scenes
// (with optional dock look-alikes) for false-positive tests, and a helper that places a dock relative to the robot.
// Host-side; deterministic for a given Rng seed (only docksim::Rng is used).
#include <string>
#include <vector>

#include "dockcore/geometry.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "docksim/lidar_sim.hpp"
#include "docksim/rng.hpp"

namespace docksim {

/// What a generated object is; recorded so tests and benchmark reports can say what a detector tripped on.
enum class ObjectKind {
  kDock,
  kWall,        ///< The wall the dock is mounted on, or a room wall.
  kBox,         ///< Box 0.15-0.6 m a side, random yaw.
  kTableLegs,   ///< Four circular legs (r 0.02-0.04 m) at the corners of a 0.5-1.2 m x 0.4-0.8 m rectangle.
  kPersonLegs,  ///< Two circles r 0.05-0.07 m, 0.1-0.3 m apart.
  kCorner,      ///< Two wall pieces 0.3-1.5 m long meeting at 90°.
  kWallPiece,   ///< One straight wall piece 0.5-2 m long.
  // Dock look-alikes (only when asked for, see look_alikes), turned to face the lidar within +-45°:
  kLookAlikeBoard,   ///< A flat board 0.30 m wide, 0.02 m thick.
  kLookAlikeCorner,  ///< A concave 90° V of two walls, arms 0.15-0.6 m (0.212 m arms match the v-marker exactly).
  kLookAlikeBox,     ///< A box 0.30 m wide, 0.10-0.30 m deep.
};

/// Name of an ObjectKind ("box", "table-legs", ...). Never null.
const char* to_string(ObjectKind k);

/// One placed object: its kind and a bounding circle in world coordinates (every segment lies inside it).
struct SceneObject {
  ObjectKind kind = ObjectKind::kBox;
  Vec2 centre_m = Vec2::Zero();
  double radius_m = 0;
};

/// Clutter shared by both generators.
struct ClutterSpec {
  /// 0 none, 1 light (3 objects), 2 medium (6), 3 heavy (12); above 3, 4*level objects. Kinds are drawn from box,
  /// table legs, person legs, corner and wall piece.
  int clutter_level = 1;
  /// Number of dock look-alikes (board / 90° corner / 0.30 m box, chosen in turn) added on top of the clutter.
  int look_alikes = 0;
  /// Objects are placed with their bounding circle centre within this distance of the lidar.
  double radius_m = 4.0;
  /// ... and no closer to the lidar than this (plus their own radius): the robot's body is there.
  double lidar_clearance_m = 0.30;
  /// Gap kept between an object's bounding circle and the dock / the dock's line-of-sight region.
  double margin_m = 0.05;
  double reflectivity_min = 0.2;  ///< Clutter reflectivity is uniform in [min, max].
  double reflectivity_max = 0.9;
  /// Placement attempts per object before it is skipped (a crowded scene just gets fewer objects).
  int max_attempts = 200;
};

/// A docking scene.
struct SceneSpec {
  dockcore::DockProfile profile;  ///< Dock outline (dock frame).
  Pose2 dock_pose_in_world;       ///< Dock frame in world.
  Pose2 lidar_pose_in_world;      ///< Where the robot's lidar will be; clutter keeps this and its view of the dock free.
  bool with_dock = true;          ///< false: the same scene without the dock (the wall stays), for negatives.
  int clutter_level = 1;          ///< See ClutterSpec::clutter_level.
  int look_alikes = 0;            ///< See ClutterSpec::look_alikes.
  bool with_wall = true;          ///< The wall behind the dock: flush with the dock's minimum x, dock frame.
  double wall_half_length_m = 3.0;///< The wall spans y in [-this, +this] in the dock frame.
  double dock_reflectivity = 0.8;
  double wall_reflectivity = 0.5;
  ClutterSpec clutter;            ///< Everything else about clutter; its level/look_alikes are overridden by the above.
};

/// Builds the scene: the dock (World::add_dock), the wall (one two-sided segment at x = min vertex x of the profile,
/// dock frame, from y = -wall_half_length to +wall_half_length), then clutter and look-alikes drawn from rng and
/// placed by rejection so that each object's bounding circle (plus margin)
///  - does not overlap the dock's bounding box (dock frame),
///  - does not touch the line-of-sight region: the convex hull of the lidar position and the dock's vertices,
///  - lies in front of the wall (dock-frame x beyond the wall by its radius + margin) when with_wall,
///  - is at least lidar_clearance_m from the lidar.
/// So every ray from the lidar to any point of the dock's outline meets nothing but the dock. Segments are appended
/// in this order: dock, wall, objects. `objects`, when given, receives what was placed (dock and wall included).
/// Cost O(objects * attempts).
World build_scene(const SceneSpec& spec, Rng& rng, std::vector<SceneObject>* objects = nullptr);

/// A scene with no dock, for false-positive tests.
struct ClutterSceneSpec {
  Pose2 lidar_pose_in_world;
  ClutterSpec clutter;  ///< Level, look-alikes (the "mirror-image clutter" of a dock), placement.
  /// Adds a rectangular room around the lidar, half sizes uniform in [room_half_min_m, room_half_max_m] per axis,
  /// centre offset so the lidar stays at least 0.5 m inside; clutter stays inside the room.
  bool with_room = true;
  double room_half_min_m = 2.0;
  double room_half_max_m = 5.0;
  double wall_reflectivity = 0.5;
};

/// Builds a dock-less scene as described by ClutterSceneSpec (objects never contain the lidar). Cost as build_scene.
World build_clutter_scene(const ClutterSceneSpec& spec, Rng& rng, std::vector<SceneObject>* objects = nullptr);

/// Ground-truth dock pose in the lidar frame for a dock whose origin lies `distance_m` from the lidar at bearing
/// `bearing_rad` (lidar frame, CCW from the lidar's +x), rotated by `dock_yaw_rad` from facing the lidar head-on:
/// 0 means the dock's +x axis points straight back at the lidar; positive turns the dock counter-clockwise.
/// Result: {distance*cos(bearing), distance*sin(bearing), wrap(bearing + pi + dock_yaw)}. O(1).
Pose2 dock_pose_from_lidar(double distance_m, double bearing_rad, double dock_yaw_rad);

/// The same placed in the world: lidar_pose_in_world ∘ dock_pose_from_lidar(...). O(1).
Pose2 dock_pose_in_world_from_lidar(const Pose2& lidar_pose_in_world, double distance_m, double bearing_rad,
                                    double dock_yaw_rad);

/// Points of the dock's outline in world coordinates, `per_segment` evenly spaced interior points per profile
/// segment (endpoints excluded, they sit on corners shared with other surfaces). For visibility checks in tests.
std::vector<Vec2> dock_outline_points(const dockcore::DockProfile& profile, const Pose2& dock_pose_in_world,
                                      int per_segment = 5);

/// Convex hull of `points`, counter-clockwise, without collinear points. O(n log n).
std::vector<Vec2> convex_hull(std::vector<Vec2> points);

/// Distance from p to the convex counter-clockwise polygon `poly` (as convex_hull returns); 0 inside, 1e300 for an
/// empty polygon. O(vertices).
double distance_to_convex(const Vec2& p, const std::vector<Vec2>& poly);

}  // namespace docksim
