#pragma once
// Docking scenarios: one TOML file describing the robot (drive, limits, footprint, lidar and camera mounts, chassis
// imperfections), the lidar model, the dock and the world, the start-pose envelope, a timeline of disturbances and the
// controller with its parameters. docs/scenarios.md documents every key with its unit and default.
//
// Errors (unknown key, wrong type, value out of range, bad profile file, ...) are ScenarioError exceptions whose
// message starts with "<source>:<line>:<column>: " (1-based, the TOML source region of the offending key or value).
// Host-side (tools/): heap and exceptions are fine here.
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "dockcore/control/controllers.hpp"
#include "dockcore/control/kinematics.hpp"
#include "dockcore/control/safety.hpp"
#include "dockcore/control/wheel_deadband.hpp"
#include "dockcore/dockcore.hpp"
#include "dockcore/geometry.hpp"
#include "dockcore/perception/dock_pose_estimator.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "dockcore/perception/tag_measurement.hpp"
#include "dockcore/task/input_watch.hpp"
#include "dockcore/task/task_manager.hpp"
#include "docksim/chassis.hpp"
#include "docksim/lidar_sim.hpp"

namespace docksim {

/// A scenario could not be read. what() is complete and user-readable; inside a file it starts with
/// "<source>:<line>:<column>: ".
class ScenarioError : public std::runtime_error {
 public:
  ScenarioError(const std::string& message, int line = 0, int column = 0)
      : std::runtime_error(message), line_(line), column_(column) {}
  int line() const { return line_; }      ///< 1-based; 0 when not tied to a position.
  int column() const { return column_; }  ///< 1-based; 0 when not tied to a position.

 private:
  int line_;
  int column_;
};

/// Disturbances on the timeline ([[events]] type = ...).
enum class EventKind : std::uint8_t {
  kPush,                 ///< "push": true pose jumps by (dx, dy) world metres and dyaw; odometry does not see it.
  kOccludeDock,          ///< "occlude_dock": the dock is invisible to lidar and camera for duration_s.
  kObstacle,             ///< "obstacle": a disc (x, y, r) in the world for duration_s (<= 0: for good); with a
                         ///< velocity it walks (a passer-by) and waits while it would come near the robot.
  kLidarDropout,         ///< "lidar_dropout": no scans for duration_s.
  kChargingNeverStarts,  ///< "charging_never_starts": the charger delivers no current from t_s on.
  kChassisSilent,        ///< "chassis_silent": the chassis stops answering for duration_s.
  kHostStall,            ///< "host_stall": the control host (dockd and dockcore) does not run for duration_s: no scan
                         ///< is read, no tick runs, the motors keep the last command (up to their command timeout).
};

/// Stable TOML name of an event kind ("push", ...). Never null.
const char* to_string(EventKind k);

struct ScenarioEvent {
  /// When it happens, s of simulated time (the first dock command is sent on the first control tick after the first
  /// scan has been delivered: scan latency plus at most one tick, ~0.04 s with the defaults).
  double t_s = 0;
  EventKind kind = EventKind::kPush;
  double dx_m = 0, dy_m = 0, dyaw_rad = 0;  ///< push (world frame).
  double duration_s = 0;                    ///< occlude_dock, obstacle, lidar_dropout, chassis_silent, host_stall.
  double x_m = 0, y_m = 0, r_m = 0.1;       ///< obstacle: centre (world) and radius.
  /// obstacle: walking velocity, world m/s (0: it stands). A walking obstacle gives way: it stands while a step would
  /// bring it within kPasserGiveWayM of the robot, and duration_s counts its walking time only.
  double vx_mps = 0, vy_mps = 0;
  bool hold_last_command = false;           ///< chassis_silent: motors keep the last command (else they stop).
  /// in_state: t_s counts from the first control tick on which the task is in this state (the event never fires
  /// when the run never gets there); absent: from the start of the run. dock-sim run/montecarlo/certify only.
  bool after_state = false;
  dockcore::TaskState state = dockcore::TaskState::kNotTasking;
};

/// Simulated camera that sees one target point on the dock (seed 003's vision process).
struct CameraSpec {
  bool enabled = false;           ///< false: ControlInput::camera is never valid.
  dockcore::CameraModel model{};  ///< fx, cx, image width and mount (robot frame).
  double rate_hz = 20.0;          ///< Frames per second.
  double latency_s = 0.05;        ///< Image time to delivery.
  double sigma_px = 1.0;          ///< Gaussian pixel noise on u, 1 sigma.
  double dropout_prob = 0.0;      ///< Chance a frame has no detection.
  double min_depth_m = 0.05;      ///< Target closer than this along the optical axis: not seen (blind zone).
  double max_depth_m = 4.0;       ///< Farther: not seen.
  double v_px = 240.0;            ///< Row reported for the target (2D world: constant).
  dockcore::Vec2 target_in_dock = dockcore::Vec2::Zero();  ///< The target point, dock frame (default: contacts).
  // Rendered frames (render = true): each frame is a pinhole image of the dock's tag ([dock.tag]) at the camera's
  // true pose, run through the AprilTag detector dockd uses; the target is the detected tag's centre and, with
  // fuse_tags, the tag's pose goes into the dock filter (Dockcore::on_tag). sigma_px, dropout and the depth range
  // then play no part: the image noise and the detector decide.
  bool render = false;
  bool fuse_tags = true;  ///< Rendered: tag poses fused into the dock filter.
  double z_m = 0.2;       ///< Camera height above the floor; the camera is level.
  std::uint32_t height_px = 480;
  double cy_px = 239.5;   ///< Principal point row (fy = fx).
  double blur_px = 0.8;   ///< Gaussian blur σ of the optics.
  double noise_grey = 4;  ///< Gaussian pixel noise σ, grey levels.
  double exposure = 1;    ///< Gain on the scene's grey levels before the noise (saturates at white).
  double decimate = 2;    ///< The detector's quad_decimate.
};

/// The AprilTag on the dock ([dock.tag]), seen by a rendered camera and fused with the lidar.
struct DockTagSpec {
  int id = 3;
  std::string family = "tag36h11";
  double size_m = 0.08;  ///< Side of the tag's black square.
  /// Height of the tag's centre above the floor; NaN: the camera's height. Its x, y are the camera target's.
  double z_m = std::numeric_limits<double>::quiet_NaN();
};

/// Start poses are drawn uniformly from these ranges: the robot centre at `distance` from the dock origin at
/// `bearing` (dock frame, 0 = straight out of the face), heading = facing the dock origin (rear facing it for rear
/// pads) + `heading`.
struct StartEnvelope {
  double distance_min_m = 0.5, distance_max_m = 2.5;
  double bearing_min_rad = -dockcore::kPi / 4, bearing_max_rad = dockcore::kPi / 4;
  double heading_min_rad = -dockcore::kPi / 6, heading_max_rad = dockcore::kPi / 6;
};

/// Static world objects besides the dock and its wall (world coordinates).
struct WorldPolyline {
  std::vector<dockcore::Vec2> points;
  bool closed = false;
};
struct WorldBox {
  dockcore::Vec2 centre = dockcore::Vec2::Zero();
  double size_x_m = 0.3, size_y_m = 0.3, yaw_rad = 0;
};
struct WorldCircle {
  dockcore::Vec2 centre = dockcore::Vec2::Zero();
  double r_m = 0.1;
};

/// Furniture beside the dock ([[dock.furniture]]), placed in the dock frame. At load it is added to the world's boxes
/// and circles (so the lidar sees it and it counts for obstacle clearance).
enum class FurnitureKind : std::uint8_t {
  kBox,    ///< "box": a box depth_m (dock x) by width_m (dock y), sides parallel to the dock's axes.
  kBin,    ///< "bin": a round bin (a cylinder) of radius_m.
  kChair,  ///< "chair": four round legs of leg_radius_m at the corners of a seat_m square.
  kDock,   ///< "dock": another dock (profile, with its own reflectors), facing the same way, back planes aligned.
};

/// Stable TOML name of a furniture kind ("box", "bin", "chair"). Never null.
const char* to_string(FurnitureKind k);

struct DockFurniture {
  FurnitureKind kind = FurnitureKind::kBox;
  int side = 1;                 ///< +1: on the dock's left (+y), -1: on its right (-y).
  double gap_m = 0.3;           ///< Free space along the dock's y from the dock's outermost vertex on that side to the
                                ///< object's nearest point, m.
  double depth_m = 0.4;         ///< box: extent along the dock's x, m.
  double width_m = 0.4;         ///< box: extent along the dock's y, m.
  double radius_m = 0.15;       ///< bin, m.
  double seat_m = 0.45;         ///< chair: seat side, m (leg centres lie leg_radius_m inside its corners).
  double leg_radius_m = 0.015;  ///< chair, m.
  dockcore::DockProfile profile{};  ///< dock: its outline and reflectors (a built-in name or a profile file).
  /// Centre along the dock's x, m. Default (x_set false): the object's back stands kFurnitureWallClearanceM in front
  /// of the wall's face, or on the dock's back plane when there is no wall.
  bool x_set = false;
  double x_m = 0;
};

/// Default clearance between furniture and the wall behind it, m (furniture does not stand exactly on the wall line).
constexpr double kFurnitureWallClearanceM = 0.01;

/// How near a walking obstacle (a passer-by) comes to the robot's outline before it stands and lets the robot pass,
/// m: people keep about this much from a machine they see.
constexpr double kPasserGiveWayM = 0.15;

/// Host behaviour around the task manager.
struct HostSpec {
  int redock_after_fault = 0;    ///< Re-send the dock command this many times after a fault (a host retrying).
  double redock_delay_s = 1.0;   ///< Wait this long in FAULT before re-sending (cancel, then dock).
};

/// What the host hears from the chassis ([robot.odometry] source).
enum class OdometrySource : std::uint8_t {
  kChassis = 0,  ///< The chassis firmware integrates its encoders and reports the pose (DockcoreBase::on_odometry).
  kWheels = 1,   ///< Only the measured wheel speeds, integrated by the core as dockd does (DockcoreBase::on_wheels).
};

/// Everything one docking simulation needs.
struct Scenario {
  std::string name;    ///< Scenario name (default: the file name without .toml).
  std::string source;  ///< File it came from.
  std::uint64_t seed = 1;
  double max_time_s = 120.0;        ///< A run that has not ended by then is a timeout.
  double settle_after_end_s = 0.3;  ///< Keep simulating this long after charging is confirmed / a final fault.

  // Robot.
  ChassisParams chassis{};             ///< Drive geometry, motors, noise, footprint (pads), contacts, battery.
  OdometrySource odometry_source = OdometrySource::kChassis;
  dockcore::DriveLimits limits{};      ///< Kinematics saturation and acceleration limits.
  dockcore::FootprintParams safety{};  ///< Obstacle check (derived from the footprint plus check areas).
  Pose2 lidar_mount{};                 ///< Lidar in the robot frame, as configured (what dockcore is told).
  /// [robot.lidar] error_*: where the lidar really sits relative to lidar_mount (a calibration error dockcore is not
  /// told). The simulator casts rays from true_lidar_mount().
  Pose2 lidar_mount_error{};
  CameraSpec camera{};
  DockTagSpec dock_tag{};
  dockcore::TagFusionParams tag_fusion{};  ///< [camera.fusion]: the tag covariance model (the parameter table).
  dockcore::WatchdogParams watchdog{};     ///< [watchdog]: the core's input watch (the parameter table).
  dockcore::WheelDeadbandParams deadband{};  ///< [robot.deadband]: what dockcore knows and learns of the deadband.
  dockcore::IntensityCheckParams intensity{};  ///< [intensity]: the lidar intensity check (the parameter table).

  // Lidar.
  LidarModel lidar{};
  double scan_latency_s = 0.03;  ///< Scan time (stamp) to delivery to dockcore.

  // Dock and world. profile.mounting is what the detector is told ([dock.mounting], else the profile file's).
  dockcore::DockProfile profile{};
  std::string profile_name = "plate-v";
  Pose2 dock_pose{};  ///< Dock frame in the world.
  double dock_face_half_width_m = 0.15;
  bool dock_dead = false;        ///< [dock] dead: the contacts close but the charger never delivers current.
  double dock_stop_short_m = 0;  ///< [dock] stop_short_m: the pads are held this far before the contacts, m.
  /// The world behind the dock (what the lidar sees, whatever the detector is told: that is profile.mounting):
  bool wall = true;         ///< A wall behind the dock, parallel to its face; false: free-standing.
  double wall_gap_m = 0;    ///< The wall's face lies this far behind the profile's minimum x, m, [0, 0.5].
  bool wall_glass = false;  ///< Glass: lidar beams pass through it (absent from the lidar's world).
  double wall_half_length_m = 2.0;
  std::vector<DockFurniture> furniture;  ///< Beside the dock; also expanded into boxes / circles / other_docks below.
  /// Docks other than the one docked to (furniture of kind "dock"), in the world: the lidar sees them (tape and all)
  /// and they count as obstacles.
  struct OtherDock {
    dockcore::DockProfile profile;
    Pose2 pose;
  };
  std::vector<OtherDock> other_docks;
  std::vector<WorldPolyline> polylines;
  std::vector<WorldBox> boxes;
  std::vector<WorldCircle> circles;

  StartEnvelope start{};
  std::vector<ScenarioEvent> events;  ///< Sorted by t_s (stable).

  // Dockcore.
  /// The dock's detector ([dock] detector; the parameter table). Checked against the profile when parsed.
  dockcore::DockDetector detector = dockcore::DockDetector::kEstimator;
  dockcore::EstimatorParams estimator{};
  dockcore::TaskParams task{};
  HostSpec host{};

  // Controller.
  std::string controller = "smooth";
  dockcore::Seed000Params seed000{};
  dockcore::Seed004Params seed004{};
  dockcore::Seed003Params seed003{};
  dockcore::SmoothParams smooth{};

  /// Where the lidar really sits in the robot frame: lidar_mount ∘ lidar_mount_error. O(1).
  Pose2 true_lidar_mount() const { return lidar_mount.compose(lidar_mount_error); }
};

/// Controller names in table order: seed000, seed004, seed003, smooth.
const std::vector<std::string>& controller_names();
/// True when `name` is one of controller_names().
bool is_controller_name(const std::string& name);

/// Parses scenario TOML held in `text`; `source_name` names it in messages and resolves relative profile paths
/// (relative to its directory). Throws ScenarioError. O(text size).
Scenario parse_scenario_toml(const std::string& text, const std::string& source_name);
/// Reads and parses a scenario file. Throws ScenarioError (also when it cannot be read).
Scenario load_scenario_file(const std::string& path);

/// The pose of the pads' docked robot centre etc. are derived from the footprint: distance from the robot centre to
/// the pads along the docking direction, m (what controllers call pad_reach_m). O(1).
double pad_reach_of(const ChassisParams& chassis);

}  // namespace docksim
