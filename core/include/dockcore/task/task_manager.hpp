#pragma once
/// @file The docking task manager: host commands, detection search, alignment with any
/// DockingController, obstacle and pose-deviation safety, charging confirmation with retries, undocking, faults.
///
/// One tick (50 Hz in dockd) takes everything the robot knows now (TaskInput) and returns the body twist to command
/// plus the status for the host (TaskOutput). State codes (TaskState) and fault codes (FaultCode) are stable wire
/// numbers. The twist leaves through one function, emit(): it is zero unless the state is a moving state
/// (REACH_TASKING_POINT, ALIGN, RETRY, UNDOCKING), no stop condition holds (obstacle, target lost, invalid values),
/// and it is finite — so every exit path, fault and idle state commands zero by construction. State diagram and
/// parameters: docs/task-manager.md. Cost per tick: O(1) plus one obstacle check O(B · S) when the robot is to move.
/// No heap; holds a reference to the controller, which must outlive the task manager.

#include <cstdint>

#include "dockcore/control/controller.hpp"
#include "dockcore/control/safety.hpp"
#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "dockcore/perception/mount_calibration.hpp"
#include "dockcore/perception/scene_check.hpp"
#include "dockcore/task/faults.hpp"

namespace dockcore {

/// Task states. Values are wire codes; 0-4 are seed 004's AutoContainerState, 5+ are dockcore's.
enum class TaskState : std::uint8_t {
  kNotTasking = 0,        ///< Idle. Zero velocity, charge request off.
  kGetTaskingCmd = 1,     ///< Command accepted; one tick to reset the controller and timers.
  kReachTaskingPoint = 2, ///< Looking for the dock: wait, then swing in place within ±swing_amplitude.
  kAlign = 3,             ///< The controller drives to the contacts.
  kFinishTasking = 4,     ///< Docked and charging confirmed. Zero velocity; contacts watched.
  kWaitForCharge = 5,     ///< At the contacts, charge requested; waiting for contact + current.
  kRetry = 6,             ///< Backing off to the staging distance before another attempt (or the final fault).
  kUndocking = 7,         ///< Charge off, then backing off to the staging distance.
  kFault = 8,             ///< Stopped with a fault code. Cleared by cancel, dock or undock (on the contacts, or to
                          ///< finish an undocking the fault interrupted).
  kTestMode = 9,          ///< Recognition only: the dock estimate is reported, the robot never moves.
};

/// Stable name ("NOT_TASKING", ...). Never null. O(1).
const char* to_string(TaskState s);
/// The states in which the task may drive the robot: REACH_TASKING_POINT, ALIGN, RETRY, UNDOCKING. O(1).
bool is_moving_state(TaskState s);

/// Host command kinds (wire codes). Anything else is rejected as unknown.
enum class HostCommandType : std::uint8_t {
  kNone = 0,      ///< No command this tick.
  kDock = 1,      ///< Dock at dock_id.
  kCancel = 2,    ///< Stop whatever runs; clears a fault.
  kUndock = 3,    ///< Leave the dock.
  kTestMode = 4,  ///< Recognition only, on dock_id (reported in the status like a docking's).
};

/// A host command, delivered once (edge) on the tick it arrives.
struct HostCommand {
  HostCommandType type = HostCommandType::kNone;
  std::uint16_t dock_id = 0;
};

/// What became of the command given on this tick.
enum class CommandResult : std::uint8_t {
  kNone = 0,              ///< No command this tick.
  kAccepted = 1,
  kAlreadyDocked = 2,     ///< Dock while docked/charging: no motion; charging is (re)confirmed.
  kRejectedUnknown = 3,   ///< Unknown command code.
  kRejectedDockId = 4,    ///< Dock/test dock id not accepted (>= 32 or not in accepted_dock_ids).
  kRejectedNotDocked = 5, ///< Undock while not on the contacts (and not resuming an interrupted undocking).
  kRejectedBusy = 6,      ///< Dock/test while a task runs, or undock while docking: cancel first.
};

/// Stable name. Never null. O(1).
const char* to_string(CommandResult r);

/// How the last task ended (persistent until the next one).
enum class TaskResult : std::uint8_t {
  kNone = 0,
  kDocked = 1,    ///< Charging confirmed.
  kUndocked = 2,  ///< Backed off to the staging distance.
  kCancelled = 3,
  kFaulted = 4,
};

/// Dock ids a task can run for: 0..31, one bit each in TaskParams::accepted_dock_ids.
constexpr std::uint16_t kDockIds = 32;

/// Task manager parameters. Times in seconds, distances in metres, angles in radians.
struct TaskParams {
  // Detection search (REACH_TASKING_POINT).
  Real detect_wait_s = static_cast<Real>(1.0);        ///< Stand still this long for a detection before swinging.
  Real swing_amplitude_rad = deg_to_rad(static_cast<Real>(20));  ///< Swing to ±this about the start heading.
  Real swing_speed_radps = static_cast<Real>(0.3);    ///< Swing rate (above the drive deadband).
  Real swing_tolerance_rad = deg_to_rad(static_cast<Real>(1));   ///< A swing leg ends this close to its target.
  std::uint8_t max_swings = 2;  ///< Full swings (+A, −A, back to the start) without a detection before fault 177.
  // Target loss (ALIGN).
  Real target_lost_after_s = static_cast<Real>(0.5);  ///< Estimate older than this: stop and wait.
  Real target_lost_timeout_s = static_cast<Real>(5.0);///< Lost this long: fault 181.
  /// The last stretch: with the robot's edge (footprint half-length or radius) this close to the dock's face, a
  /// confirmed estimate carried by odometry stays current for up to blind_finish_max_s, m (0: off). A lidar near the
  /// robot's front comes too close to see more than the dock's flat face, which fixes no lateral position.
  Real blind_finish_m = static_cast<Real>(0.10);
  Real blind_finish_max_s = static_cast<Real>(10.0);  ///< Longest the last stretch runs on odometry alone, s.
  /// The approach from afar: with the dock at least this far from the robot's edge (footprint half-length or
  /// radius), the estimate carried by odometry stays current for up to blind_approach_max_s, m (> 0). At range a lidar
  /// puts few beams on the dock and a steep view loses it from scan to scan; a robot that stood still for each loss
  /// would keep the view that lost it, while a metre of odometry moves the dock by centimetres, which the next
  /// detection on the way in corrects.
  Real blind_approach_m = static_cast<Real>(1.0);
  /// The approach from the side: with the robot's centre at least this far off the dock's axis (bearing from the
  /// dock's face, rad, in [0, pi]), the estimate carried by odometry also stays current for up to
  /// blind_approach_max_s, however near the dock. Seen that steeply, a dock shows one side (a V one arm, edge-on
  /// the other) and is refused scan after scan; the way to the axis is what brings it back into view. pi: off.
  Real blind_off_axis_rad = deg_to_rad(static_cast<Real>(20));
  /// Longest the approach runs on odometry alone, s (0: off). Long enough for a far robot to turn towards the dock
  /// and then cover some of the way: a slow lidar (RPLIDAR at 5.5 Hz) loses a dock 2–2.5 m out from scan to scan.
  Real blind_approach_max_s = static_cast<Real>(8.0);
  /// The final push: it starts on the first ALIGN tick on which the estimate puts the robot lined up with the dock
  /// (its axis within 45° of the dock's, pads fore or aft) with its edge (footprint half-length or radius) this close
  /// to the dock's face, m (> 0), and lasts until ALIGN ends. Within it the robot may travel at most max_push_m on
  /// odometry and spend at most max_push_s without the contacts closing; then the attempt ends (RETRY, and fault 190
  /// when no retry is left). A robot held short of the contacts (something the lidar does not see between the pads
  /// and the contacts) would otherwise push on, its command raised by the wheel deadband learning, until the task
  /// timeout; one that slips or runs past the dock's face would drive on.
  Real push_zone_m = static_cast<Real>(0.10);
  Real max_push_m = static_cast<Real>(0.30);  ///< Odometry path length allowed in the final push, m (> 0).
  Real max_push_s = static_cast<Real>(15.0);  ///< Time allowed in the final push, s (> 0).
  // Pose deviation (ALIGN) and obstacle handling.
  DeviationParams deviation{};
  MotionGateParams gate{};
  Real obstacle_timeout_s = static_cast<Real>(10.0);  ///< Blocked this long: fault 180.
  /// A command whose translation an obstacle blocks keeps its turn when turning in place is free (the robot turns
  /// away from what stands before it, as the controller wants to turn anyway); false: the whole command stops. The
  /// blocked time runs until a whole command passes again, so turning on the spot cannot hide an obstacle beyond
  /// obstacle_timeout_s.
  bool turn_when_blocked = true;
  // Charging (WAIT_FOR_CHARGE, FINISH_TASKING).
  Real charge_current_threshold_a = static_cast<Real>(0.5);  ///< Charging = contact and current at least this.
  Real charge_confirm_hold_s = static_cast<Real>(0.3);  ///< Contact and current held this long confirm charging.
  Real charge_confirm_timeout_s = static_cast<Real>(5.0);  ///< No confirmation within this: retry.
  Real contact_lost_debounce_s = static_cast<Real>(0.3);   ///< Contacts open this long while charging: fault 183.
  std::uint8_t max_retries = 3;  ///< Attempts after the first; then fault 182/188/190 with the robot backed off.
  /// Lateral search on retries, m (>= 0; 0: off). After an attempt that reached the dock without the contacts closing
  /// (retry reason 188 or 190), the next attempt aims on the axis again (the miss may have had a transient cause), and
  /// every further one beside it: +s, -s, +2s, -2s ... from the dock's axis. A lidar whose mount is off its configured
  /// pose by a centimetre (a calibration error nobody measured) puts every attempt the same centimetre beside the
  /// contacts; the search finds them. The controller gets the aim as ControlInput::aim_lateral_m (`smooth` honours it).
  /// Neighbouring aims overlap when the step is at most the contacts' lateral window (±tolerance) less twice the
  /// docking's own lateral error: 2 × (10 − 4) mm for the simulated ±10 mm contacts.
  Real retry_lateral_step_m = static_cast<Real>(0.012);
  /// Remember the aim that closed the contacts. When charging is confirmed, the lateral aim of that attempt (the
  /// search's offset, plus the aim it started from) becomes the first aim of the next docking at the same dock
  /// (ids 0-31), and the search runs around it: a lidar calibration error is then searched for once, not on every
  /// docking. A docking that ends in 188/190 after missing the contacts forgets its dock's aim. Kept until
  /// configure().
  bool remember_aim = true;
  /// Measure where the lidar sits sideways on the robot (MountCalibration, docs/task-manager.md "Mount calibration")
  /// after the first attempt of a docking that reached the dock without the contacts closing (188, 190, or contacts
  /// that closed and did not stay closed) and has a retry left: backed off to the staging distance, the robot turns on
  /// the spot to +calibration_swing_rad, to −calibration_swing_rad and back at swing_speed_radps, and the lidar mount
  /// dockcore uses moves sideways by what the swing measured (at most max_mount_correction_m). The move is kept until
  /// configure(), and no further swing runs once one has measured; the remembered aims (remember_aim) are forgotten
  /// with it, since they answered the old mount. A swing an obstacle stops, or whose measure fails a check, changes
  /// nothing and the retry goes on as before (the next docking that misses swings again).
  bool calibrate_mount = true;
  Real calibration_swing_rad = deg_to_rad(static_cast<Real>(25));  ///< Swing to ±this about the heading, rad.
  Real max_mount_correction_m = static_cast<Real>(0.03);           ///< Largest sideways move a swing may make, m (> 0).
  // Backing off (RETRY, UNDOCKING).
  Real staging_distance_m = static_cast<Real>(0.6);   ///< Back off until the robot centre is this far from the dock.
  Real fallback_backoff_m = static_cast<Real>(0.3);   ///< Without a dock estimate: back off this far on odometry.
  Real backoff_speed_mps = static_cast<Real>(0.1);    ///< Backing speed (above the drive deadband).
  /// The charging pads are at the robot's rear: it docks backwards, so backing off from the dock (RETRY, UNDOCKING)
  /// drives forwards. Not a key of its own: dockd and the scenarios derive it from the footprint's `pads`.
  bool pads_rear = false;
  Real backoff_timeout_s = static_cast<Real>(20.0);   ///< Back-off not done in this time: fault (186 undocking).
  Real charge_off_timeout_s = static_cast<Real>(2.0); ///< Undock: current must stop within this, else fault 186.
  /// The host switches the charging current (a relay the chassis closes on request: dockcore CAN v1's
  /// ChargeRequest). Undocking then waits for the current to stop before the robot moves. When false (bases with no
  /// relay frame, e.g. AgileX: the dock's charger is live whenever the contacts touch) it cannot be stopped from the
  /// robot: undocking backs off at once, the contacts opening ends the current, and fault 186 is raised when current
  /// still flows after the back-off. Not a key of its own: dockd derives it from the chassis profile, the scenarios
  /// from `[dock.contacts] switched`.
  bool charger_switched = true;
  // Limits and timing.
  Real task_timeout_s = static_cast<Real>(180.0);     ///< Docking (GET_TASKING_CMD..WAIT_FOR_CHARGE) longer: fault 189.
  Real max_vx_mps = static_cast<Real>(0.5);           ///< Final clamp on |vx| (the controller's limits come first).
  Real max_vy_mps = static_cast<Real>(0.5);           ///< Final clamp on |vy|.
  Real max_wz_radps = static_cast<Real>(1.5);         ///< Final clamp on |wz|.
  Real nominal_dt_s = static_cast<Real>(0.02);        ///< dt for the first tick and for non-increasing time.
  std::uint32_t accepted_dock_ids = 0xFFFFFFFFu;      ///< Bit i set: dock id i accepted (ids 0..31).
};

/// The dock estimate (filtered), as the DockPoseFilter gives it for the current odometry pose.
struct DockInput {
  bool valid = false;             ///< The filter has a dock (it may be old: see stamp_us).
  Pose2 pose{};                   ///< Dock in the robot frame now.
  Mat3 covariance = Mat3::Zero(); ///< Robot-frame covariance of (x, y, yaw).
  std::uint64_t stamp_us = 0;     ///< Time of the last detection fused into it.
  /// The estimate rests on at least two agreeing detections since the filter's last (re)initialisation. When false
  /// a disagreeing detection says only that one of two detections is wrong, not that the robot was pushed: the
  /// push test skips it (the filter's gate sorts it out).
  bool confirmed = true;
};

/// One raw detection of a scan processed since the previous tick (for the push test).
struct DetectionInput {
  bool fresh = false;          ///< A detection arrived since the previous tick.
  Pose2 dock_in_robot{};       ///< Dock in the robot frame at the scan time.
  Pose2 odom_at_scan{};        ///< Robot odometry pose at the scan time.
  std::uint64_t stamp_us = 0;
  /// The filter's expectation just before this detection was fused, as Dockcore records it per detection: the
  /// push test compares the detection with it, so a detection the filter then adopts (it restarts after
  /// DockFilterParams::reinit_after jumps, e.g. several scans of a pushed robot fused between two ticks) is still
  /// judged against what odometry said at its time. When false (callers without a filter) the test uses
  /// TaskInput::dock as it is on the tick.
  bool expectation_set = false;
  bool expectation_confirmed = false;  ///< The expectation rested on two agreeing detections (DockInput::confirmed).
  /// Dock in the odometry frame the filter expected: confirmed, or (expectation_confirmed false) the filter resting
  /// on one detection, which the push test uses only when the room says the robot was moved (scene kMoved).
  Pose2 expected_in_odom{};
  /// Whether the scan shows the room where odometry puts it (SceneCheck, judged when the detection is off the
  /// expectation): kStill makes a detection that fails the push test another object taken for the dock, not a push;
  /// kMoved means the room moved as the detection implies, so even an expectation that rests on one detection
  /// (expectation_confirmed false) is the push test's reference.
  SceneVerdict scene = SceneVerdict::kUnknown;
  /// The detection lies, within the push test's tolerances, where the filter had the dock before a detection the room
  /// overruled restarted it on something else (furniture taken for the hidden dock): the dock seen again, not a push,
  /// unless the room says the robot was moved.
  bool at_overruled_place = false;
};

/// Detections one tick can carry: a host draining a scan backlog after a stall hands several scans to
/// Dockcore::on_scan before the next tick (dockd: up to 4 per loop). Beyond this the oldest are kept (a push shows in
/// the first detections after it) and the rest counted.
constexpr std::size_t kMaxDetectionsPerTick = 8;

/// Everything the task manager sees on one tick.
struct TaskInput {
  std::uint64_t now_us = 0;  ///< Monotonic time of this tick.
  HostCommand command{};     ///< Command arriving on this tick (edge), or kNone.
  DockInput dock{};
  /// Detections since the previous tick, oldest first; the push test (ALIGN) runs on every one of them in order.
  DetectionInput detections[kMaxDetectionsPerTick] = {};
  std::uint8_t detection_count = 0;
  Pose2 odom_pose{};
  Twist2 odom_twist{};
  const ScanView* scan = nullptr;  ///< Latest scan for the obstacle check (null: motion blocked). This call only.
  Pose2 lidar_mount{};
  CameraTarget camera{};
  bool contact = false;            ///< Charging contacts closed.
  Real charge_current_a = 0;       ///< Charging current (positive into the battery).
  bool chassis_ok = true;          ///< Chassis feedback fresh (host's judgement).
  bool lidar_ok = true;            ///< Lidar scans fresh (host's judgement).
};

/// The status frame content for the host (CAN/UDP).
struct TaskStatus {
  TaskState state = TaskState::kNotTasking;
  std::uint8_t phase = 0;  ///< Controller phase in ALIGN; 1 in RETRY while the mount calibration swings; else 0.
  FaultCode fault = FaultCode::kNone;
  std::uint8_t retries = 0;        ///< Retries used in the current/last task.
  /// In RETRY: why the attempt ended (kAlignFailed: the controller gave up, e.g. pressed without contact;
  /// kChargeNotConfirmed: the contacts closed but no charging current; kContactsNotReached: the final push used up
  /// its distance or time, or the contacts stayed open while waiting for the charge), the fault raised when no retry
  /// is left. kNone in every other state.
  FaultCode retry_reason = FaultCode::kNone;
  bool dock_valid = false;         ///< dock_pose is a current estimate (not older than target_lost_after_s).
  Pose2 dock_pose{};               ///< Dock in the robot frame.
  bool charge_enable = false;      ///< Charging requested.
  CommandResult last_command = CommandResult::kNone;  ///< Result of the most recent command.
  TaskResult last_result = TaskResult::kNone;
  std::uint16_t dock_id = 0;       ///< Dock of the current/last task.
  /// Lateral aim of the current/last attempt, m: beside the dock's axis, the remembered aim plus the search's
  /// offset (TaskParams::retry_lateral_step_m, remember_aim).
  Real aim_lateral_m = 0;
};

/// One tick's result.
struct TaskOutput {
  Twist2 cmd{};                     ///< Body twist to command (before kinematics). Zero unless moving is allowed.
  TaskStatus status{};
  CommandResult command_result = CommandResult::kNone;  ///< For the command given on this tick.
  /// The wanted motion was stopped by an obstacle this tick: cmd is zero, or its turn alone (turn_when_blocked).
  bool blocked = false;
  bool target_lost = false;         ///< ALIGN is holding because the estimate is stale or the controller lost it.
  ObstacleFlags obstacles{};        ///< Obstacle check of this tick (valid = false when none was needed).
  ControlStatus control = ControlStatus::kRunning;  ///< Controller status this tick (ALIGN only).
  /// A calibration swing moved the lidar mount on this tick (TaskManager::mount_shift_m()): estimates made with the
  /// old mount are that far off.
  bool mount_changed = false;
};

/// What the task manager learned about the robot and its docks while docking, which configure() forgets: the lidar
/// mount's calibration and the aim that closed each dock's contacts. A host that configures the core for another dock
/// (or for a teach) hands it back (TaskManager::restore_learned) so the robot need not learn it again.
struct TaskLearned {
  Real remembered_aim_m[kDockIds] = {};
  Vec2 mount_shift_m = Vec2::Zero();
  MountCalibrationResult last_calibration{};
  std::uint32_t calibrations = 0;
};

class TaskManager {
 public:
  /// `controller` must outlive this object; it is reset() at the start of every attempt.
  explicit TaskManager(DockingController& controller) : ctrl_(&controller) {}

  /// Sets the parameters, footprint and dock outline (for the obstacle check's dock exclusion). Resets to
  /// NOT_TASKING. O(vertices).
  void configure(const TaskParams& params, const FootprintParams& footprint, const DockProfile& profile);

  /// One tick. Cost: O(1) plus the controller's step plus one obstacle check when a motion is wanted.
  TaskOutput tick(const TaskInput& in);

  TaskState state() const { return state_; }
  /// A detection failed the push test and the next agreeing one would raise 178/179 (ALIGN). O(1).
  bool push_suspected() const { return suspects_ > 0; }
  /// Detections that failed the push test while their scan showed the room standing where odometry puts it
  /// (DetectionInput::scene kStill), or that saw the dock again where it stood before furniture was taken for it
  /// (DetectionInput::at_overruled_place): not counted towards 178/179. Since configure(). O(1).
  std::uint32_t pushes_overruled() const { return pushes_overruled_; }
  /// Where this attempt aims beside the dock's axis (retry_lateral_step_m), m in the dock frame's y. O(1).
  Real retry_lateral_offset_m() const;
  /// The lateral aim of the current attempt: the dock's remembered aim plus the search's offset, m.
  Real attempt_aim_m() const;
  /// The current attempt is in its final push (ALIGN, see TaskParams::push_zone_m). O(1).
  bool in_final_push() const { return pushing_; }
  /// Odometry path length travelled in the final push so far, m; that of the last push once ALIGN has ended, 0
  /// before any. O(1).
  Real push_travel_m() const { return push_travel_m_; }
  /// Time spent in the final push so far, s (at the last tick); that of the last push once ALIGN has ended, 0
  /// before any. O(1).
  Real push_elapsed_s() const { return push_elapsed_s_; }
  /// What to add to the configured lidar mount's x and y (robot frame), m: the last calibration swing that measured
  /// (TaskParams::calibrate_mount). Zero after configure(). O(1).
  const Vec2& mount_shift_m() const { return mount_shift_m_; }
  /// The last calibration swing's result; status kNone before any since configure(). O(1).
  const MountCalibrationResult& last_calibration() const { return last_calibration_; }
  /// Calibration swings ended since configure(), whatever their result. O(1).
  std::uint32_t calibrations() const { return calibrations_; }
  /// The learned state (TaskLearned). O(kDockIds).
  TaskLearned learned() const;
  /// Takes `l` as this configuration's learned state (after configure(), before a task runs). O(kDockIds).
  void restore_learned(const TaskLearned& l);
  FaultCode fault() const { return fault_; }
  const TaskParams& params() const { return params_; }
  const ObstacleChecker& obstacle_checker() const { return obstacles_; }

 private:
  void handle_command(const TaskInput& in, TaskOutput& out);
  void enter(TaskState s, const TaskInput& in);
  void raise(FaultCode f, const TaskInput& in);
  void start_backoff(const TaskInput& in);
  /// Backs off; returns true when done. Sets want_.
  bool run_backoff(const TaskInput& in);
  void run_reach(const TaskInput& in);
  /// One tick of a swing on the spot about `origin_rad` at swing_speed_radps: to +amplitude_rad (*leg 1), to
  /// −amplitude_rad (2), back to the origin (3), one still tick between legs. Sets want_ while turning; true on the
  /// tick the third leg ends (*leg stays 3).
  bool swing(Real origin_rad, Real amplitude_rad, std::uint8_t* leg, const TaskInput& in);
  void run_align(const TaskInput& in, TaskOutput& out);
  /// Push test (178/179) on one detection; returns true when it raised the fault.
  bool test_detection(const DetectionInput& det, const TaskInput& in);
  void run_wait_for_charge(const TaskInput& in);
  void run_finish(const TaskInput& in);
  void run_retry(const TaskInput& in);
  /// The next attempt: counts the retry and starts the search (REACH_TASKING_POINT).
  void next_attempt(const TaskInput& in);
  /// Starts the calibration swing where the robot stands (RETRY, after the back-off).
  void start_calibration(const TaskInput& in);
  /// The calibration swing: collects this tick's detections, turns, and at its end measures and moves the mount.
  void run_calibration(const TaskInput& in);
  void end_calibration(const MountCalibrationResult& result, const TaskInput& in);
  void run_undocking(const TaskInput& in);
  /// Attempt failed (charge not confirmed, contacts not reached, controller failure): back off, then retry or fault
  /// with `final_fault`. A miss of the contacts (188, 190, or `lateral_miss`: they closed and did not stay closed)
  /// moves the next attempt's aim (retry_lateral_step_m).
  void fail_attempt(FaultCode final_fault, const TaskInput& in, bool lateral_miss = false);
  /// An attempt that ended this way reached the dock without the contacts closing (188, 190).
  static bool missed_contacts(FaultCode f) {
    return f == FaultCode::kAlignFailed || f == FaultCode::kContactsNotReached;
  }
  bool dock_fresh(const TaskInput& in) const;
  /// The estimate puts the robot in the final push's zone (TaskParams::push_zone_m).
  bool in_push_zone(const TaskInput& in) const;
  /// Starts or advances the final push on this tick's odometry; true when it has used up its distance or time.
  bool push_exhausted(const TaskInput& in);
  static Real since_s(std::uint64_t t_us, const TaskInput& in);
  /// The one place the output twist is produced.
  void emit(const TaskInput& in, TaskOutput& out);

  DockingController* ctrl_;
  TaskParams params_{};
  ObstacleChecker obstacles_{};

  TaskState state_ = TaskState::kNotTasking;
  FaultCode fault_ = FaultCode::kNone;
  TaskState faulted_in_ = TaskState::kNotTasking;  // the state the current fault was raised in
  TaskResult last_result_ = TaskResult::kNone;
  CommandResult last_command_ = CommandResult::kNone;
  std::uint16_t dock_id_ = 0;
  std::uint8_t retries_ = 0;
  std::uint8_t lateral_misses_ = 0;  ///< This task's attempts that reached the dock without contact (188, 190).
  Real remembered_aim_m_[kDockIds] = {};  ///< Per dock id: the aim that last closed the contacts (remember_aim).
  std::uint8_t phase_ = 0;

  Twist2 want_{};              // the state's wanted twist for this tick; emit() decides what leaves
  bool hold_ = false;          // a stop condition of the running state (target lost)
  bool have_prev_tick_ = false;
  std::uint64_t prev_tick_us_ = 0;
  std::uint64_t state_since_us_ = 0;
  std::uint64_t task_since_us_ = 0;

  // Detection search.
  Real swing_origin_rad_ = 0;
  std::uint8_t swing_leg_ = 0;   // 0 wait, 1 to +A, 2 to −A, 3 back to origin
  std::uint8_t swings_ = 0;
  // Alignment.
  bool lost_ = false;
  std::uint64_t lost_since_us_ = 0;
  Real start_distance_m_ = 0;
  std::uint32_t pushes_overruled_ = 0;
  /// Places where detections failed the push test since the last one that passed, newest last: each the latest
  /// failing detection there (odometry frame) and how many agreeing ones failed there. Two, so that one lone
  /// outlier between two detections of a pushed robot does not hide the push.
  static constexpr std::size_t kPushSuspects = 2;
  Pose2 suspect_pose_[kPushSuspects] = {};
  std::uint8_t suspect_count_[kPushSuspects] = {};
  std::uint8_t suspects_ = 0;
  bool pushing_ = false;              ///< In the final push (reset on entering ALIGN).
  std::uint64_t push_since_us_ = 0;
  Pose2 push_prev_odom_{};  ///< Odometry pose of the previous tick in the push.
  Real push_travel_m_ = 0;
  Real push_elapsed_s_ = 0;
  // Obstacles.
  bool blocked_ = false;
  std::uint64_t blocked_since_us_ = 0;
  // Charging.
  bool charge_ok_ = false;
  std::uint64_t charge_ok_since_us_ = 0;
  bool contact_seen_ = false;  ///< The contacts were closed on entering WAIT_FOR_CHARGE or since.
  bool contact_open_ = false;
  std::uint64_t contact_open_since_us_ = 0;
  // Back-off.
  Pose2 backoff_start_{};
  Real backoff_needed_m_ = 0;
  FaultCode pending_fault_ = FaultCode::kNone;  // set when the current back-off ends in a fault (retries used up)
  FaultCode retry_reason_ = FaultCode::kNone;   // why the current attempt failed
  bool undock_backing_ = false;
  std::uint64_t backoff_since_us_ = 0;
  // Mount calibration (RETRY).
  MountCalibration calibration_{};
  bool calibrate_next_ = false;       // the current back-off ends in a calibration swing
  bool calibrating_ = false;          // the swing runs
  bool swung_this_task_ = false;      // one swing per docking task
  std::uint8_t calibration_leg_ = 0;  // 1 to +A, 2 to −A, 3 back to the origin
  Real calibration_origin_rad_ = 0;
  std::uint64_t calibration_since_us_ = 0;
  Vec2 mount_shift_m_ = Vec2::Zero();
  MountCalibrationResult last_calibration_{};
  std::uint32_t calibrations_ = 0;
  bool mount_changed_ = false;  // reported in this tick's output
  Real dt_s_ = 0;
};

}  // namespace dockcore
