#pragma once
/// @file Dockcore: the whole docking stack behind two calls, as dockd and dock-sim run it.
///
/// Owns the Odometry (the robot in the odometry frame, from the chassis's feedback), a DockPoseEstimator (per-scan
/// detection), a DockPoseFilter (the dock in the odometry frame, fed by the detections) and a TaskManager (states,
/// safety, faults); drives a DockingController given by reference.
/// - on_wheels() / on_odometry(): the chassis's feedback, by its stamp (dockcore/control/odometry.hpp). Scans and tag
///   frames are placed at the odometry pose of their own stamp; the tick uses the newest.
/// - The InputWatch (dockcore/task/input_watch.hpp) judges every input's freshness with one set of thresholds
///   (DockcoreConfig::watchdog): a late scan is not used, stale input holds the drive at zero at once, and input that
///   stays stale faults the task (184/185). check_inputs() gives the host the verdict's changes before the tick.
/// - submit(): host commands wait in a queue (CommandQueue, 8 deep); each tick hands the oldest to the task manager,
///   else the resume policy's: a dock or undock that stale input faulted is issued again once both inputs have been
///   fresh for WatchdogParams::resume_after_ms, at most max_resumes times per task. TickOutput says which command
///   was taken and what became of it.
/// - on_scan(): detection with the filter's prediction as the estimator's hint (tracking mode; global search when
///   the filter has no dock or the hint fails), then the filter update. The scan is copied so the tick can run the
///   obstacle check and give controllers (seed003) the latest ranges. Before detection the scan's intensities go to
///   the IntensityCheck (intensity()): the estimator reads a reflector dock's stripes (EvidenceCue::kIntensity)
///   unless it calls them flat or absent (so also before its first verdict: the geometry alone would take another
///   dock of the same shape).
/// - tick() also shapes the task manager's twist into what the drive is sent (TickOutput::drive_cmd, ::wheels):
///   saturation keeping the path's curvature, the acceleration limit over one control period, a zero twist at once
///   (stop, fault, idle: the drive's own limits brake), and the drive's inverse kinematics. Every caller (dockd, the
///   simulator, the firmware) sends these, so the loop that is simulated is the one that runs.
/// - tick(): the filtered dock seen from the current odometry pose, every raw detection since the previous tick (for
///   the push test; up to kMaxDetectionsPerTick, oldest first, each with the filter's expectation from just before
///   it was fused), the latest scan and the host's flags go to the TaskManager; its twist and status come back. The
///   push test trusts the filter only once it has fused a second, agreeing detection since it (re)started
///   (DockInput::confirmed). Recording the expectation per detection matters when several scans arrive between two
///   ticks (a host draining a backlog after a stall): the filter restarts at a pushed pose on its third jump, and a
///   test against the filter as it is at the tick would find nothing wrong.
/// The filter is reset when a new dock task starts (the robot may have been carried since the last one). A resumed
/// dock command (the resume policy re-issues a command a lidar/chassis outage interrupted) resets it too, but the push
/// test keeps the confirmed estimate from before the outage as its reference — the filter's own, or the one it had
/// before it restarted at a pushed pose during the outage — carried by odometry, up to
/// DockcoreConfig::push_check_max_gap_s old, until a detection in ALIGN agrees with it (docs/faults.md, 178).
/// - on_tag(): a camera's tag detection (docs/camera.md, "Fusion"): the active dock's tag only, in stamp order, not
///   older than the newest scan by more than TagFusionParams::max_lag_s, turned into a dock pose
///   (tag_to_dock_measurement) and fused into the same filter (DockPoseFilter::update_tag: same gate, no evidence).
///   Refusals are counted by reason and change nothing else. Tag measurements are not raw detections for the push
///   test, and the lidar's scan stays the obstacle check's input: the tag replaces the lidar's dock detection, not
///   its safety role.
/// - The detector is a per-dock choice (DockcoreConfig::detector): the estimator (any profile), or seed 000's
///   BreakpointDetector for the built-in breakpoint dock (breakpoint_measurement.hpp turns its detection into a pose
///   and covariance; it has no evidence for the sequential test and takes no hint). The breakpoint detector is not
///   part of the core: its owner attaches one (attach_breakpoint), so a core whose docks do not use it does not carry
///   its buffers.
/// No heap. DockcoreN<N> holds the estimator's buffers and the scan copy for N beams (docs/architecture.md: about
/// 81 KiB with double at 720 beams, 334 KiB at kMaxScanPoints): keep it static or a member, never on a small stack.

#include <cstdint>

#include "dockcore/control/controller.hpp"
#include "dockcore/control/kinematics.hpp"
#include "dockcore/control/odometry.hpp"
#include "dockcore/control/safety.hpp"
#include "dockcore/control/wheel_deadband.hpp"
#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/breakpoint_detector.hpp"
#include "dockcore/perception/dock_pose_estimator.hpp"
#include "dockcore/perception/dock_pose_filter.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "dockcore/perception/intensity_check.hpp"
#include "dockcore/perception/scene_check.hpp"
#include "dockcore/perception/tag_measurement.hpp"
#include "dockcore/task/command_queue.hpp"
#include "dockcore/task/input_watch.hpp"
#include "dockcore/task/task_manager.hpp"

namespace dockcore {

/// Which detector finds the dock in each scan: a per-dock choice (dockd's [[docks]] detector, a scenario's
/// [dock] detector). docs/docks.md says which detector finds which dock.
enum class DockDetector : std::uint8_t {
  kEstimator = 0,  ///< DockPoseEstimator: any profile; pose, covariance and evidence. The default.
  kBreakpoint =
      1,  ///< BreakpointDetector (seed 000): the breakpoint dock only, against a wall; needs attach_breakpoint.
};

/// "estimator" / "breakpoint", as in config files. Never null.
const char* to_string(DockDetector d);

/// Why DockcoreBase::configure() refused a configuration (configure_status()).
enum class ConfigureStatus : std::uint8_t {
  kOk = 0,
  kBadProfile,               ///< The profile has no segments (the estimator refuses it).
  kDetectorNotAttached,      ///< DockDetector::kBreakpoint without a BreakpointDetector attached (attach_breakpoint).
  kDetectorProfileMismatch,  ///< DockDetector::kBreakpoint with a profile that is not the breakpoint outline.
  kDetectorNeedsWall,        ///< DockDetector::kBreakpoint with a free-standing mounting: its pattern needs a wall.
};

/// A one-line reason for a ConfigureStatus. Never null.
const char* to_string(ConfigureStatus s);

/// Whether `detector` can find a dock of `profile`: kOk, or kDetectorProfileMismatch / kDetectorNeedsWall for the
/// breakpoint detector (breakpoint_outline_frame; a mounting of kind free_standing). The estimator takes every
/// profile configure() takes. Config readers call it to refuse a file's pairing before a core exists. O(vertices).
ConfigureStatus detector_supports(DockDetector detector, const DockProfile& profile);

/// Everything Dockcore needs besides the profile and the controller.
struct DockcoreConfig {
  EstimatorParams estimator{};
  DockFilterParams filter{};
  TaskParams task{};
  FootprintParams footprint{};
  Pose2 lidar_mount{};                               ///< Lidar in the robot frame.
  DriveGeometry drive{};                             ///< Wheel arrangement, for the wheel speeds tick() returns.
  DriveLimits limits{};                              ///< Velocity and acceleration limits tick() applies.
  /// The control tick's nominal period, s: the acceleration limit's step. > 0.
  Real control_period_s = static_cast<Real>(0.02);
  WatchdogParams watchdog{};  ///< When scans and chassis feedback count as stale.
  WheelDeadbandParams deadband{};  ///< The drive's wheel deadband: known, and learned while docking (WheelDeadband).
  /// A resumed dock command (the resume policy's) keeps the dock estimate from before the outage as the push test's
  /// reference when its last detection is at most this old at the resume (s). Wheel odometry runs through a lidar
  /// outage, so the old estimate carried by odometry still says where the dock must be; beyond this, odometry drift
  /// (and the chance that the robot was carried) make it no evidence of a push, and the task starts afresh. The
  /// same bound keeps the task's last confirmed estimate the reference while a filter restarted within the task is
  /// unconfirmed. 8 s: a far robot sees a steep dock seldom, looks seconds apart around a push (blind_approach_max_s
  /// carries the approach as long), and odometry over that moves the dock by centimetres, not the push test's 0.3 m.
  Real push_check_max_gap_s = static_cast<Real>(8.0);
  /// The camera, the active dock's tag and the tag noise model (on_tag). dock_tag.id −1 (the default): every tag
  /// detection is refused as kWrongId.
  TagFusionParams tag{};
  /// This dock's detector. kBreakpoint uses estimator.range_sigma_m for its covariance (breakpoint_measurement.hpp).
  DockDetector detector = DockDetector::kEstimator;
  /// When the lidar's intensity counts as usable (IntensityCheck): the estimator reads reflector stripes unless the
  /// verdict is flat or absent.
  IntensityCheckParams intensity{};
  /// The push test's second opinion (SceneCheck): a detection off the expectation while the room stands where
  /// odometry puts it is another object taken for the dock, not a push.
  SceneCheckParams scene{};
};

/// Per-tick input from the chassis and the host.
struct TickInput {
  std::uint64_t now_us = 0;  ///< Monotonic time, same clock as the scan stamps.
  CameraTarget camera{};
  bool contact = false;
  Real charge_current_a = 0;
  /// The host is busy (teaching a dock): queued commands and resumes wait.
  bool hold_commands = false;
};

/// The task manager's output plus what the drive is sent and which command was taken.
struct TickOutput : TaskOutput {
  Twist2 drive_cmd{};    ///< `cmd` saturated, acceleration-limited and zeroed as the file comment says.
  WheelSpeeds wheels{};  ///< drive_cmd as wheel speeds of DockcoreConfig::drive (count from its kind).
  bool command_taken = false;               ///< A command reached the task manager (its result: command_result).
  QueuedCommand command{};                  ///< That command (a resume has `resume` set and token 0).
  ResumeEvent resume = ResumeEvent::kNone;  ///< What the resume policy did this tick.
  std::uint8_t resumes = 0;                 ///< Resumes of the current task so far.
};

/// The docking stack over an estimator and a scan buffer it does not own (DockcoreN<N> gives them, for scans of up
/// to N beams). Everything that drives the loop takes this, whatever its capacity. Not copyable.
class DockcoreBase {
 public:
  DockcoreBase(const DockcoreBase&) = delete;
  DockcoreBase& operator=(const DockcoreBase&) = delete;

  /// Configures every part but the inputs: the odometry, the input watch's history and the latest scan run on across
  /// docks and configurations (rescan() runs that scan through the new profile). False (unusable until a good call)
  /// when the profile has no segments or config.detector cannot run on it (configure_status() says which). O(vertices).
  bool configure(const DockProfile& profile, const DockcoreConfig& config);

  /// What the core learned about the robot while docking — the wheels' deadband floors and the task manager's
  /// TaskLearned (the lidar mount's calibration, the aims that closed each dock's contacts) — which configure()
  /// forgets. O(kDockIds).
  struct Learned {
    WheelDeadband::Floors deadband{};
    TaskLearned task{};
  };
  Learned learned() const;
  /// Takes `l` after configure() (for another dock, or a teach, on the same robot and configuration): the floors,
  /// the aims, and the lidar mount moved by the calibration's shift. O(kDockIds).
  void restore_learned(const Learned& l);
  /// What the last configure() decided (kOk before the first). O(1).
  ConfigureStatus configure_status() const { return configure_status_; }
  /// The BreakpointDetector docks configured with DockDetector::kBreakpoint run (nullptr: none; such a configure()
  /// is refused). `detector` must outlive this object or be detached first; configure() checks it, so attach before
  /// configuring. Each scan sets its beam-count thresholds to the seed's at that scan's resolution
  /// (breakpoint_params_for_scan); its other parameters are its own. O(1).
  void attach_breakpoint(BreakpointDetector* detector) { breakpoint_ = detector; }
  /// The attached breakpoint detector (nullptr: none), e.g. for its counters. O(1).
  const BreakpointDetector* breakpoint() const { return breakpoint_; }

  /// Measured wheel speeds (rad/s, DockcoreConfig::drive's order) at `stamp_us`, integrated into the odometry
  /// (Odometry::add_wheels). False when the stamp is 0 or repeats the previous feedback's. O(1).
  bool on_wheels(const WheelSpeeds& measured, std::uint64_t stamp_us) {
    return odometry_.add_wheels(config_.drive, measured, stamp_us);
  }
  /// A base's own odometry pose and body twist at `stamp_us` (Odometry::add_pose). Same stamp rules. O(1).
  bool on_odometry(const Pose2& pose, const Twist2& twist, std::uint64_t stamp_us) {
    return odometry_.add_pose(pose, twist, stamp_us);
  }
  /// The odometry and its history. O(1).
  const Odometry& odometry() const { return odometry_; }
  /// Continues another core's inputs: its odometry, input watch, latest scan (copied, up to scan_capacity() beams)
  /// and queued commands. dockd rebuilding the core on a config reload (only while idle): the robot, its sensors and
  /// the host carry on. O(count).
  void take_inputs(const DockcoreBase& from);

  /// One scan stamped `stamp_us` (its first sample; 0 or later than `now_us` is taken as `now_us`), read at `now_us`:
  /// the input watch's check (a late scan is not used: nullptr, counted), then the intensity check, detection (the
  /// configured detector; the estimator's hint = the filter's prediction for the odometry pose at the stamp), filter
  /// update, scan copy. Feed the chassis feedback up to the scan's time first. Returns the scan's estimate
  /// (last_estimate(); from the breakpoint detector: found, status, pose and covariance only). Cost: the detector's
  /// (the estimator's, or BreakpointDetector::detect's O(beams)) plus O(count + Odometry::kHistory +
  /// IntensityCheck::kMaxSamples).
  const DockEstimate* on_scan(const ScanView& scan, std::uint64_t stamp_us, std::uint64_t now_us);
  /// The latest scan (last_scan()) through detection again, e.g. for a profile configure() just set; copies nothing.
  /// An empty estimate before the first scan. Cost: the detector's.
  const DockEstimate& rescan();

  /// The input watch's verdict at `now_us` (tick() makes the same call): which of lidar and chassis changed between
  /// fresh and stale. A host calls it before the tick to log the changes and act on them. O(1).
  InputWatch::Change check_inputs(std::uint64_t now_us) {
    return watch_.update(now_us, odometry_.valid(), odometry_.stamp_us());
  }
  /// The input watch (staleness, late scans, trips). O(1).
  const InputWatch& inputs() const { return watch_; }
  /// Whether the lidar's intensity is usable, judged on every scan on_scan() takes (IntensityCheck). It belongs to
  /// the sensor: configure() keeps its history, take_inputs() carries it. O(1).
  const IntensityCheck& intensity() const { return intensity_; }

  /// Queues a host command for the tick (CommandQueue::submit: a cancel is never lost). O(1).
  SubmitResult submit(const QueuedCommand& c, QueuedCommand* replaced = nullptr) { return queue_.submit(c, replaced); }
  /// The command the next tick will take from the queue (nullptr: none), so a host can prepare for it (dockd
  /// configures the core for its dock while idle). O(1).
  const QueuedCommand* next_command() const { return queue_.front(); }
  const CommandQueue& commands() const { return queue_; }
  /// A command that stale input interrupted waits for the inputs to be fresh again (resume policy). O(1).
  bool resume_pending() const { return interrupted_.type != HostCommandType::kNone; }

  /// One tag detection from a camera frame captured at `obs.stamp_us` (file comment), placed at the odometry pose of
  /// that stamp. Returns what became of it; anything but kFused leaves the filter unchanged. Counted in
  /// tag_counts(). O(Odometry::kHistory).
  TagStatus on_tag(const TagObservation& obs);
  /// Tag detections by outcome since configure(), indexed by TagStatus. O(1).
  std::uint32_t tag_count(TagStatus s) const { return tag_counts_[static_cast<std::size_t>(s)]; }

  /// One control tick: the task manager, then the output shaping (file comment). Cost: TaskManager::tick + O(1).
  TickOutput tick(const TickInput& in);

  const DockEstimate& last_estimate() const { return last_estimate_; }
  const DockPoseFilter& filter() const { return filter_; }
  const DockPoseEstimatorBase& estimator() const { return estimator_; }
  /// Most beams a scan may have: larger scans are refused by the estimator (kBadScan) and their copy truncated.
  std::size_t scan_capacity() const { return scan_capacity_; }
  /// The latest scan as kept for the tick (empty before the first). Valid until the next on_scan(). O(1).
  ScanView last_scan() const { return have_scan_ ? scan_ : ScanView{}; }
  /// Bytes the last on_scan() copied (ranges and intensities for the tick): 2 · count · sizeof(Real); 0 after
  /// rescan(). O(1).
  std::size_t scan_copy_bytes() const { return scan_copy_bytes_; }
  const TaskManager& task_manager() const { return tasks_; }
  const DockcoreConfig& config() const { return config_; }
  /// The lidar mount in use (robot frame): the configured one, moved sideways by the task manager's last calibration
  /// swing that measured (TaskParams::calibrate_mount). O(1).
  const Pose2& lidar_mount() const { return lidar_mount_; }
  /// The host sent the drive a zero command outside tick() (shutdown, a stop of its own): the next tick's
  /// acceleration limit starts from rest. O(1).
  void note_drive_stopped() {
    prev_drive_cmd_ = Twist2{};
    sent_drive_cmd_ = Twist2{};
    sent_wheels_ = WheelSpeeds{};
  }
  /// drive_cmd of the last tick. O(1).
  const Twist2& drive_cmd() const { return sent_drive_cmd_; }
  /// The wheel deadband the output shaping applies: its floors and how often they grew. O(1).
  const WheelDeadband& deadband() const { return deadband_; }
  /// Detections that did not fit into one tick's list (more than kMaxDetectionsPerTick scans between two ticks).
  std::uint32_t detections_dropped() const { return pending_dropped_; }
  /// Detections of scans stamped in a gap of the odometry (Odometry::pose_at's in_gap): reported in the estimate, not
  /// fused and not tested for a push. O(1).
  std::uint32_t detections_unplaced() const { return detections_unplaced_; }

 protected:
  /// `controller` must outlive this object; `estimator` and the two scan arrays (`scan_capacity` elements each)
  /// are the owner's.
  DockcoreBase(DockingController& controller, DockPoseEstimatorBase& estimator, Real* scan_ranges_m,
               Real* scan_intensities, std::size_t scan_capacity)
      : estimator_(estimator), tasks_(controller), scan_ranges_m_(scan_ranges_m), scan_intensities_(scan_intensities),
        scan_capacity_(scan_capacity) {}
  ~DockcoreBase() = default;

 private:
  /// The lidar mount in use: the configured one moved by the task manager's mount_shift_m().
  void take_mount_shift();
  /// Forgets the dock the filter follows and what was placed with it: the filter, the room's reference, the push
  /// test's references from this task (not a resumed command's pre-outage one, push_ref_). O(1).
  void forget_dock();
  /// Fills out->drive_cmd and out->wheels from out->cmd (file comment). O(1).
  void shape(bool hold, TickOutput* out);
  /// Hands the deadband the last command and the measured wheel speeds; `state` is the task's state that command was
  /// given in, `t` this tick's task input (the dock estimate). O(wheels).
  void observe_drive(const TickInput& in, TaskState state, const TaskInput& t);
  /// The robot's edge closer than this to the dock's face: a stall there may be the dock holding it, m.
  static constexpr Real kDeadbandDockClearanceM = static_cast<Real>(0.01);
  /// The resume policy's bookkeeping after the task manager's tick: what the taken command started or stopped, and
  /// which fault left a command to resume (file comment). O(1).
  void resume_policy(TaskState before, bool have_cmd, const QueuedCommand& cmd, TickOutput* out);
  /// Copies `scan` (unless it is the kept copy) and runs detection and the filter on it. Cost: the detector's.
  const DockEstimate& estimate_scan(const ScanView& scan, std::uint64_t stamp_us);
  /// The attached breakpoint detector on `scan`, as an estimate of the configured profile's frame. O(beams).
  DockEstimate breakpoint_estimate(const ScanView& scan);
  DockcoreConfig config_{};
  Pose2 lidar_mount_{};  ///< config_.lidar_mount plus the task manager's mount_shift_m().
  Odometry odometry_{};
  InputWatch watch_{};
  IntensityCheck intensity_{};
  SceneCheck scene_{};              ///< The latest agreeing scan, for the push test's second opinion.
  std::uint64_t scene_ref_us_ = 0;  ///< When scene_ took its reference.
  CommandQueue queue_{};
  // The resume policy: the dock/undock running now, the one stale input interrupted, resumes this task.
  HostCommand running_{};
  HostCommand interrupted_{};
  std::uint8_t resumes_ = 0;
  DockPoseEstimatorBase& estimator_;
  DockPoseFilter filter_{};
  TaskManager tasks_;
  // The latest scan's copy, for the tick: its geometry and the owner's arrays.
  Real* scan_ranges_m_;
  Real* scan_intensities_;
  std::size_t scan_capacity_;
  ScanView scan_{};
  BreakpointDetector* breakpoint_ = nullptr;  ///< attach_breakpoint's; the owner's.
  std::size_t scan_copy_bytes_ = 0;
  std::uint64_t last_scan_us_ = 0;
  DockEstimate last_estimate_{};
  DetectionInput pending_[kMaxDetectionsPerTick] = {};
  std::uint8_t pending_count_ = 0;
  bool have_scan_ = false;
  DockDetector detector_ = DockDetector::kEstimator;  ///< The configured one (kEstimator after a refusal).
  ConfigureStatus configure_status_ = ConfigureStatus::kOk;
  std::uint32_t pending_dropped_ = 0;  ///< Detections beyond kMaxDetectionsPerTick between two ticks (not tested).
  std::uint32_t detections_unplaced_ = 0;  ///< Detections of scans the odometry could not place (not fused).
  std::uint32_t tag_counts_[kTagStatusCount] = {};
  bool have_tag_ = false;
  TaskState prev_state_ = TaskState::kNotTasking;  // beside the flag: the two share one padded word
  std::uint64_t last_tag_us_ = 0;                  ///< Newest tag frame past the id and order checks.
  Twist2 prev_drive_cmd_{};    ///< The previous tick's command before the deadband: the acceleration limit's start.
  Twist2 sent_drive_cmd_{};    ///< drive_cmd of the previous tick (after the deadband).
  WheelSpeeds sent_wheels_{};  ///< wheels of the previous tick: what the measured wheel speeds are compared with.
  WheelDeadband deadband_{};
  bool filter_confirmed_ = false;  ///< The filter fused a detection since its last (re)initialisation.
  // The flags of the three references below, kept together (one padded word).
  bool restart_ref_set_ = false;
  bool push_ref_set_ = false;
  bool confirmed_ref_set_ = false;
  bool overruled_restart_set_ = false;
  /// The filter's dock before a detection the room overruled restarted it (this task): the dock may be hidden there.
  Pose2 overruled_restart_from_{};
  /// The confirmed estimate from before the filter's most recent restart (this task), for a resumed command.
  Pose2 restart_ref_in_odom_{};
  std::uint64_t restart_ref_us_ = 0;  ///< Last detection fused into it.
  /// The push test's reference after a resume (the resume policy's command), replacing the restarted filter.
  Pose2 push_ref_in_odom_{};
  /// This task's newest confirmed estimate (dock in odom; equal to the filter's while filter_confirmed_) and the
  /// stamp of the detection that made it: the push test's reference, also while the filter rests on one detection
  /// after a restart.
  Pose2 confirmed_ref_in_odom_{};
  std::uint64_t confirmed_ref_us_ = 0;
};

/// The docking stack with its estimator and scan copy, for scans of up to N beams (a board picks N for its lidar:
/// 720 for an LD06's 0.5°, 1440, or kMaxScanPoints). docs/architecture.md gives the size of each choice.
template <std::size_t N>
class DockcoreN : public DockcoreBase {
 public:
  static constexpr std::size_t kCapacity = N;
  /// `controller` must outlive this object.
  explicit DockcoreN(DockingController& controller)
      : DockcoreBase(controller, estimator_storage_, scan_ranges_storage_, scan_intensities_storage_, N) {}

 private:
  DockPoseEstimatorN<N> estimator_storage_;
  Real scan_ranges_storage_[N] = {};
  Real scan_intensities_storage_[N] = {};
};

/// The docking stack for every lidar core supports (kMaxScanPoints beams).
using Dockcore = DockcoreN<kMaxScanPoints>;

}  // namespace dockcore
