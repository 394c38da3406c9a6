#include "dockcore/task/task_manager.hpp"

#include <cmath>

namespace dockcore {

const char* to_string(TaskState s) {
  switch (s) {
    case TaskState::kNotTasking: return "NOT_TASKING";
    case TaskState::kGetTaskingCmd: return "GET_TASKING_CMD";
    case TaskState::kReachTaskingPoint: return "REACH_TASKING_POINT";
    case TaskState::kAlign: return "ALIGN";
    case TaskState::kFinishTasking: return "FINISH_TASKING";
    case TaskState::kWaitForCharge: return "WAIT_FOR_CHARGE";
    case TaskState::kRetry: return "RETRY";
    case TaskState::kUndocking: return "UNDOCKING";
    case TaskState::kFault: return "FAULT";
    case TaskState::kTestMode: return "TEST_MODE";
  }
  return "UNKNOWN";
}

const char* to_string(CommandResult r) {
  switch (r) {
    case CommandResult::kNone: return "none";
    case CommandResult::kAccepted: return "accepted";
    case CommandResult::kAlreadyDocked: return "already_docked";
    case CommandResult::kRejectedUnknown: return "rejected_unknown";
    case CommandResult::kRejectedDockId: return "rejected_dock_id";
    case CommandResult::kRejectedNotDocked: return "rejected_not_docked";
    case CommandResult::kRejectedBusy: return "rejected_busy";
  }
  return "unknown";
}

bool is_moving_state(TaskState s) {
  return s == TaskState::kReachTaskingPoint || s == TaskState::kAlign || s == TaskState::kRetry ||
         s == TaskState::kUndocking;
}

namespace {

/// States in which the docking task (started by a dock command) is running: the task timeout applies.
bool is_docking_state(TaskState s) {
  return s == TaskState::kGetTaskingCmd || s == TaskState::kReachTaskingPoint || s == TaskState::kAlign ||
         s == TaskState::kWaitForCharge || s == TaskState::kRetry;
}

bool is_active_state(TaskState s) {
  return s != TaskState::kNotTasking && s != TaskState::kFault && s != TaskState::kTestMode;
}

bool is_zero(const Twist2& t) { return t.vx_mps == 0 && t.vy_mps == 0 && t.wz_radps == 0; }

/// Distance of a pose's origin from the robot's centre (a dock pose in the robot frame), m.
Real distance_m(const Pose2& p) {
  return std::sqrt(p.x_m * p.x_m + p.y_m * p.y_m);
}

}  // namespace

void TaskManager::configure(const TaskParams& params, const FootprintParams& footprint, const DockProfile& profile) {
  params_ = params;
  obstacles_.configure(footprint, &profile);
  state_ = TaskState::kNotTasking;
  fault_ = FaultCode::kNone;
  faulted_in_ = TaskState::kNotTasking;
  last_result_ = TaskResult::kNone;
  last_command_ = CommandResult::kNone;
  retries_ = 0;
  lateral_misses_ = 0;
  pushes_overruled_ = 0;
  for (Real& a : remembered_aim_m_) a = 0;
  phase_ = 0;
  have_prev_tick_ = false;
  calibrate_next_ = calibrating_ = swung_this_task_ = false;
  mount_shift_m_ = Vec2::Zero();
  last_calibration_ = MountCalibrationResult{};
  calibrations_ = 0;
  mount_changed_ = false;
}

TaskLearned TaskManager::learned() const {
  TaskLearned l;
  for (std::size_t i = 0; i < kDockIds; ++i) l.remembered_aim_m[i] = remembered_aim_m_[i];
  l.mount_shift_m = mount_shift_m_;
  l.last_calibration = last_calibration_;
  l.calibrations = calibrations_;
  return l;
}

void TaskManager::restore_learned(const TaskLearned& l) {
  for (std::size_t i = 0; i < kDockIds; ++i) {
    const Real aim = l.remembered_aim_m[i];
    remembered_aim_m_[i] = params_.remember_aim && std::isfinite(aim) ? aim : 0;
  }
  // A shift that is not finite cannot be the one a swing measured: the mount stays as configured, measured again.
  const bool shift_ok = std::isfinite(l.mount_shift_m.x()) && std::isfinite(l.mount_shift_m.y());
  mount_shift_m_ = shift_ok ? l.mount_shift_m : Vec2::Zero();
  last_calibration_ = shift_ok ? l.last_calibration : MountCalibrationResult{};
  calibrations_ = l.calibrations;
}

Real TaskManager::since_s(std::uint64_t t_us, const TaskInput& in) {
  if (in.now_us <= t_us) return 0;
  return static_cast<Real>(in.now_us - t_us) * static_cast<Real>(1e-6);
}

bool TaskManager::dock_fresh(const TaskInput& in) const {
  if (!in.dock.valid) return false;
  const Real age_s = since_s(in.dock.stamp_us, in);
  if (age_s <= params_.target_lost_after_s) return true;
  if (state_ != TaskState::kAlign) return false;
  const Real front_m = obstacles_.body_front_m();
  // The last stretch: odometry carries a confirmed estimate over a few centimetres with sub-millimetre error, while
  // the lidar may see only the dock's face from there.
  if (in.dock.confirmed && age_s <= params_.blind_finish_max_s &&
      std::fabs(in.dock.pose.x_m) - front_m <= params_.blind_finish_m) {
    return true;
  }
  // Far away, odometry carries an estimate over a metre with centimetres of error, less than the lidar's own there,
  // and the next detection on the way in corrects it. ALIGN starts on one detection, confirmed or not: holding still
  // on the view that lost it would not find it again. The same holds for a view from the side.
  if (age_s > params_.blind_approach_max_s) return false;
  if (distance_m(in.dock.pose) - front_m >= params_.blind_approach_m) return true;
  // From the side the dock shows one flank and is refused scan after scan; standing still keeps that view.
  const Pose2 robot = in.dock.pose.inverse();  // the robot in the dock frame
  return std::fabs(std::atan2(robot.y_m, robot.x_m)) >= params_.blind_off_axis_rad;
}

bool TaskManager::in_push_zone(const TaskInput& in) const {
  if (!in.dock.valid) return false;
  const Pose2 robot = in.dock.pose.inverse();  // the robot in the dock frame: x = its centre's distance from the face
  const bool lined_up = std::fabs(std::cos(robot.yaw_rad)) >= static_cast<Real>(0.70710678);  // within 45°
  return lined_up && robot.x_m - obstacles_.body_front_m() <= params_.push_zone_m;
}

bool TaskManager::push_exhausted(const TaskInput& in) {
  if (!pushing_) {
    if (!in_push_zone(in)) return false;
    pushing_ = true;
    push_since_us_ = in.now_us;
    push_prev_odom_ = in.odom_pose;
    push_travel_m_ = 0;
  }
  const Real dx = in.odom_pose.x_m - push_prev_odom_.x_m;
  const Real dy = in.odom_pose.y_m - push_prev_odom_.y_m;
  push_travel_m_ += std::sqrt(dx * dx + dy * dy);
  push_prev_odom_ = in.odom_pose;
  push_elapsed_s_ = since_s(push_since_us_, in);
  return push_travel_m_ > params_.max_push_m || push_elapsed_s_ > params_.max_push_s;
}

void TaskManager::enter(TaskState s, const TaskInput& in) {
  state_ = s;
  state_since_us_ = in.now_us;
  blocked_ = false;
  lost_ = false;
  charge_ok_ = false;
  contact_seen_ = in.contact;
  contact_open_ = false;
  swing_leg_ = 0;
  undock_backing_ = false;
  phase_ = 0;
  want_ = Twist2{};
  calibrating_ = false;
  if (s != TaskState::kRetry) calibrate_next_ = false;
  if (s == TaskState::kReachTaskingPoint) {
    swings_ = 0;
    swing_origin_rad_ = in.odom_pose.yaw_rad;
  }
}

void TaskManager::raise(FaultCode f, const TaskInput& in) {
  fault_ = f;
  faulted_in_ = state_;
  last_result_ = TaskResult::kFaulted;
  enter(TaskState::kFault, in);
}

void TaskManager::handle_command(const TaskInput& in, TaskOutput& out) {
  CommandResult r = CommandResult::kNone;
  switch (in.command.type) {
    case HostCommandType::kNone:
      return;
    case HostCommandType::kDock: {
      const std::uint16_t id = in.command.dock_id;
      if (id >= kDockIds || ((params_.accepted_dock_ids >> id) & 1u) == 0) {
        r = CommandResult::kRejectedDockId;
      } else if (state_ == TaskState::kWaitForCharge || state_ == TaskState::kFinishTasking) {
        r = CommandResult::kAlreadyDocked;
      } else if (state_ == TaskState::kNotTasking || state_ == TaskState::kFault) {
        fault_ = FaultCode::kNone;
        retries_ = 0;
        lateral_misses_ = 0;
        swung_this_task_ = false;
        dock_id_ = id;
        task_since_us_ = in.now_us;
        ctrl_->reset();
        if (in.contact) {
          // Already on the contacts: confirm charging without moving (a failed confirmation retries normally).
          r = CommandResult::kAlreadyDocked;
          enter(TaskState::kWaitForCharge, in);
        } else {
          r = CommandResult::kAccepted;
          enter(TaskState::kGetTaskingCmd, in);
        }
      } else {
        r = CommandResult::kRejectedBusy;
      }
      break;
    }
    case HostCommandType::kCancel:
      r = CommandResult::kAccepted;
      if (state_ != TaskState::kNotTasking) {
        if (state_ != TaskState::kFault) last_result_ = TaskResult::kCancelled;
        fault_ = FaultCode::kNone;
        enter(TaskState::kNotTasking, in);
      }
      break;
    case HostCommandType::kUndock:
      if (state_ == TaskState::kUndocking) {
        r = CommandResult::kAccepted;
      } else if (state_ == TaskState::kWaitForCharge || state_ == TaskState::kFinishTasking ||
                 ((state_ == TaskState::kNotTasking || state_ == TaskState::kFault) && in.contact) ||
                 (state_ == TaskState::kFault && faulted_in_ == TaskState::kUndocking)) {
        // A fault during the back-off (a watchdog hold, an obstacle timeout) leaves the robot between the contacts
        // and the staging point: undock again finishes the back-off (the distance still needed is measured anew),
        // where "not docked" would strand it there.
        r = CommandResult::kAccepted;
        fault_ = FaultCode::kNone;
        enter(TaskState::kUndocking, in);
      } else if (state_ == TaskState::kNotTasking || state_ == TaskState::kFault) {
        r = CommandResult::kRejectedNotDocked;
      } else {
        r = CommandResult::kRejectedBusy;
      }
      break;
    case HostCommandType::kTestMode: {
      // The test runs on the dock it names: the status reports that id, like a docking's.
      const std::uint16_t id = in.command.dock_id;
      if (id >= kDockIds || ((params_.accepted_dock_ids >> id) & 1u) == 0) {
        r = CommandResult::kRejectedDockId;
      } else if (state_ == TaskState::kTestMode && id == dock_id_) {
        r = CommandResult::kAccepted;
      } else if (state_ == TaskState::kNotTasking || state_ == TaskState::kFault) {
        r = CommandResult::kAccepted;
        fault_ = FaultCode::kNone;
        dock_id_ = id;
        enter(TaskState::kTestMode, in);
      } else {
        r = CommandResult::kRejectedBusy;
      }
      break;
    }
    default:
      r = CommandResult::kRejectedUnknown;
      break;
  }
  out.command_result = r;
  last_command_ = r;
}

void TaskManager::start_backoff(const TaskInput& in) {
  backoff_start_ = in.odom_pose;
  if (in.dock.valid) {
    const Real d = distance_m(in.dock.pose);
    backoff_needed_m_ = params_.staging_distance_m > d ? params_.staging_distance_m - d : static_cast<Real>(0);
  } else {
    backoff_needed_m_ = params_.fallback_backoff_m;
  }
}

bool TaskManager::run_backoff(const TaskInput& in) {
  const Real dx = in.odom_pose.x_m - backoff_start_.x_m;
  const Real dy = in.odom_pose.y_m - backoff_start_.y_m;
  if (std::sqrt(dx * dx + dy * dy) >= backoff_needed_m_) return true;
  want_.vx_mps = params_.pads_rear ? params_.backoff_speed_mps : -params_.backoff_speed_mps;
  return false;
}

void TaskManager::fail_attempt(FaultCode final_fault, const TaskInput& in, bool lateral_miss) {
  retry_reason_ = final_fault;
  const bool missed = lateral_miss || missed_contacts(final_fault);
  if (missed && lateral_misses_ < 255) ++lateral_misses_;
  pending_fault_ = retries_ >= params_.max_retries ? final_fault : FaultCode::kNone;
  enter(TaskState::kRetry, in);
  start_backoff(in);
  // A miss beside the contacts is what a lidar mounted off its configured pose causes: measure it before the next
  // attempt. Once per task, and not again after a swing that measured: the bracket does not move, and later misses
  // have other causes (the lidar's turn, the dock's installation), which the search and the remembered aim answer.
  calibrate_next_ = missed && params_.calibrate_mount && !swung_this_task_ &&
                    last_calibration_.status != MountCalibrationStatus::kOk && pending_fault_ == FaultCode::kNone;
}

void TaskManager::run_reach(const TaskInput& in) {
  if (dock_fresh(in)) {
    start_distance_m_ = distance_m(in.dock.pose);
    suspects_ = 0;
    pushing_ = false;
    push_travel_m_ = 0;
    push_elapsed_s_ = 0;
    ctrl_->reset();
    enter(TaskState::kAlign, in);
    return;
  }
  if (swing_leg_ == 0) {
    if (since_s(state_since_us_, in) < params_.detect_wait_s) return;
    swing_leg_ = 1;
  }
  if (!swing(swing_origin_rad_, params_.swing_amplitude_rad, &swing_leg_, in)) return;
  ++swings_;
  if (swings_ >= params_.max_swings) {
    raise(FaultCode::kDetectionFailed, in);
    return;
  }
  swing_leg_ = 1;  // the next swing, after this still tick
}

bool TaskManager::swing(Real origin_rad, Real amplitude_rad, std::uint8_t* leg, const TaskInput& in) {
  const Real target = origin_rad + (*leg == 1 ? amplitude_rad : (*leg == 2 ? -amplitude_rad : static_cast<Real>(0)));
  const Real err = wrap_angle(target - in.odom_pose.yaw_rad);
  if (std::fabs(err) <= params_.swing_tolerance_rad) {
    if (*leg >= 3) return true;
    ++*leg;
    return false;  // one still tick between legs: the new leg's direction starts next tick
  }
  want_.wz_radps = err > 0 ? params_.swing_speed_radps : -params_.swing_speed_radps;
  return false;
}

bool TaskManager::test_detection(const DetectionInput& det, const TaskInput& in) {
  if (!det.fresh) return false;
  const Pose2 detected = det.odom_at_scan.compose(det.dock_in_robot);
  // An unconfirmed filter rests on one detection: disagreeing with it is no evidence of a push, so only the
  // distance limit is tested (expected = detected) — unless the room moved as the detection implies: then the one
  // detection was right and the robot was moved (a push early in ALIGN, before a second look confirmed the dock).
  Pose2 expected = detected;
  if (det.expectation_set) {
    if (det.expectation_confirmed || det.scene == SceneVerdict::kMoved) expected = det.expected_in_odom;
  } else if (in.dock.valid && in.dock.confirmed) {
    expected = in.odom_pose.compose(in.dock.pose);
  } else if (!in.dock.valid) {
    return false;
  }
  const Pose2& d = det.dock_in_robot;
  const Real dist = distance_m(d);
  const FaultCode f = check_pose_deviation(detected, expected, dist, start_distance_m_, params_.deviation);
  if (f == FaultCode::kNone) {
    suspects_ = 0;
    return false;
  }
  // The room stands where odometry puts it, so the robot was not moved: the detection is something else taken for
  // the dock (furniture beside it, while the dock is hidden). It neither counts towards a push nor clears one.
  if (det.scene == SceneVerdict::kStill) {
    ++pushes_overruled_;
    // With the robot where odometry puts it, a detection farther than the start's distance is no push away: the
    // start's distance came from a wrong first look (against a filter resting on it, only the distance was tested),
    // or from clutter a confirmed filter followed before this detection restarts it. It is the start's now.
    if (dist > start_distance_m_) start_distance_m_ = dist;
    return false;
  }
  // The room moved as this detection implies (SceneCheck): the push is seen, and needs no second look. A robot
  // shoved so that it sees the dock only from the side may not get one.
  if (det.scene == SceneVerdict::kMoved) {
    raise(f, in);
    return true;
  }
  // The dock back where it stood before furniture was taken for it while it was hidden, in a room too bare to say
  // whether the robot moved: the filter followed the furniture, not the robot a push.
  if (det.at_overruled_place) {
    ++pushes_overruled_;
    return false;
  }
  // A push moves every later detection to the same new place; an outlier is alone. Count only failing
  // detections that agree with an earlier failing one (same tolerances as the push test itself). Two places are
  // kept: a lone outlier between two detections of a pushed robot (sparse at range) starts a place of its own
  // instead of replacing the push's.
  const auto agrees = [&](const Pose2& place) {
    return check_pose_deviation(detected, place, static_cast<Real>(0), start_distance_m_, params_.deviation) ==
           FaultCode::kNone;
  };
  std::size_t at = 0;
  while (at < suspects_ && !agrees(suspect_pose_[at])) ++at;
  std::uint8_t count = 1;
  if (at < suspects_) {
    count = suspect_count_[at] < 255 ? static_cast<std::uint8_t>(suspect_count_[at] + 1) : suspect_count_[at];
  } else if (suspects_ < kPushSuspects) {
    ++suspects_;
  } else {
    at = 0;  // the oldest place gives way
  }
  // The place just seen becomes the newest.
  for (std::size_t i = at; i + 1 < suspects_; ++i) {
    suspect_pose_[i] = suspect_pose_[i + 1];
    suspect_count_[i] = suspect_count_[i + 1];
  }
  suspect_pose_[suspects_ - 1] = detected;
  suspect_count_[suspects_ - 1] = count;
  if (count >= params_.deviation.confirm_detections) {
    raise(f, in);
    return true;
  }
  return false;
}

Real TaskManager::retry_lateral_offset_m() const {
  // The first miss is retried on the axis (a transient cause: a stall, a bump, a late estimate); misses 2, 3, 4, 5 ...
  // aim at +1, -1, +2, -2 ... steps beside it.
  if (lateral_misses_ < 2) return static_cast<Real>(0);
  const int j = lateral_misses_ - 1;
  const int steps = (j + 1) / 2;  // 1, 1, 2, 2, ...
  const Real offset_m = static_cast<Real>(steps) * params_.retry_lateral_step_m;
  return j % 2 == 1 ? offset_m : -offset_m;
}

Real TaskManager::attempt_aim_m() const {
  return remembered_aim_m_[dock_id_] + retry_lateral_offset_m();  // dock_id_ < kDockIds: only accepted ids run
}

void TaskManager::run_align(const TaskInput& in, TaskOutput& out) {
  // Every detection since the last tick, in order: a push followed by a stall shows only in the first scans of the
  // backlog (the later ones may already have restarted the filter at the pushed pose).
  const std::size_t n = in.detection_count < kMaxDetectionsPerTick ? in.detection_count : kMaxDetectionsPerTick;
  for (std::size_t i = 0; i < n; ++i) {
    if (test_detection(in.detections[i], in)) return;
  }
  ControlInput ci;
  ci.now_us = in.now_us;
  ci.dt_s = dt_s_;
  ci.dock_valid = in.dock.valid;
  ci.dock_confirmed = in.dock.confirmed;
  ci.dock_in_robot = in.dock.pose;
  ci.aim_lateral_m = attempt_aim_m();
  ci.dock_covariance = in.dock.covariance;
  ci.dock_stamp_us = in.dock.stamp_us;
  ci.odom_pose = in.odom_pose;
  ci.measured_twist = in.odom_twist;
  ci.camera = in.camera;
  ci.scan = in.scan;
  ci.lidar_mount = in.lidar_mount;
  ci.contact = in.contact;
  ci.charging = in.contact && in.charge_current_a >= params_.charge_current_threshold_a;
  const ControlOutput co = ctrl_->step(ci);
  out.control = co.status;
  phase_ = co.phase;
  if (co.status == ControlStatus::kArrived) {
    enter(TaskState::kWaitForCharge, in);
    return;
  }
  if (co.status == ControlStatus::kFailed) {
    fail_attempt(FaultCode::kAlignFailed, in);
    return;
  }
  // The final push is bounded in distance and time: a robot held short of the contacts, or slipping, would
  // otherwise push on (the deadband learning raising its command) until the task timeout.
  if (push_exhausted(in)) {
    fail_attempt(FaultCode::kContactsNotReached, in);
    return;
  }
  if (!dock_fresh(in) || co.status == ControlStatus::kLost) {
    if (!lost_) {
      lost_ = true;
      lost_since_us_ = in.now_us;
    }
    if (since_s(lost_since_us_, in) > params_.target_lost_timeout_s) {
      // Lost in the final push: the robot stands at the dock's face without the contacts, a miss the retry's
      // sideways search answers; lost anywhere else, the dock is gone.
      if (pushing_) {
        fail_attempt(FaultCode::kContactsNotReached, in);
      } else {
        raise(FaultCode::kTargetLost, in);
      }
      return;
    }
    hold_ = true;
    out.target_lost = true;
    return;
  }
  lost_ = false;
  want_ = co.cmd;
}

void TaskManager::run_wait_for_charge(const TaskInput& in) {
  contact_seen_ = contact_seen_ || in.contact;
  if (in.contact && in.charge_current_a >= params_.charge_current_threshold_a) {
    if (!charge_ok_) {
      charge_ok_ = true;
      charge_ok_since_us_ = in.now_us;
    }
    if (since_s(charge_ok_since_us_, in) >= params_.charge_confirm_hold_s) {
      // A docking that began on the contacts (no attempt, no search) stores the aim it already had.
      if (params_.remember_aim) {
        remembered_aim_m_[dock_id_] = attempt_aim_m();
        lateral_misses_ = 0;  // the aim that closed them is now the dock's aim, not an offset from it
      }
      last_result_ = TaskResult::kDocked;
      enter(TaskState::kFinishTasking, in);
      return;
    }
  } else {
    charge_ok_ = false;
  }
  if (since_s(state_since_us_, in) > params_.charge_confirm_timeout_s) {
    // Contacts closed without a charge held: the charger (dead, unpowered, or a poor contact). Contacts that never
    // closed (a controller arriving by its own test alone): the robot is not on them. Contacts that closed and did
    // not stay closed: the pads at the edge of the contacts' window, a miss the sideways search counts.
    fail_attempt(contact_seen_ ? FaultCode::kChargeNotConfirmed : FaultCode::kContactsNotReached, in,
                 contact_seen_ && !in.contact);
  }
}

void TaskManager::run_finish(const TaskInput& in) {
  if (in.contact) {
    contact_open_ = false;
    return;
  }
  if (!contact_open_) {
    contact_open_ = true;
    contact_open_since_us_ = in.now_us;
  }
  if (since_s(contact_open_since_us_, in) > params_.contact_lost_debounce_s) raise(FaultCode::kContactsLost, in);
}

void TaskManager::run_retry(const TaskInput& in) {
  if (calibrating_) {
    run_calibration(in);
    return;
  }
  if (run_backoff(in)) {
    want_ = Twist2{};
    if (pending_fault_ != FaultCode::kNone) {
      // The search around the remembered aim did not find the contacts: the next docking starts on the axis again.
      if (missed_contacts(pending_fault_)) remembered_aim_m_[dock_id_] = 0;
      raise(pending_fault_, in);
      return;
    }
    if (calibrate_next_) {
      calibrate_next_ = false;
      start_calibration(in);
      return;
    }
    next_attempt(in);
    return;
  }
  if (since_s(state_since_us_, in) > params_.backoff_timeout_s) raise(retry_reason_, in);
}

void TaskManager::next_attempt(const TaskInput& in) {
  ++retries_;
  ctrl_->reset();
  enter(TaskState::kReachTaskingPoint, in);
}

void TaskManager::start_calibration(const TaskInput& in) {
  swung_this_task_ = true;
  calibrating_ = true;
  calibration_leg_ = 1;
  calibration_origin_rad_ = in.odom_pose.yaw_rad;
  calibration_since_us_ = in.now_us;
  calibration_.begin(in.lidar_mount, in.odom_pose);
  phase_ = 1;
}

void TaskManager::run_calibration(const TaskInput& in) {
  const std::size_t n = in.detection_count < kMaxDetectionsPerTick ? in.detection_count : kMaxDetectionsPerTick;
  const Pose2 lidar_in_robot_inverse = in.lidar_mount.inverse();
  for (std::size_t i = 0; i < n; ++i) {
    const DetectionInput& d = in.detections[i];
    if (d.fresh) calibration_.add(lidar_in_robot_inverse.compose(d.dock_in_robot), d.odom_at_scan);
  }
  // An obstacle stopped the turn (the previous tick), or the drive is far slower than asked: measure nothing rather
  // than wait for the obstacle timeout on a swing the docking does not need.
  const Real a = params_.calibration_swing_rad;
  const Real nominal_s = params_.swing_speed_radps > 0 ? 4 * a / params_.swing_speed_radps : static_cast<Real>(0);
  if (blocked_ || since_s(calibration_since_us_, in) > 3 * nominal_s + static_cast<Real>(2)) {
    MountCalibrationResult r;
    r.status = MountCalibrationStatus::kInterrupted;
    r.mount = in.lidar_mount;
    r.detections = calibration_.detections();
    end_calibration(r, in);
    return;
  }
  if (swing(calibration_origin_rad_, a, &calibration_leg_, in)) {
    end_calibration(calibration_.solve(params_.max_mount_correction_m), in);
  }
}

void TaskManager::end_calibration(const MountCalibrationResult& result, const TaskInput& in) {
  calibrating_ = false;
  last_calibration_ = result;
  ++calibrations_;
  if (result.status == MountCalibrationStatus::kOk) {
    mount_shift_m_ += Vec2(result.mount.x_m - in.lidar_mount.x_m, result.mount.y_m - in.lidar_mount.y_m);
    mount_changed_ = true;
    // The remembered aims answered the old mount's error.
    for (Real& aim : remembered_aim_m_) aim = 0;
  }
  next_attempt(in);
}

void TaskManager::run_undocking(const TaskInput& in) {
  if (!undock_backing_) {
    if (!params_.charger_switched || in.charge_current_a < params_.charge_current_threshold_a) {
      undock_backing_ = true;
      backoff_since_us_ = in.now_us;
      start_backoff(in);
    } else {
      if (since_s(state_since_us_, in) > params_.charge_off_timeout_s) raise(FaultCode::kUndockFailed, in);
      return;
    }
  }
  if (run_backoff(in)) {
    want_ = Twist2{};
    if (in.charge_current_a >= params_.charge_current_threshold_a) {
      raise(FaultCode::kUndockFailed, in);  // backed off, yet current flows: the robot is not where it thinks
      return;
    }
    last_result_ = TaskResult::kUndocked;
    enter(TaskState::kNotTasking, in);
    return;
  }
  if (since_s(backoff_since_us_, in) > params_.backoff_timeout_s) raise(FaultCode::kUndockFailed, in);
}

TaskOutput TaskManager::tick(const TaskInput& in) {
  TaskOutput out;
  dt_s_ = params_.nominal_dt_s;
  if (have_prev_tick_ && in.now_us > prev_tick_us_) dt_s_ = static_cast<Real>(in.now_us - prev_tick_us_) * static_cast<Real>(1e-6);
  have_prev_tick_ = true;
  prev_tick_us_ = in.now_us;
  want_ = Twist2{};
  hold_ = false;

  handle_command(in, out);

  if (is_active_state(state_)) {
    if (!in.chassis_ok) {
      raise(FaultCode::kChassisStale, in);
    } else if (!in.lidar_ok && (is_moving_state(state_) || state_ == TaskState::kGetTaskingCmd)) {
      raise(FaultCode::kLidarStale, in);
    } else if (is_docking_state(state_) && since_s(task_since_us_, in) > params_.task_timeout_s) {
      raise(FaultCode::kTaskTimeout, in);
    }
  }

  switch (state_) {
    case TaskState::kGetTaskingCmd:
      // Visible for the tick the command arrived on; the search starts on the next.
      if (state_since_us_ != in.now_us) enter(TaskState::kReachTaskingPoint, in);
      break;
    case TaskState::kReachTaskingPoint: run_reach(in); break;
    case TaskState::kAlign: run_align(in, out); break;
    case TaskState::kWaitForCharge: run_wait_for_charge(in); break;
    case TaskState::kFinishTasking: run_finish(in); break;
    case TaskState::kRetry: run_retry(in); break;
    case TaskState::kUndocking: run_undocking(in); break;
    case TaskState::kNotTasking:
    case TaskState::kFault:
    case TaskState::kTestMode:
      break;
  }

  emit(in, out);
  out.mount_changed = mount_changed_;
  mount_changed_ = false;
  return out;
}

void TaskManager::emit(const TaskInput& in, TaskOutput& out) {
  Twist2 cmd{};
  if (is_moving_state(state_) && !hold_) {
    cmd.vx_mps = clamp_abs(want_.vx_mps, params_.max_vx_mps);
    cmd.vy_mps = clamp_abs(want_.vy_mps, params_.max_vy_mps);
    cmd.wz_radps = clamp_abs(want_.wz_radps, params_.max_wz_radps);
    if (!std::isfinite(cmd.vx_mps) || !std::isfinite(cmd.vy_mps) || !std::isfinite(cmd.wz_radps)) cmd = Twist2{};
  }
  if (!is_zero(cmd)) {
    if (in.scan != nullptr) {
      out.obstacles = obstacles_.check(*in.scan, in.lidar_mount, in.dock.valid ? &in.dock.pose : nullptr);
    }
    cmd = permitted_motion(cmd, out.obstacles, params_.gate, params_.turn_when_blocked, &out.blocked);
    if (out.blocked) {
      if (!blocked_) {
        blocked_ = true;
        blocked_since_us_ = in.now_us;
      } else if (since_s(blocked_since_us_, in) > params_.obstacle_timeout_s) {
        raise(FaultCode::kObstacleTimeout, in);
      }
    } else {
      blocked_ = false;
    }
  } else if (!hold_) {
    blocked_ = false;
  }
  out.cmd = cmd;

  TaskStatus& s = out.status;
  s.state = state_;
  s.phase = state_ == TaskState::kAlign || calibrating_ ? phase_ : static_cast<std::uint8_t>(0);
  s.fault = fault_;
  s.retries = retries_;
  s.retry_reason = state_ == TaskState::kRetry ? retry_reason_ : FaultCode::kNone;
  s.dock_valid = dock_fresh(in);
  s.dock_pose = in.dock.pose;
  s.charge_enable = state_ == TaskState::kWaitForCharge || state_ == TaskState::kFinishTasking;
  s.aim_lateral_m = attempt_aim_m();
  s.last_command = last_command_;
  s.last_result = last_result_;
  s.dock_id = dock_id_;
}

}  // namespace dockcore
