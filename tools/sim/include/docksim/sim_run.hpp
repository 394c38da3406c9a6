#pragma once
// Closed-loop simulation of one docking: docksim::Chassis (5 ms steps) + the lidar simulator (at the model's rate,
// delivered after a scan latency) + the camera simulation + the Dockcore facade (estimator, filter, task manager)
// driving one of the four controllers at 50 Hz, its twist saturated and acceleration-limited by dockcore's
// kinematics and sent as wheel speeds. Scenario events are applied at their times. Records the trajectory, a timeline
// of task states, controller phases, faults, events and contact changes, and the outcome metrics.
// Host-side. Deterministic: the same scenario, controller and seed give bit-identical results (every random draw
// comes from docksim::Rng streams derived from the seed).
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "dockcore/control/kinematics.hpp"
#include "dockcore/dockcore.hpp"
#include "dockcore/geometry.hpp"
#include "dockcore/task/task_manager.hpp"
#include "docksim/camera_sim.hpp"
#include "docksim/chassis.hpp"
#include "docksim/scenario.hpp"

namespace docksim {

/// A start pose, in the envelope's terms and as poses.
struct StartPose {
  double distance_m = 0;   ///< Robot centre to dock origin.
  double bearing_rad = 0;  ///< Of the robot centre in the dock frame (0 = straight out of the face).
  double heading_rad = 0;  ///< Heading offset from facing the dock (rear facing it for rear pads).
  Pose2 robot_in_dock{};
  Pose2 robot_world{};
};

/// The start pose for given envelope coordinates. O(1).
StartPose start_from(const Scenario& sc, double distance_m, double bearing_rad, double heading_rad);
/// A start pose drawn uniformly from the scenario's envelope with an Rng derived from `seed`. O(1).
StartPose draw_start(const Scenario& sc, std::uint64_t seed);
/// Seed of Monte Carlo trial `index` for base seed `base` (splitmix64 mixing): the same for every controller.
std::uint64_t trial_seed(std::uint64_t base, std::uint64_t index);

/// dockcore's drive geometry (kinematics.hpp) for the simulated chassis' geometry. O(1).
dockcore::DriveGeometry core_drive_geometry(const DriveGeometry& g);
/// The core's configuration for a scenario: estimator, task, footprint, lidar mount, drive geometry and limits,
/// watchdog, and the control period (the simulator ticks every 4 chassis steps). The camera's tag fusion is the
/// caller's (tag_fusion_params). With odometry from wheel speeds the drive geometry is the one the robot believes
/// (the chassis's radius and base errors applied), as a user would configure a robot whose dimensions are off. O(1).
dockcore::DockcoreConfig core_config(const Scenario& sc);
/// Seed 000's detector for a scenario whose dock picks it (sc.detector kBreakpoint), attached to `core`; nullptr
/// (nothing attached) otherwise, so its ~37 KiB of buffers exist only then. Keep the result alive as long as `core`
/// and attach before DockcoreBase::configure. O(1) plus one allocation.
std::unique_ptr<dockcore::BreakpointDetector> attach_detector(const Scenario& sc, dockcore::DockcoreBase& core);
/// Hands the chassis's feedback at `now_us` to the core as the scenario's odometry source says: the chassis
/// firmware's pose and the measured twist, or the measured wheel speeds (each scaled by its own believed radius
/// over the common one, so a left/right radius difference reaches the core's odometry). O(1).
void feed_chassis(dockcore::DockcoreBase& core, const Scenario& sc, const ChassisState& reported, std::uint64_t now_us);
/// The body twist of the chassis's reported (measured) wheel speeds under dockcore's drive geometry `g`: what a host
/// hands the core with the chassis's odometry pose (DockcoreBase::on_odometry). O(1).
dockcore::Twist2 measured_twist(const dockcore::DriveGeometry& g, const ChassisState& reported);
/// The camera simulator's parameters for a scenario's camera (rate, latency, noise, dropouts, depth range). O(1).
CameraSimParams camera_sim_params(const Scenario& sc);
/// The tag fusion's parameters for a scenario's camera and dock tag: [camera.fusion], the camera's mount (level, at
/// `robot.camera.z_m`), focal length, tag size and the tag's place on the dock (the camera target, at `dock.tag.z_m`
/// or the camera's height). What the run fuses with and where the rendered camera draws the tag. O(1).
dockcore::TagFusionParams tag_fusion_params(const Scenario& sc);
/// The seed of one random stream of a run: splitmix64 of `seed ^ salt`, as run_docking derives its chassis, lidar and
/// camera streams (salts 0x43484153 "CHAS", 0x4C494441 "LIDA", 0x43414d "CAM"). O(1).
std::uint64_t seed_stream(std::uint64_t seed, std::uint64_t salt);

enum class TimelineKind : std::uint8_t { kState, kPhase, kFault, kEvent, kContact, kHost };
const char* to_string(TimelineKind k);

struct TimelineEntry {
  double t_s = 0;
  TimelineKind kind = TimelineKind::kState;
  int code = 0;      ///< State code, phase code, fault code, event kind, 1/0 for contact/charging changes.
  std::string text;  ///< Human-readable ("ALIGN", "fault 178 distance_deviation", ...).
};

struct TrajectorySample {
  double t_s = 0;
  Pose2 pose{};            ///< True robot pose, world.
  double vx_cmd_mps = 0;   ///< Commanded forward speed after kinematics.
  std::uint8_t state = 0;  ///< Task state code.
};

/// The outcome of one run.
struct SimOutcome {
  bool charging_confirmed = false;                                       ///< The task manager reached FINISH_TASKING.
  double time_to_charging_s = std::numeric_limits<double>::quiet_NaN();  ///< From the first dock command.
  /// Pads at the end (at charging confirmation when it happened): lateral = pad y in the dock frame, longitudinal =
  /// pad x in the dock frame (negative = pressed past the contact plane), yaw = pad heading error. Ground truth.
  double lateral_m = 0, longitudinal_m = 0, yaw_rad = 0;
  double path_length_m = 0;         ///< Of the robot centre, true motion.
  int reversals = 0;                ///< Sign changes of the commanded vx (|vx| > 1 mm/s).
  int inplace_turns_45 = 0;         ///< Stretches of turning with |v| < 1 cm/s whose cumulative |yaw| exceeded 45°.
  double max_inplace_turn_rad = 0;  ///< Largest such stretch.
  /// Smallest distance between the robot outline and any obstacle (world objects and obstacle events; the dock and
  /// its wall are not obstacles). +inf when there is none.
  double min_clearance_m = std::numeric_limits<double>::infinity();
  std::map<int, int> faults;  ///< Fault code -> times raised.
  dockcore::TaskState final_state = dockcore::TaskState::kNotTasking;
  bool timed_out = false;  ///< max_time_s reached without charging or a final fault.
  int retries = 0;         ///< Charging retries used (task manager).
  double end_time_s = 0;
  /// seed003 only: when its own success test (phase SEED_SUCCESS) first held, from the first dock command, and the
  /// true camera-to-target errors then: depth along the optical axis minus goal_z_m, and lateral offset (positive =
  /// target to the right). NaN when it never held. This is what seed 003's published table measures.
  double seed_success_t_s = std::numeric_limits<double>::quiet_NaN();
  double seed_success_z_err_m = std::numeric_limits<double>::quiet_NaN();
  double seed_success_x_m = std::numeric_limits<double>::quiet_NaN();
  bool camera_rendered = false;  ///< The camera rendered frames through the tag detector (robot.camera.render).
  /// Camera frames delivered and those that carried the target; tag poses fused into the dock filter / refused by
  /// it (Dockcore::on_tag; rendered camera only). All 0 without a camera.
  std::uint64_t camera_frames = 0;
  std::uint64_t camera_detections = 0;
  std::uint64_t tags_fused = 0;
  std::uint64_t tags_refused = 0;
  /// The core's verdict on the lidar's intensity at the end (Dockcore::intensity()), and its judged and flat scans.
  dockcore::IntensityVerdict intensity = dockcore::IntensityVerdict::kUnknown;
  std::uint32_t intensity_scans_judged = 0;
  std::uint32_t intensity_scans_flat = 0;
  /// The dock estimator's counters at the end (scans, found, candidates refused by reason): why a dock was or was
  /// not taken.
  dockcore::EstimatorCounters detector{};
  /// The task manager's mount calibration at the end: swings ended, the last one's result, and the lidar mount in
  /// use (the configured one moved by the swings that measured; TaskParams::calibrate_mount).
  std::uint32_t calibrations = 0;
  dockcore::MountCalibrationResult last_calibration{};
  dockcore::Pose2 lidar_mount_in_use{};
};

struct SimRun {
  std::string controller;
  std::uint64_t seed = 0;
  StartPose start{};
  SimOutcome outcome{};
  std::vector<TimelineEntry> timeline;
  std::vector<TrajectorySample> trajectory;
  Pose2 final_pose{};                           ///< True pose at the end.
  std::vector<dockcore::Vec2> last_scan_world;  ///< Valid returns of the last simulated scan, world coordinates.
};

struct SimOptions {
  bool record_trajectory = true;
  double trajectory_period_s = 0.05;
  bool keep_last_scan = true;
  const StartPose* start = nullptr;  ///< Fixed start instead of draw_start(seed).
  /// Makes the run's rendered camera for a scenario whose camera renders (robot.camera.render); dock-sim sets it
  /// when it is built with the tag detector. Without it such a scenario is refused (ScenarioError).
  std::function<std::unique_ptr<FrameCamera>(const Scenario&)> make_frame_camera;
};

/// Runs one docking of `sc` with `controller` (one of controller_names()). Throws ScenarioError for an unknown
/// controller. Cost: O(duration / 5 ms) chassis steps plus the lidar and estimator per scan.
SimRun run_docking(const Scenario& sc, const std::string& controller, std::uint64_t seed,
                   const SimOptions& options = SimOptions{});

/// The chassis's dock for a scenario: pose, face width, a dead charger, what holds the pads short. O(1).
DockPlacement dock_placement(const Scenario& sc);
/// The robot's outline in the body frame (rectangle corners or a 24-gon). O(1).
std::vector<dockcore::Vec2> footprint_outline(const ChassisParams& chassis);

/// Where an `obstacle` event's disc appears when the robot stands at `robot_pose` (world): at the event's place, or,
/// when that would put it within `clearance_m` of the robot's outline (0: touching or inside it), further away until
/// it is not (at most 5 m): a walking one further back on its way in 5 cm steps, a standing one further from the
/// robot's centre in 1 cm steps. Someone entering does not appear inside the robot. O(outline) per step.
dockcore::Vec2 obstacle_entry(const Scenario& sc, const ScenarioEvent& ev, const dockcore::Pose2& robot_pose,
                              double clearance_m);

/// The wall behind the dock (Scenario::wall, wall_gap_m, wall_half_length_m) as a world segment a-b, glass or not;
/// false when the dock is free-standing. O(vertices).
bool dock_wall(const Scenario& sc, dockcore::Vec2* a, dockcore::Vec2* b);

/// The static world the lidar sees: dock, wall (unless glass), polylines, boxes and circles (furniture included; no
/// event obstacles). O(objects).
World scenario_world(const Scenario& sc, bool with_dock = true);

}  // namespace docksim
