#pragma once
// World generator for measuring how a dock detector generalises: random docks (the built-ins and random plausible
// outlines), mountings, clutter next to the dock, lidar models with random noise, lidar mounts with an unknown
// calibration error, and robot poses, all drawn from the broad documented distributions below. Evaluation only:
// nothing here may be used to tune a detector against a fixed scene.
//
// Every scene is a pure function of (seed, stream, index): draw() seeds its own Rng from them, so scenes do not
// depend on the order they are drawn in or on how many threads draw them.
//
// Frames. World = the robot's odometry frame; the robot starts at the world origin facing +x. The lidar is mounted
// at `lidar_mount` in the robot frame (known to the detector) but really sits at lidar_mount ∘ calibration_error
// (not known). Distance and bearing are those of the dock's origin seen from the true lidar position, the bearing
// measured from the robot's heading; dock yaw is the angle between the dock's +x axis and the direction from the dock
// to the lidar (0 = facing the lidar head-on, positive = turned counter-clockwise).
//
// Distributions (defaults of WorldGenParams; each draw is independent and uniform unless said otherwise):
//  - profile: with probability builtin_share one of the built-ins (breakpoint, v-marker, plate-v; equally likely),
//    otherwise one of `random_profiles` outlines drawn once per seed by random_profile() (equally likely);
//  - mounting class (equally likely): flush (wall at the back plane), gap (wall 0-10 cm behind it), skirting (see
//    MountClass::kSkirting), glass (no visible wall), free-standing, corner (back wall flush or 0-10 cm behind, second
//    wall 0-0.5 m beside the dock's side); glass and free-standing scenes get a room wall 0.6-3 m behind the dock with
//    probability 1/2;
//  - clutter next to the dock (equally likely): none, boxes, chair legs, table legs, a bin, a person's legs, mixed
//    (see ClutterClass); clutter never enters the line of sight from any lidar position of the scene to the dock;
//  - lidar (equally likely): ld06 (LD06/LD19), rplidar-a1, rplidar-a2, industrial (lidar_sim.hpp), with range noise
//    σ = sqrt(σ_c² + (σ_p·r)²): σ_c uniform in 5-10 mm for half the scenes and 10-20 mm for the other half, σ_p
//    0-0.5 % of range, dropouts 0-10 %, mixed pixels at depth edges with probability 0-1 per straddling beam;
//  - lidar mount on the robot: x ±0.25 m, y ±0.15 m, yaw ±15°; calibration error x, y ±1 cm, yaw ±1°;
//  - pose: distance 0.3-2.5 m, bearing ±60°, dock yaw ±45°;
//  - reflectivity: dock 0.5-0.95, walls 0.2-0.9, clutter 0.1-0.9 (intensity only).
// Streams (ScenePath): kSingle is one scan from the start pose; kConfirm adds two more poses, each 1-3 cm further
// forward, ±1 cm sideways and ±1° turned from the previous (a robot creeping while it confirms a detection); kApproach
// starts 0.45-1.0 m from the dock (bearing ±45°, dock yaw ±30°) and drives towards it for 10 steps of 0.1 s at
// 0.05-0.15 m/s, turning ±0.1 rad/s.
// Dock-less scenes (with_dock = false) are drawn exactly like docking scenes, then the dock is left out and a
// look-alike (LookAlike) put where it stood.
//
// Reflector mode (WorldGenParams::reflectors; off by default, and off every draw is bit for bit what it was without
// the mode). Everything above still holds, the lidars being whatever WorldGenParams::lidars lists (the reflector
// benchmark lists `ld06` only), and:
//  - tape code: the profile's longest segment, if >= 0.18 m (or >= 3 x code_region_m when that is set), gets three
//    equal regions (each a third of it, or code_region_m wide centred on it) and a pattern drawn uniformly among the
//    6 with at least one stripe and one gap (bit k = region k from the segment's first vertex taped; each taped region
//    is a stripe of its own). The profile the detector is told carries the stripes; the dock in the world is taped
//    the same. A profile without such a segment gets no code (code_pattern 0);
//  - reflective clutter after the other clutter: 0-3 objects (uniform), each equally likely one of: a safety vest (a
//    person's torso, a 16-sided circle r 0.10-0.20 m, 0.3-1.5 m in front of the dock's face and up to 1.5 m beside
//    it, with 1-2 retro bands: arcs of 40-120° of its circumference, centred anywhere); a sign (a board 2 cm thick,
//    0.2-0.6 m wide, on the wall or up to 10 cm in front of it (level with the dock's back where there is no wall),
//    yaw ±5°, 0.2-2.0 m beside the dock, taped over all its face (probability 1/2) or over 20-100 % of it at a random
//    offset); chrome legs (a stool or chair: four 16-sided legs r 1.0-2.5 cm on a 0.35-0.50 m square, 0.2-2.0 m
//    beside the dock and 0-0.8 m out from the wall, retro with an incidence cutoff of 10-15°,
//    Segment::retro_cutoff_rad: bright only where a leg's facet faces the lidar); a glass pane (0.3-1.0 m, placed like
//    a sign: no return, so only its place is taken). As other clutter, never in the line of sight to the dock;
//  - dock-less scenes draw among all LookAlike kinds, the three tape ones included: the same shape with another of
//    the 5 other patterns, the same shape untaped, and a taped board (a 2 cm board as kBoard, its face in three equal
//    regions with one of the 6 patterns);
//  - a back wall leaves out where a segment of the dock (or of a look-alike of its shape) lies in the wall's plane, so
//    the tape on a face flush with the wall is what the rays meet.
// Host-side: std::vector and std::string are used freely.
#include <cstdint>
#include <string>
#include <vector>

#include "dockcore/geometry.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "docksim/lidar_sim.hpp"
#include "docksim/rng.hpp"

namespace docksim {

/// How the dock is installed in the generated world.
enum class MountClass : std::uint8_t {
  kFlush,  ///< A wall flush with the dock's back plane (the profile's smallest x).
  kGap,    ///< A wall 0-10 cm (uniform, above 0) behind the back plane.
  /// Flush against the wall, with a skirting board along the wall's base on both sides. The lidar's scan plane is
  /// taken to be at skirting height, so it sees the board: a ledge 1-2 cm deep standing out of the wall, ending 0-2 cm
  /// from the dock's sides (the board is cut away where the dock stands). In the scan the wall beside the dock is
  /// 1-2 cm in front of the dock's back plane, with a short step where each board ends.
  kSkirting,
  kGlass,         ///< Against a glass wall: the lidar sees through it (no segment), maybe a room wall far behind.
  kFreeStanding,  ///< Open space behind the dock, maybe a room wall far behind.
  kCorner,        ///< A back wall (flush, or a gap 0-10 cm) and a second wall at right angles beside the dock.
  kCount,
};

/// Clutter placed next to the dock.
enum class ClutterClass : std::uint8_t {
  kNone,
  kBoxes,       ///< 1-2 boxes 0.2-0.6 m a side, 0.2-1 m beside the dock, against the wall when there is one.
  kChairLegs,   ///< 1-2 chairs: four legs r 1-1.5 cm at the corners of a 0.40-0.50 m square, 0.2-1 m beside it.
  kTableLegs,   ///< A table: four legs r 2-3.5 cm at the corners of 0.6-1.4 x 0.4-0.8 m, 0.2-1 m beside it.
  kBin,         ///< A round (r 0.12-0.20 m) or square (0.25-0.35 m) bin 0.2-1 m beside the dock.
  kPersonLegs,  ///< Two legs r 5-7 cm, 10-30 cm apart, 0.3-1.0 m in front of the dock face, beside the line of sight.
  kMixed,       ///< 2-4 objects, each of a kind above drawn in turn.
  kCount,
};

/// What stands where the dock would in a dock-less scene.
enum class LookAlike : std::uint8_t {
  kNothing,    ///< Just the mounting and the clutter.
  kBoard,      ///< A 2 cm board, its back at the dock's back plane.
  kBox,        ///< A box filling the dock's bounding box.
  kNotch,      ///< A 90° V notch (two boards) opening towards the lidar, apex at the back plane.
  kOtherDock,  ///< Another profile (built-in or random).
  // Reflector mode only (WorldGenParams::reflectors):
  kOtherCode,   ///< The dock's own shape taped with another code pattern (a dock of the fleet with another id).
  kUntaped,     ///< The dock's own shape without tape.
  kTapedBoard,  ///< A board as kBoard whose face carries a 3-region stripe pattern.
  kCount,
};
/// Look-alikes drawn outside reflector mode: kNothing .. kOtherDock.
constexpr int kPlainLookAlikes = static_cast<int>(LookAlike::kOtherDock) + 1;

/// Reflective clutter (reflector mode), see the file comment.
enum class ReflectiveClass : std::uint8_t {
  kVest,        ///< A torso with 1-2 retro bands.
  kSign,        ///< A board on or near the wall, partly or wholly taped.
  kChromeLegs,  ///< Four chrome legs: retro within 10-15° of normal incidence.
  kGlassPane,   ///< No return.
  kCount,
};

/// Smallest segment a 3-region code is put on when the regions are a third of it, m.
constexpr double kCodeMinSegmentM = 0.18;
/// Code patterns: bit k set = region k taped. Valid codes have at least one stripe and one gap: 1..6.
constexpr int kCodePatternMin = 1, kCodePatternMax = 6;
/// For board, box and notch the width is 0.2-0.7 m but at least 20 % away from the configured dock's width, and the
/// other dock's width is too, so a look-alike is never an exact copy of the dock the detector is told about.

/// Names ("flush", "boxes", "board", ...). Never null.
const char* to_string(MountClass c);
const char* to_string(ClutterClass c);
const char* to_string(LookAlike c);
const char* to_string(ReflectiveClass c);

/// Which robot poses a scene is seen from (see the file comment).
enum class ScenePath : std::uint8_t { kSingle, kConfirm, kApproach };

/// The distributions. Defaults are those of the file comment.
struct WorldGenParams {
  double builtin_share = 0.5;  ///< Chance a scene uses a built-in profile rather than a random one.
  int random_profiles = 100;   ///< Size of the random-profile pool drawn once per seed.
  std::vector<std::string> lidars{"ld06", "rplidar-a1", "rplidar-a2", "industrial"};
  double distance_min_m = 0.3, distance_max_m = 2.5;
  double bearing_max_rad = 60.0 * dockcore::kPi / 180.0;
  double dock_yaw_max_rad = 45.0 * dockcore::kPi / 180.0;
  double mount_x_max_m = 0.25, mount_y_max_m = 0.15;
  double mount_yaw_max_rad = 15.0 * dockcore::kPi / 180.0;
  double calib_xy_max_m = 0.01;
  double calib_yaw_max_rad = 1.0 * dockcore::kPi / 180.0;
  double sigma_min_m = 0.005, sigma_split_m = 0.010, sigma_max_m = 0.020;  ///< σ_c: half below, half above split.
  double sigma_prop_max = 0.005;                                           ///< σ_p, per metre of range.
  double dropout_max = 0.10;
  double gap_max_m = 0.10;  ///< kGap and kCorner wall gap.
  /// Reflector mode (file comment): a tape code on the dock, reflective clutter, the tape look-alikes. Off: draws are
  /// exactly those without the mode.
  bool reflectors = false;
  /// Reflector mode: each code region's width, m (the longest segment must hold three); 0 = a third of the segment.
  double code_region_m = 0;
};

/// One object of a generated world, for reports and tests: what it is and a circle containing it.
struct GenObject {
  std::string kind;  ///< "dock", "wall", "skirting", "box", "chair-legs", "table-legs", "bin", "person-legs", ...
  Vec2 centre_m = Vec2::Zero();
  double radius_m = 0;
};

/// One generated scene: what was drawn (the factors), the truth, and the world.
struct GenScene {
  std::uint64_t index = 0;
  bool with_dock = true;
  // --- profile
  dockcore::DockProfile profile;  ///< The dock (mounting kUnknown); for dock-less scenes, the one the detector is told.
  bool builtin = false;
  int random_index = -1;  ///< Index into WorldGenerator::random_profiles(), or -1 for a built-in.
  /// The mounting a user who knows the installation writes into the profile: kWall with a gap range containing the
  /// true gap (flush 0-1 cm, skirting 0-2 cm, gap g: g ± 2 cm clipped at 0) for flush / gap / skirting / corner,
  /// kFreeStanding for glass and free-standing.
  dockcore::DockMounting told_mounting;
  // --- mounting
  MountClass mount = MountClass::kFlush;
  double wall_gap_m = 0;            ///< Back wall face behind the back plane (flush, gap, corner, skirting: 0).
  double skirting_depth_m = 0;      ///< kSkirting: how far the board stands out of the wall.
  double skirting_end_gap_m = 0;    ///< kSkirting: board end to the dock's side.
  int corner_side = 0;              ///< kCorner: +1 the second wall on the dock's +y side, -1 on its -y side.
  double corner_distance_m = 0;     ///< kCorner: dock side (its largest |y|) to the second wall.
  double back_wall_distance_m = 0;  ///< Glass / free-standing: room wall behind the back plane, 0 = none.
  // --- clutter
  ClutterClass clutter = ClutterClass::kNone;
  int clutter_wanted = 0;                      ///< Objects drawn.
  int clutter_placed = 0;                      ///< Of which placed (the rest found no free spot and were left out).
  LookAlike look_alike = LookAlike::kNothing;  ///< Dock-less scenes only.
  double dock_reflectivity = 0;                ///< The dock's (or the look-alike's) surface, 0..1.
  // --- reflector mode
  int code_pattern = 0;        ///< The dock's code (bit k = region k taped), 0 = none (mode off or no segment for it).
  int code_segment = -1;       ///< The taped segment, -1 = none.
  double code_region_m = 0;    ///< Width of each region, m.
  int look_alike_pattern = 0;  ///< kOtherCode, kTapedBoard: the look-alike's pattern.
  int reflective_wanted = 0;   ///< Reflective objects drawn.
  std::vector<ReflectiveClass> reflective;  ///< Of which placed.
  // --- lidar
  LidarModel lidar;  ///< With the drawn noise, dropouts and mixed pixels.
  // --- poses
  double distance_m = 0, bearing_rad = 0, dock_yaw_rad = 0;  ///< At the first robot pose.
  Pose2 lidar_mount;                                         ///< Known to the detector.
  Pose2 calibration_error;        ///< Not known: the lidar really sits at lidar_mount ∘ calibration_error.
  Pose2 dock_in_world;            ///< The dock (or its look-alike's place).
  std::vector<Pose2> robot_path;  ///< Robot poses in the world, the first at the origin.
  World world;
  std::vector<GenObject> objects;

  /// Where the lidar really is on the robot. O(1).
  Pose2 true_mount() const { return lidar_mount.compose(calibration_error); }
  /// True dock pose in the robot frame at robot_path[k]. O(1).
  Pose2 dock_in_robot(std::size_t k = 0) const;
  /// True dock pose in the true lidar frame at robot_path[k] (what the scan sees). O(1).
  Pose2 dock_in_sensor(std::size_t k = 0) const;
  /// True lidar pose in the world at robot_path[k]. O(1).
  Pose2 lidar_in_world(std::size_t k = 0) const;
  /// Range noise 1-σ at range r: sqrt(σ_c² + (σ_p·r)²). O(1).
  double sigma_at(double range_m) const;
};

/// Draws a random plausible dock outline: 2-8 vertices, 0.2-0.7 m wide, 4-20 cm deep; from -y to +y with y never
/// decreasing, so it is a simple polyline whose every segment faces +x (or ±y for a step). Each segment is either a
/// face (rising in y by >= 2 cm) or a step (constant y, >= 2 cm in x; never two steps in a row), and every interior
/// vertex lies >= 2 cm from the line through its neighbours, so every feature is at least 2 cm. The origin (the
/// contacts) is on the outline at y = 0, at the middle of the width (the front end of a step there). `name` is
/// copied (truncated to the profile's 23 characters). Deterministic for the Rng's state; O(attempts · vertices).
dockcore::DockProfile random_profile(Rng& rng, const char* name);

/// The profile's longest segment (index; its length in *length_m when not null); the first of equals. O(vertices).
std::size_t longest_segment(const dockcore::DockProfile& profile, double* length_m);

/// Tapes a 3-region code on `segment`: regions `region_m` wide centred on the segment, region k (k = 0 nearest the
/// segment's first vertex) a stripe of its own when bit k of `pattern` is set. Replaces any stripes the profile had.
/// False (stripes cleared) when the three regions do not fit on the segment or add_reflector refuses one. O(1).
bool add_code(dockcore::DockProfile* profile, std::size_t segment, double region_m, int pattern);

/// Draws scenes. Construct once per seed; draw() is const and thread-safe.
class WorldGenerator {
 public:
  /// Builds the random-profile pool ("random-000", "random-001", ...) from `seed`. O(pool size).
  WorldGenerator(const WorldGenParams& params, std::uint64_t seed);

  /// Scene `index` of the docking (with_dock) or dock-less stream, seen along `path`. Its Rng is seeded from
  /// (seed, with_dock, path, index) only. Throws std::invalid_argument for an unknown lidar name in the params.
  /// Cost O(clutter attempts + segments).
  GenScene draw(std::uint64_t index, bool with_dock, ScenePath path) const;

  const std::vector<dockcore::DockProfile>& random_profiles() const { return random_; }
  const WorldGenParams& params() const { return params_; }
  std::uint64_t seed() const { return seed_; }

 private:
  WorldGenParams params_;
  std::uint64_t seed_;
  std::vector<dockcore::DockProfile> builtin_;
  std::vector<dockcore::DockProfile> random_;
};

}  // namespace docksim
