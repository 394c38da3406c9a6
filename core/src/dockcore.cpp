#include "dockcore/dockcore.hpp"

#include <cmath>

#include "dockcore/perception/breakpoint_measurement.hpp"

namespace dockcore {

namespace {
// A detection this far off the expectation has the room judged (SceneCheck); nearer ones are tracking noise.
constexpr Real kSceneGateM = static_cast<Real>(0.05);
constexpr Real kSceneGateRad = static_cast<Real>(0.0873);  // 5°
// The scene's reference is renewed at most this often: odometry drifts slowly, and each renewal costs a pass over
// the scan.
constexpr std::uint64_t kSceneReferencePeriodUs = 500000;
// A scan that would keep under three quarters of the reference's points (the dock hidden, someone near the lidar)
// does not replace it until the reference is this old.
constexpr std::uint64_t kSceneReferenceMaxAgeUs = 3000000;
// The turns "still" must beat when the implied push rests on one detection: well above a detection's yaw noise.
constexpr Real kSceneProbeTurnRad = static_cast<Real>(0.1745);  // 10°
}  // namespace

const char* to_string(DockDetector d) {
  switch (d) {
    case DockDetector::kEstimator:
      return "estimator";
    case DockDetector::kBreakpoint:
      return "breakpoint";
  }
  return "unknown detector";
}

const char* to_string(ConfigureStatus s) {
  switch (s) {
    case ConfigureStatus::kOk:
      return "ok";
    case ConfigureStatus::kBadProfile:
      return "the dock profile has no segments";
    case ConfigureStatus::kDetectorNotAttached:
      return "detector breakpoint needs a BreakpointDetector attached";
    case ConfigureStatus::kDetectorProfileMismatch:
      return "detector breakpoint finds only the breakpoint dock (its outline, vertex for vertex)";
    case ConfigureStatus::kDetectorNeedsWall:
      return "detector breakpoint needs the dock against a wall (its mounting is free_standing)";
  }
  return "unknown configure status";
}

ConfigureStatus detector_supports(DockDetector detector, const DockProfile& profile) {
  if (detector != DockDetector::kBreakpoint) return ConfigureStatus::kOk;
  if (!breakpoint_outline_frame(profile)) return ConfigureStatus::kDetectorProfileMismatch;
  if (profile.mounting.kind == DockMountKind::kFreeStanding) return ConfigureStatus::kDetectorNeedsWall;
  return ConfigureStatus::kOk;
}

bool DockcoreBase::configure(const DockProfile& profile, const DockcoreConfig& config) {
  config_ = config;
  lidar_mount_ = config.lidar_mount;
  watch_.configure(config.watchdog);
  intensity_.configure(config.intensity);
  filter_ = DockPoseFilter(config.filter);
  tasks_.configure(config.task, config.footprint, profile);
  pending_count_ = 0;
  pending_dropped_ = 0;
  detections_unplaced_ = 0;
  scene_.clear();
  for (std::uint32_t& c : tag_counts_) c = 0;
  have_tag_ = false;
  last_tag_us_ = 0;
  filter_confirmed_ = false;
  restart_ref_set_ = false;
  push_ref_set_ = false;
  confirmed_ref_set_ = false;
  overruled_restart_set_ = false;
  last_estimate_ = DockEstimate{};
  prev_state_ = TaskState::kNotTasking;
  prev_drive_cmd_ = Twist2{};
  sent_drive_cmd_ = Twist2{};
  sent_wheels_ = WheelSpeeds{};
  deadband_.configure(config.deadband);
  detector_ = DockDetector::kEstimator;
  configure_status_ = ConfigureStatus::kOk;
  if (!estimator_.configure(profile, config.estimator)) {
    configure_status_ = ConfigureStatus::kBadProfile;
    return false;
  }
  if (config.detector == DockDetector::kBreakpoint) {
    configure_status_ =
        breakpoint_ == nullptr ? ConfigureStatus::kDetectorNotAttached : detector_supports(config.detector, profile);
    if (configure_status_ != ConfigureStatus::kOk) return false;
  }
  detector_ = config.detector;
  return true;
}

DockcoreBase::Learned DockcoreBase::learned() const {
  Learned l;
  l.deadband = deadband_.floors();
  l.task = tasks_.learned();
  return l;
}

void DockcoreBase::restore_learned(const Learned& l) {
  deadband_.restore_floors(l.deadband);
  tasks_.restore_learned(l.task);
  take_mount_shift();
}

void DockcoreBase::forget_dock() {
  filter_.reset();
  filter_confirmed_ = false;
  scene_.clear();
  restart_ref_set_ = false;
  confirmed_ref_set_ = false;
  overruled_restart_set_ = false;
}

void DockcoreBase::take_mount_shift() {
  lidar_mount_ = config_.lidar_mount;
  lidar_mount_.x_m += tasks_.mount_shift_m().x();
  lidar_mount_.y_m += tasks_.mount_shift_m().y();
}

DockEstimate DockcoreBase::breakpoint_estimate(const ScanView& scan) {
  DockEstimate e;
  Pose2 native_in_dock;
  if (breakpoint_ == nullptr || !breakpoint_outline_frame(estimator_.profile(), &native_in_dock)) {
    e.status = EstimateStatus::kNoProfile;
    return e;
  }
  breakpoint_->set_params(breakpoint_params_for_scan(scan.angle_increment_rad, breakpoint_->params()));
  const BreakpointDetection d = breakpoint_->detect(scan);
  switch (d.status) {
    case BreakpointStatus::kFound:
      e.status = EstimateStatus::kNotVerified;
      break;  // until the pose is made
    case BreakpointStatus::kBadScan:
    case BreakpointStatus::kBadWindow:
      e.status = EstimateStatus::kBadScan;
      break;
    case BreakpointStatus::kEmptyWindow:
      e.status = EstimateStatus::kNoPoints;
      break;
    case BreakpointStatus::kTooFewMutations:
    case BreakpointStatus::kNoPattern:
      e.status = EstimateStatus::kNoCandidates;
      break;
  }
  Pose2 native_in_robot;
  Mat3 cov;
  if (!breakpoint_measurement(d, scan.angle_increment_rad, lidar_mount_, config_.estimator.range_sigma_m,
                              &native_in_robot, &cov, breakpoint_->params().min_jump_m)) {
    return e;
  }
  // The profile's frame may be the built-in's moved (a taught target): dock = native ∘ native_in_dock⁻¹. The
  // covariance is of the built-in frame's pose; the move is a few millimetres and degrees, so it stays as it is.
  e.found = true;
  e.status = EstimateStatus::kOk;
  e.pose = native_in_robot.compose(native_in_dock.inverse());
  e.covariance = cov;
  return e;
}

void DockcoreBase::take_inputs(const DockcoreBase& from) {
  odometry_ = from.odometry_;
  watch_ = from.watch_;  // configure() sets this core's thresholds
  intensity_ = from.intensity_;
  queue_ = from.queue_;
  have_scan_ = from.have_scan_;
  last_scan_us_ = from.last_scan_us_;
  const std::size_t n = from.scan_.count < scan_capacity_ ? from.scan_.count : scan_capacity_;
  for (std::size_t i = 0; i < n; ++i) {
    scan_ranges_m_[i] = from.scan_ranges_m_[i];
    scan_intensities_[i] = from.scan_intensities_[i];
  }
  scan_ = from.scan_;
  scan_.ranges_m = scan_ranges_m_;
  scan_.intensities = scan_intensities_;
  scan_.count = n;
}

const DockEstimate* DockcoreBase::on_scan(const ScanView& scan, std::uint64_t stamp_us, std::uint64_t now_us) {
  if (stamp_us == 0 || stamp_us > now_us) stamp_us = now_us;  // no stamp, or one from the future: when it was read
  if (!watch_.on_scan(stamp_us, now_us)) return nullptr;
  // The sensor's intensity is judged before detection reads it. Until there is a verdict a reflector dock's stripes
  // are read: taking the geometry alone then would accept another dock of the same shape, and the switch to the
  // right one once the verdict came would look like a push.
  intensity_.add(scan);
  const IntensityVerdict v = intensity_.verdict();
  estimator_.set_intensity_usable(v == IntensityVerdict::kUsable || v == IntensityVerdict::kUnknown);
  return &estimate_scan(scan, stamp_us);
}

const DockEstimate& DockcoreBase::rescan() {
  if (!have_scan_) {
    last_estimate_ = DockEstimate{};
    return last_estimate_;
  }
  return estimate_scan(scan_, scan_.stamp_us);
}

const DockEstimate& DockcoreBase::estimate_scan(const ScanView& scan, std::uint64_t stamp_us) {
  bool odometry_gap = false;
  const Pose2 odom_pose = odometry_.pose_at(stamp_us, &odometry_gap);
  const std::size_t n = scan.count < scan_capacity_ ? scan.count : scan_capacity_;
  // The tick's copy of the scan: the one copy a scan gets on its way from the parser (the estimator reads the
  // caller's). A scan fed back from that copy (last_scan()) is already there.
  scan_copy_bytes_ = 0;
  if (scan.ranges_m != scan_ranges_m_) {
    for (std::size_t i = 0; i < n; ++i) {
      scan_ranges_m_[i] = scan.ranges_m != nullptr ? scan.ranges_m[i] : static_cast<Real>(0);
      scan_intensities_[i] = scan.intensities != nullptr ? scan.intensities[i] : static_cast<Real>(0);
    }
    scan_copy_bytes_ = 2 * n * sizeof(Real);
  }
  scan_ = ScanView{scan_ranges_m_, scan_intensities_, n, scan.angle_min_rad, scan.angle_increment_rad, stamp_us};
  have_scan_ = true;
  last_scan_us_ = stamp_us;

  Pose2 hint{};
  const Pose2* hint_ptr = nullptr;
  if (filter_.initialised()) {
    hint = filter_.dock_in_robot(odom_pose);
    hint_ptr = &hint;
  }
  last_estimate_ = detector_ == DockDetector::kBreakpoint ? breakpoint_estimate(scan)
                                                          : estimator_.estimate(scan, lidar_mount_, hint_ptr);
  // A scan taken during a gap in the odometry (a host that read no feedback for a while, a chassis outage) cannot
  // be placed: the pose before the gap may be a driven half-second off, and the detection would land that far from
  // the dock, which the push test reads as a push. Its estimate is reported; the filter and the push test skip it.
  if (last_estimate_.found && odometry_gap) {
    ++detections_unplaced_;
    return last_estimate_;
  }
  if (last_estimate_.found) {
    // The push test's reference is the filter before this detection: once fused (or adopted by a restart) it
    // would agree with the detection whatever happened to the robot.
    DetectionInput d;
    d.fresh = true;
    d.dock_in_robot = last_estimate_.pose;
    d.odom_at_scan = odom_pose;
    d.stamp_us = stamp_us;
    d.expectation_set = true;
    const bool was_confirmed = filter_.initialised() && filter_confirmed_;
    // The expectation is the task's last confirmed estimate: while the filter is confirmed that is the filter itself
    // (gated detections leave it alone). After a restart it rests on one detection, and the last confirmed estimate,
    // carried by odometry, stays the expectation until the filter is confirmed again, if it is recent enough. A
    // restart needs reinit_after gated detections in a row, and those may come before a push (detections matched to
    // odometry read late on a loaded host): without this, the restart left the push test one look at the push and the
    // next post-push detection met the unconfirmed filter untested (HIL, motion_push_angle on a loaded machine).
    d.expectation_confirmed =
        confirmed_ref_set_ &&
        (was_confirmed ||
         (stamp_us >= confirmed_ref_us_ && static_cast<Real>(stamp_us - confirmed_ref_us_) * static_cast<Real>(1e-6) <=
                                               config_.push_check_max_gap_s));
    if (d.expectation_confirmed) d.expected_in_odom = confirmed_ref_in_odom_;
    if (push_ref_set_) {  // a resumed task: the pre-outage estimate, not the filter restarted since
      d.expectation_confirmed = true;
      d.expected_in_odom = push_ref_in_odom_;
    }
    // Off the expectation by more than the scene gate: does the room say push or false detection? Against a filter
    // resting on one detection the room is asked too: there the task tests only how far the robot is from the dock,
    // and a first detection at a steep, far view may have put the dock decimetres too near.
    const bool have_expected = d.expectation_confirmed || filter_.initialised();
    if (!d.expectation_confirmed) d.expected_in_odom = filter_.dock_in_odom();
    const Pose2& expected_in_odom = d.expected_in_odom;
    const Pose2 detected_in_odom = odom_pose.compose(last_estimate_.pose);
    const bool off_expectation =
        have_expected &&
        ((Vec2(detected_in_odom.x_m, detected_in_odom.y_m) - Vec2(expected_in_odom.x_m, expected_in_odom.y_m)).norm() >
             kSceneGateM ||
         std::fabs(wrap_angle(detected_in_odom.yaw_rad - expected_in_odom.yaw_rad)) > kSceneGateRad);
    // Where the filter had the dock before something the room overruled restarted it: a detection back there is the
    // dock seen again (the push test leaves it alone unless the room says the robot was moved).
    d.at_overruled_place = off_expectation && overruled_restart_set_ &&
                           check_pose_deviation(detected_in_odom, overruled_restart_from_, 0, 0,
                                                config_.task.deviation) == FaultCode::kNone;
    if (off_expectation && scene_.reference_points() > 0) {
      // The push the detection implies, and the partial readings of it that a noisy detection allows.
      const Real dock_radius_m = estimator_.profile_radius_m() + config_.scene.range_tolerance_m;
      ExpectedDock docks[2] = {{Vec2(expected_in_odom.x_m, expected_in_odom.y_m), dock_radius_m}, {}};
      std::size_t n_docks = 1;
      if (overruled_restart_set_) {
        docks[n_docks++] = {Vec2(overruled_restart_from_.x_m, overruled_restart_from_.y_m), dock_radius_m};
      }
      Pose2 corrections[9];
      std::size_t readings = push_readings(expected_in_odom, detected_in_odom, odom_pose, config_.scene, corrections);
      if (d.expectation_confirmed) {
        d.scene = scene_.judge(scan, lidar_mount_, odom_pose, corrections, readings, config_.scene, nullptr, 0, docks,
                               n_docks);
      } else {
        // The implied push rests on one detection, which may be the wrong one. "Still" must then also beat a shove
        // of the push test's size in each direction and a turn either way: a room that could not show such a push
        // (one long wall along it) gives no verdict, and the distance test stands.
        const Real a = config_.task.deviation.push_distance_tolerance_m;
        const std::size_t pushes = readings;
        for (const Pose2& probe :
             {Pose2{a, 0, 0}, Pose2{-a, 0, 0}, Pose2{0, a, 0}, Pose2{0, -a, 0},
              turn_about(odom_pose, kSceneProbeTurnRad), turn_about(odom_pose, -kSceneProbeTurnRad)}) {
          corrections[readings++] = probe;
        }
        // The probes never make "moved": the room vouches for the one detection only by the push it implies.
        d.scene = scene_.judge(scan, lidar_mount_, odom_pose, corrections, readings, config_.scene, nullptr,
                               readings - pushes, docks, n_docks);
      }
    }
    const Pose2 before = filter_.dock_in_odom();
    const std::uint64_t before_us = filter_.last_update_us();
    if (pending_count_ < kMaxDetectionsPerTick) {
      pending_[pending_count_++] = d;
    } else {
      ++pending_dropped_;  // keep the oldest: a push shows in the first detections after it
    }
    const FilterUpdate u = filter_.update(last_estimate_.pose, last_estimate_.covariance, odom_pose, stamp_us,
                                           last_estimate_.evidence.total_nats);
    // A (re)started filter rests on this one detection, which may be clutter: confirmed once a second detection
    // agrees with it (is fused).
    if (u == FilterUpdate::kInitialised || u == FilterUpdate::kReinitialised) filter_confirmed_ = false;
    // The first look at the dock: the room as odometry puts it, whether or not this detection is right, so that a
    // disagreement before any detection agrees can be judged too. Not when the detection is judged against an older
    // estimate (a resumed task's): the robot may have been pushed since, and this room would be the pushed one.
    if (u == FilterUpdate::kInitialised && !d.expectation_confirmed && scene_.reference_points() == 0) {
      scene_.set_reference(scan, lidar_mount_, odom_pose, config_.scene);
      scene_ref_us_ = stamp_us;
    }
    // Restarted by a detection the room overruled (something else taken for the dock, which may just be hidden):
    // where the filter had the dock stays a place the dock may be hidden at, for the rest of the task.
    if (u == FilterUpdate::kReinitialised && d.expectation_confirmed && d.scene == SceneVerdict::kStill) {
      overruled_restart_set_ = true;
      overruled_restart_from_ = before;
    }
    if (u == FilterUpdate::kReinitialised && was_confirmed) {  // the estimate a resume may still need
      restart_ref_set_ = true;
      restart_ref_in_odom_ = before;
      restart_ref_us_ = before_us;
    }
    if (u == FilterUpdate::kFused) {
      filter_confirmed_ = true;
      confirmed_ref_set_ = true;
      confirmed_ref_in_odom_ = filter_.dock_in_odom();
      confirmed_ref_us_ = stamp_us;
      // A scan whose detection agreed with the expectation shows the room where odometry puts it: the reference
      // for the next off-expectation detection, renewed now and then (the room does not move; odometry drifts).
      if (!off_expectation && (scene_.reference_points() == 0 || stamp_us < scene_ref_us_ ||
                               (stamp_us - scene_ref_us_ >= kSceneReferencePeriodUs &&
                                (stamp_us - scene_ref_us_ >= kSceneReferenceMaxAgeUs ||
                                 4 * SceneCheck::points_kept(scan, config_.scene) >= 3 * scene_.reference_points())))) {
        scene_.set_reference(scan, lidar_mount_, odom_pose, config_.scene);
        scene_ref_us_ = stamp_us;
      }
    }
  }
  return last_estimate_;
}

TagStatus DockcoreBase::on_tag(const TagObservation& obs) {
  const TagFusionParams& p = config_.tag;
  TagStatus st = TagStatus::kFused;
  TagMeasurement m;
  Pose2 odom_at_frame{};  // where the robot was at the frame's stamp, by odometry
  if (p.dock_tag.id < 0 || obs.id != p.dock_tag.id) {
    st = TagStatus::kWrongId;
  } else if (have_tag_ && obs.stamp_us <= last_tag_us_) {
    st = TagStatus::kOutOfOrder;
  } else {
    have_tag_ = true;
    last_tag_us_ = obs.stamp_us;
    const Real lag_s = have_scan_ && last_scan_us_ > obs.stamp_us
                           ? static_cast<Real>(last_scan_us_ - obs.stamp_us) * static_cast<Real>(1e-6)
                           : static_cast<Real>(0);
    bool odometry_gap = false;
    odom_at_frame = odometry_.pose_at(obs.stamp_us, &odometry_gap);
    // A frame taken in a gap of the odometry cannot be placed, as a scan cannot (estimate_scan()).
    if (!(lag_s <= p.max_lag_s) || odometry_gap) {
      st = TagStatus::kStale;
    } else {
      st = tag_to_dock_measurement(obs, p, &m);
    }
  }
  if (st == TagStatus::kFused) {
    const FilterUpdate u = filter_.update_tag(m.dock_in_robot, m.covariance, odom_at_frame, obs.stamp_us);
    if (u == FilterUpdate::kGated) st = TagStatus::kGated;
    if (u == FilterUpdate::kInvalid) st = TagStatus::kInvalid;
    // A filter (re)started by a tag rests on it alone: the push test waits for a second lidar detection.
    if (u == FilterUpdate::kInitialised || u == FilterUpdate::kReinitialised) filter_confirmed_ = false;
  }
  ++tag_counts_[static_cast<std::size_t>(st)];
  return st;
}

TickOutput DockcoreBase::tick(const TickInput& in) {
  check_inputs(in.now_us);
  const TaskState before = tasks_.state();
  TickOutput out;
  // The command of this tick: the oldest queued, else the resume policy's.
  QueuedCommand cmd;
  bool have_cmd = false;
  if (!in.hold_commands && queue_.front() != nullptr) {
    cmd = *queue_.front();
    queue_.pop();
    have_cmd = true;
  } else if (!in.hold_commands && interrupted_.type != HostCommandType::kNone && before == TaskState::kFault &&
             !watch_.hold() &&
             in.now_us - watch_.fresh_since_us() >=
                 static_cast<std::uint64_t>(config_.watchdog.resume_after_ms) * 1000u) {
    if (resumes_ < config_.watchdog.max_resumes) {
      ++resumes_;
      cmd.command = interrupted_;
      cmd.resume = true;
      have_cmd = true;
      out.resume = ResumeEvent::kResumed;
    } else {
      out.resume = ResumeEvent::kGivenUp;
    }
    interrupted_ = HostCommand{};
  }

  TaskInput t;
  t.now_us = in.now_us;
  if (have_cmd) t.command = cmd.command;
  t.odom_pose = odometry_.pose();
  t.odom_twist = odometry_.twist();
  t.camera = in.camera;
  t.contact = in.contact;
  t.charge_current_a = in.charge_current_a;
  t.chassis_ok = watch_.chassis_ok(in.now_us);
  t.lidar_ok = watch_.lidar_ok(in.now_us);
  t.scan = have_scan_ ? &scan_ : nullptr;
  t.lidar_mount = lidar_mount_;
  if (filter_.initialised()) {
    t.dock.valid = true;
    t.dock.pose = filter_.dock_in_robot(t.odom_pose, &t.dock.covariance);
    t.dock.stamp_us = filter_.last_update_us();
    t.dock.confirmed = filter_confirmed_;
  }
  for (std::size_t i = 0; i < pending_count_; ++i) t.detections[i] = pending_[i];
  t.detection_count = pending_count_;
  pending_count_ = 0;

  static_cast<TaskOutput&>(out) = tasks_.tick(t);
  if (out.mount_changed) {
    // The calibration swing moved the lidar: the filter's dock, the room's reference and the push test's references
    // were all placed through the old mount, centimetres off now. The robot stands at the staging distance and the
    // next attempt starts with a search, which the next detection answers.
    take_mount_shift();
    forget_dock();
  }
  observe_drive(in, before, t);
  shape(watch_.hold(), &out);
  // A new dock task: forget the old dock (the robot may have been carried since), so the push test and the
  // controller start from this task's own detections. A resumed one keeps the pre-outage estimate for the push test.
  if (out.status.state == TaskState::kGetTaskingCmd && prev_state_ != TaskState::kGetTaskingCmd) {
    push_ref_set_ = false;
    if (have_cmd && cmd.resume && cmd.command.type == HostCommandType::kDock) {
      // The filter may have restarted at a pushed pose while the task stood in the fault: its estimate from before
      // that restart is the pre-outage one.
      const bool own = filter_.initialised() && filter_confirmed_ && !restart_ref_set_;
      const std::uint64_t ref_us = own ? filter_.last_update_us() : restart_ref_us_;
      if ((own || restart_ref_set_) &&
          (in.now_us <= ref_us ||
           static_cast<Real>(in.now_us - ref_us) * static_cast<Real>(1e-6) <= config_.push_check_max_gap_s)) {
        push_ref_set_ = true;
        push_ref_in_odom_ = own ? filter_.dock_in_odom() : restart_ref_in_odom_;
      }
    }
    forget_dock();
  }
  // A detection in ALIGN agreed with the push test's reference: the reference has done its job (no push), and an
  // earlier restart was no push either (the restarted filter is the reference now). Both end with the task.
  const bool agreed = before == TaskState::kAlign && t.detection_count > 0 && !tasks_.push_suspected() &&
                      out.status.state == TaskState::kAlign;
  const bool ended = out.status.state == TaskState::kNotTasking || out.status.state == TaskState::kFinishTasking;
  if (agreed || ended) {
    push_ref_set_ = false;
    restart_ref_set_ = false;
  }
  if (out.status.state == TaskState::kFault) push_ref_set_ = false;
  prev_state_ = out.status.state;
  resume_policy(before, have_cmd, cmd, &out);
  return out;
}

void DockcoreBase::resume_policy(TaskState before, bool have_cmd, const QueuedCommand& cmd, TickOutput* out) {
  const TaskState after = out->status.state;
  if (have_cmd) {
    out->command_taken = true;
    out->command = cmd;
    const bool accepted =
        out->command_result == CommandResult::kAccepted || out->command_result == CommandResult::kAlreadyDocked;
    if (accepted && !cmd.resume) resumes_ = 0;  // a host's command is a new task
    const HostCommandType type = cmd.command.type;
    if (accepted && (type == HostCommandType::kDock || type == HostCommandType::kUndock)) running_ = cmd.command;
    if (type == HostCommandType::kCancel) {  // a stop forgets the interrupted command too
      running_ = HostCommand{};
      interrupted_ = HostCommand{};
    }
  }
  // A fault caused by stale input while a dock or undock ran remembers it for the resume; any other fault, none.
  if (after == TaskState::kFault && before != TaskState::kFault) {
    const FaultCode f = out->status.fault;
    const bool stale_input = (f == FaultCode::kChassisStale || f == FaultCode::kLidarStale) && watch_.hold();
    interrupted_ = stale_input ? running_ : HostCommand{};
  }
  if (after == TaskState::kNotTasking || after == TaskState::kFinishTasking) running_ = HostCommand{};
  out->resumes = resumes_;
}

void DockcoreBase::observe_drive(const TickInput& in, TaskState state, const TaskInput& t) {
  // A stall may be the drive's deadband only while the robot moves freely: not on the contacts, not with stale
  // feedback, not in a state that stands still, and not with its front (or rear) edge at the dock's face (pressing
  // a misaligned dock is no deadband). A dock beside the robot is not pressed: a robot turned across its face still
  // learns.
  const bool at_dock = t.dock.valid &&
                       std::fabs(t.dock.pose.x_m) - body_front_m(config_.footprint) < kDeadbandDockClearanceM &&
                       std::fabs(t.dock.pose.y_m) < body_half_width_m(config_.footprint);
  const bool learn = is_moving_state(state) && !in.contact && !watch_.hold() && !at_dock;
  // Timed by the feedback's own stamp: ticks that brought no new wheel speeds (a slower chassis, one falling silent
  // before it counts as stale) add no time to a stall.
  deadband_.observe(sent_wheels_, twist_to_wheels(config_.drive, odometry_.twist()), odometry_.stamp_us(),
                    learn && odometry_.stamp_us() > 0);
}

void DockcoreBase::shape(bool hold, TickOutput* out) {
  Twist2 c{};
  const Twist2& want = out->cmd;
  // A zero twist (stop, fault, idle) is sent at once: the drive's own limits do the braking.
  if (!hold && !(want.vx_mps == 0 && want.vy_mps == 0 && want.wz_radps == 0)) {
    c = saturate_twist(config_.drive, config_.limits, want);
    c = limit_acceleration(config_.limits, prev_drive_cmd_, c, config_.control_period_s);
  }
  prev_drive_cmd_ = c;
  // Raised above the wheels' deadband as a whole: the path keeps its curvature and is driven faster, not left
  // unexecuted (the limiter keeps ramping the command the controller asked for).
  const Real s = deadband_.scale(config_.drive, config_.limits, c);
  c = Twist2{c.vx_mps * s, c.vy_mps * s, c.wz_radps * s};
  out->drive_cmd = c;
  out->wheels = twist_to_wheels(config_.drive, c);
  sent_drive_cmd_ = c;
  sent_wheels_ = out->wheels;
}

}  // namespace dockcore
