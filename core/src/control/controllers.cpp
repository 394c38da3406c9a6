#include "dockcore/control/controllers.hpp"

#include <cmath>
#include <cstring>

namespace dockcore {
namespace {

constexpr Real kZero = 0;
constexpr Real kOne = 1;
constexpr Real kHalfPi = kPi / static_cast<Real>(2);

Real sign_of(Real v) { return v < 0 ? -kOne : kOne; }

// |v| clamped into [lo, hi], sign kept (v == 0 stays 0).
Real clamp_mag(Real v, Real lo, Real hi) {
  if (v == 0) return 0;
  Real a = std::fabs(v);
  if (a < lo) a = lo;
  if (a > hi) a = hi;
  return sign_of(v) * a;
}

ControlOutput stopped(ControlStatus s, std::uint8_t phase) {
  ControlOutput o;
  o.status = s;
  o.phase = phase;
  return o;
}

// Robot pose in the dock frame and the pads' position there (front pads at body (reach, 0)).
struct DockView {
  Pose2 robot;  // robot centre and heading in the dock frame
  Vec2 pad;     // pads' centre in the dock frame: x = distance in front of the contact plane, y = lateral error
};

DockView view_of(const ControlInput& in, Real pad_x_body) {
  DockView v;
  v.robot = in.dock_in_robot.inverse();
  v.pad = v.robot.transform(Vec2(pad_x_body, 0));
  return v;
}

// Updates the stall timer; true once the pads have sat past the plane for the timeout without contact. Sticky: the
// caller checks stall_s >= timeout before anything else.
bool stalled(const DockingCommonParams& c, Real pad_x_m, Real dt_s, Real* stall_s) {
  if (pad_x_m <= c.stall_press_m) {
    *stall_s += dt_s;
  } else {
    *stall_s = 0;
  }
  return *stall_s >= c.stall_timeout_s;
}

// The checks every controller makes before its own law, in this order: contact ends the run (arrived, sticky), a
// stall that timed out stays failed, and a missing or non-finite estimate is "lost" when the controller needs one.
// kRunning means carry on.
ControlStatus common_guard(const ControlInput& in, bool docked, Real stall_s, const DockingCommonParams& c,
                           bool needs_dock) {
  if (docked || in.contact) return ControlStatus::kArrived;
  if (stall_s >= c.stall_timeout_s) return ControlStatus::kFailed;
  if (needs_dock && (!in.dock_valid || !finite_pose(in.dock_in_robot))) return ControlStatus::kLost;
  return ControlStatus::kRunning;
}

Real positive_dt(const ControlInput& in) { return (in.dt_s > 0 && std::isfinite(in.dt_s)) ? in.dt_s : kZero; }

}  // namespace

// ===================================================================================================== seed000 ========

const char* Seed000Controller::phase_name(std::uint8_t phase) const {
  switch (phase) {
    case 0: return "ROTATE";
    case 1: return "DRIVE";
    case 2: return "DOCKED";
    default: return "UNKNOWN";
  }
}

void Seed000Controller::reset() {
  phase_ = Seed000Phase::kRotate;
  stall_s_ = 0;
}

ControlOutput Seed000Controller::step(const ControlInput& in) {
  const DockingCommonParams& c = p_.common;
  const ControlStatus guard = common_guard(in, phase_ == Seed000Phase::kDocked, stall_s_, c, true);
  if (guard == ControlStatus::kArrived) phase_ = Seed000Phase::kDocked;
  if (guard != ControlStatus::kRunning) return stopped(guard, static_cast<std::uint8_t>(phase_));
  const DockView dv = view_of(in, c.pad_reach_m);
  if (stalled(c, dv.pad.x(), positive_dt(in), &stall_s_)) {
    return stopped(ControlStatus::kFailed, static_cast<std::uint8_t>(phase_));
  }
  const Real bx = in.dock_in_robot.x_m;
  const Real by = in.dock_in_robot.y_m;
  const Real bearing = std::atan2(by, bx);
  ControlOutput o;
  if (phase_ == Seed000Phase::kDrive && std::fabs(bearing) > p_.angle_threshold_rad) phase_ = Seed000Phase::kRotate;
  if (phase_ == Seed000Phase::kRotate && std::fabs(bearing) < p_.rotate_exit_rad) phase_ = Seed000Phase::kDrive;
  if (phase_ == Seed000Phase::kRotate) {
    o.cmd.wz_radps = clamp_mag(p_.rotate_kp * bearing, p_.rotate_min_radps, p_.rotate_max_radps);
  } else {
    // Pad-to-contact distance along the line of sight (the seed drives straight at the centre).
    const Real dist = std::sqrt(bx * bx + by * by) - c.pad_reach_m;
    Real v = p_.forward_speed_mps;
    if (p_.slowdown_distance_m > 0 && dist < p_.slowdown_distance_m) {
      v = p_.forward_speed_mps * (dist > 0 ? dist : kZero) / p_.slowdown_distance_m;
    }
    if (v < c.creep_speed_mps) v = c.creep_speed_mps;
    o.cmd.vx_mps = v;
  }
  o.phase = static_cast<std::uint8_t>(phase_);
  return o;
}

// ===================================================================================================== seed004 ========

const char* Seed004Controller::phase_name(std::uint8_t phase) const {
  switch (phase) {
    case 0: return "READY";
    case 1: return "POSITION";
    case 2: return "ROTATE";
    case 3: return "LATERAL";
    case 4: return "LATERAL_ORI_CONFIRM";
    case 5: return "LATERAL_ROTATE";
    case 6: return "FRONT_BACK_ORI_CONFIRM";
    case 7: return "FRONT_BACK";
    case 8: return "FINISH";
    case 9: return "FINAL_APPROACH";
    case 10: return "DOCKED";
    default: return "UNKNOWN";
  }
}

void Seed004Controller::reset() {
  phase_ = Seed004Phase::kReady;
  target_yaw_rad_ = 0;
  stall_s_ = 0;
}

Real Seed004Controller::turn_rate(Real err_rad) const {
  return clamp_mag(p_.angle_kp * err_rad, p_.min_wz_radps, p_.max_wz_radps);
}

Real Seed004Controller::drive_speed(Real err_m, Real max_mps) const {
  return clamp_mag(p_.distance_kp * err_m, p_.min_speed_mps, max_mps);
}

ControlOutput Seed004Controller::step(const ControlInput& in) {
  const DockingCommonParams& c = p_.common;
  const ControlStatus guard = common_guard(in, phase_ == Seed004Phase::kDocked, stall_s_, c, true);
  if (guard == ControlStatus::kArrived) phase_ = Seed004Phase::kDocked;
  if (guard != ControlStatus::kRunning) return stopped(guard, static_cast<std::uint8_t>(phase_));
  const DockView dv = view_of(in, c.pad_reach_m);
  if (stalled(c, dv.pad.x(), positive_dt(in), &stall_s_)) {
    return stopped(ControlStatus::kFailed, static_cast<std::uint8_t>(phase_));
  }
  const Real x = dv.robot.x_m;
  const Real y = dv.robot.y_m;
  const Real th = dv.robot.yaw_rad;
  ControlOutput o;
  o.phase = static_cast<std::uint8_t>(phase_);  // the phase this tick acted in
  switch (phase_) {
    case Seed004Phase::kReady:
      // Parallel to the dock face: the one of ±π/2 nearer to the current heading.
      target_yaw_rad_ = std::fabs(wrap_angle(th - kHalfPi)) <= std::fabs(wrap_angle(th + kHalfPi)) ? kHalfPi : -kHalfPi;
      phase_ = Seed004Phase::kPosition;
      break;
    case Seed004Phase::kPosition:
      phase_ = std::fabs(y) > p_.robot_distance_tolerance_m ? Seed004Phase::kRotate : Seed004Phase::kFrontBackOriConfirm;
      break;
    case Seed004Phase::kRotate:
    case Seed004Phase::kLateralRotate: {
      const Real err = wrap_angle(target_yaw_rad_ - th);
      if (std::fabs(err) < p_.angle_tolerance_rad) {
        phase_ = phase_ == Seed004Phase::kRotate ? Seed004Phase::kLateral : Seed004Phase::kFrontBackOriConfirm;
      } else {
        o.cmd.wz_radps = turn_rate(err);
      }
      break;
    }
    case Seed004Phase::kLateral: {
      if (std::fabs(y) < p_.distance_tolerance_m) {
        phase_ = Seed004Phase::kLateralOriConfirm;
      } else {
        // Forward travel that brings y to 0 along the current (≈ ±π/2) heading.
        o.cmd.vx_mps = drive_speed(-y * std::sin(th), p_.max_speed_mps);
      }
      break;
    }
    case Seed004Phase::kLateralOriConfirm:
      target_yaw_rad_ = std::atan2(-y, -x);  // face the dock origin (the marker's centre)
      phase_ = Seed004Phase::kLateralRotate;
      break;
    case Seed004Phase::kFrontBackOriConfirm:
      phase_ = Seed004Phase::kFrontBack;
      break;
    case Seed004Phase::kFrontBack: {
      const Real err = x - p_.relative_distance_m;
      if (std::fabs(err) < p_.distance_tolerance_m) {
        phase_ = Seed004Phase::kFinish;
      } else {
        o.cmd.vx_mps = drive_speed(-err * std::cos(th), p_.max_speed_mps);
      }
      break;
    }
    case Seed004Phase::kFinish:
      phase_ = Seed004Phase::kFinalApproach;
      break;
    case Seed004Phase::kFinalApproach: {
      const Real d = dv.pad.x() > 0 ? dv.pad.x() : kZero;
      Real v = p_.distance_kp * d;
      if (v > p_.final_speed_mps) v = p_.final_speed_mps;
      if (v < c.creep_speed_mps) v = c.creep_speed_mps;
      o.cmd.vx_mps = v;
      // Heading hold only: below the turn floor the command is left small (a straight creep, as the seed would).
      o.cmd.wz_radps = clamp_abs(p_.final_heading_kp * wrap_angle(kPi - th), p_.max_wz_radps);
      break;
    }
    case Seed004Phase::kDocked:
      break;
  }
  return o;
}

// ===================================================================================================== seed003 ========

const char* Seed003Controller::phase_name(std::uint8_t phase) const {
  switch (phase) {
    case 0: return "STAGE1";
    case 1: return "STAGE2";
    case 2: return "SEED_SUCCESS";
    case 3: return "FINAL_APPROACH";
    case 4: return "DOCKED";
    default: return "UNKNOWN";
  }
}

void Seed003Controller::reset() {
  phase_ = Seed003Phase::kStage1;
  win_n_ = win_head_ = 0;
  x_f_ = z_f_ = 0;
  have_prev_err_ = false;
  prev_ez_ = prev_ex_ = prev_eu_ = 0;
  success_held_s_ = 0;
  seed_success_ = false;
  final_start_ = Pose2{};
  stall_s_ = 0;
}

bool Seed003Controller::lidar_range(const ControlInput& in, Real u_px, Real* z_m) const {
  if (in.scan == nullptr || in.scan->count == 0 || in.scan->ranges_m == nullptr) return false;
  const ScanView& s = *in.scan;
  if (!(std::fabs(s.angle_increment_rad) > 0)) return false;
  const Real cam_bearing = -std::atan((u_px - p_.camera.cx_px) / p_.camera.fx_px);
  Real rel = p_.camera.mount.yaw_rad + cam_bearing - in.lidar_mount.yaw_rad - s.angle_min_rad;
  if (s.wraps()) {
    rel = std::remainder(rel, kTwoPi);
    if (rel * s.angle_increment_rad < 0) rel += s.angle_increment_rad > 0 ? kTwoPi : -kTwoPi;
  } else {
    rel = wrap_angle(rel);
  }
  const Real fi = rel / s.angle_increment_rad;
  if (!(fi > static_cast<Real>(-0.5)) || !(fi < static_cast<Real>(s.count) - static_cast<Real>(0.5))) {
    if (!s.wraps()) return false;
  }
  const long n = static_cast<long>(s.count);
  const long i0 = static_cast<long>(std::lround(fi));
  // The beam itself, else the nearest valid neighbour within two beams (the seed reads one index; dropouts happen).
  const long order[5] = {0, 1, -1, 2, -2};
  for (long k : order) {
    long i = i0 + k;
    if (s.wraps()) {
      i %= n;
      if (i < 0) i += n;
    } else if (i < 0 || i >= n) {
      continue;
    }
    const Real r = s.ranges_m[static_cast<std::size_t>(i)];
    if (is_valid_range(r)) {
      *z_m = r;
      return true;
    }
  }
  return false;
}

ControlOutput Seed003Controller::step(const ControlInput& in) {
  const DockingCommonParams& c = p_.common;
  // Seed 003 steers on the camera target, so a missing dock estimate is not "lost" here.
  const ControlStatus guard = common_guard(in, phase_ == Seed003Phase::kDocked, stall_s_, c, false);
  if (guard == ControlStatus::kArrived) phase_ = Seed003Phase::kDocked;
  if (guard != ControlStatus::kRunning) return stopped(guard, static_cast<std::uint8_t>(phase_));
  const Real dt = positive_dt(in);
  const Real cx = p_.camera.cx_px;
  const bool fresh = in.camera.valid && std::isfinite(in.camera.u_px) && in.camera.stamp_us <= in.now_us &&
                     static_cast<Real>(in.now_us - in.camera.stamp_us) * static_cast<Real>(1e-6) <= p_.target_timeout_s;

  if (phase_ == Seed003Phase::kSeedSuccess) {
    final_start_ = in.odom_pose;
    phase_ = Seed003Phase::kFinalApproach;
  }
  if (phase_ == Seed003Phase::kFinalApproach) {
    // Stall: odometry says we are not moving although commanded.
    if (std::fabs(in.measured_twist.vx_mps) < static_cast<Real>(0.25) * c.creep_speed_mps) {
      stall_s_ += dt;
    } else {
      stall_s_ = 0;
    }
    const Real dx = in.odom_pose.x_m - final_start_.x_m;
    const Real dy = in.odom_pose.y_m - final_start_.y_m;
    if (stall_s_ >= c.stall_timeout_s || std::sqrt(dx * dx + dy * dy) > p_.final_max_travel_m) {
      stall_s_ = c.stall_timeout_s;
      return stopped(ControlStatus::kFailed, static_cast<std::uint8_t>(phase_));
    }
    ControlOutput o;
    o.phase = static_cast<std::uint8_t>(phase_);
    o.cmd.vx_mps = p_.final_speed_mps > c.creep_speed_mps ? p_.final_speed_mps : c.creep_speed_mps;
    // Keep gazing while the camera still sees the target; blind (too close) = straight on.
    if (fresh) o.cmd.wz_radps = clamp_abs(p_.u_kp * (cx - in.camera.u_px), p_.u_max_radps);
    return o;
  }

  if (!fresh) return stopped(ControlStatus::kLost, static_cast<std::uint8_t>(phase_));
  const Real u = in.camera.u_px;
  Real z_raw = 0;
  if (!lidar_range(in, u, &z_raw)) {
    if (win_n_ == 0) return stopped(ControlStatus::kLost, static_cast<std::uint8_t>(phase_));
    z_raw = z_f_;  // hold the last fused range (the seed keeps its last coordinates)
  }
  const Real x_raw = (u - cx) * z_raw / p_.camera.fx_px;
  std::size_t w = p_.window;
  if (w < 1) w = 1;
  if (w > kSeed003MaxWindow) w = kSeed003MaxWindow;
  win_x_[win_head_] = x_raw;
  win_z_[win_head_] = z_raw;
  win_head_ = (win_head_ + 1) % w;
  if (win_n_ < w) ++win_n_;
  Real sx = 0;
  Real sz = 0;
  for (std::size_t i = 0; i < win_n_; ++i) {
    sx += win_x_[i];
    sz += win_z_[i];
  }
  const Real inv_n = kOne / static_cast<Real>(win_n_);
  x_f_ = p_.ema_alpha * x_raw + (kOne - p_.ema_alpha) * sx * inv_n;
  z_f_ = p_.ema_alpha * z_raw + (kOne - p_.ema_alpha) * sz * inv_n;

  const Real ez = z_f_ - p_.goal_z_m;
  const Real ex = x_f_;
  const Real eu = cx - u;
  const Real dscale = dt > 0 ? p_.seed_period_s / dt : kZero;
  const Real dez = have_prev_err_ ? (ez - prev_ez_) * dscale : kZero;
  const Real dex = have_prev_err_ ? (ex - prev_ex_) * dscale : kZero;
  const Real deu = have_prev_err_ ? (eu - prev_eu_) * dscale : kZero;
  prev_ez_ = ez;
  prev_ex_ = ex;
  prev_eu_ = eu;
  have_prev_err_ = true;

  ControlOutput o;
  if (z_f_ > p_.stage_switch_m) {
    phase_ = Seed003Phase::kStage1;
    o.cmd.wz_radps = clamp_abs(p_.stage1_kw * eu, p_.stage1_max_wz_radps);
    o.cmd.vx_mps = clamp_abs(p_.stage1_kv * (z_f_ - p_.stage1_target_m), p_.stage1_max_vx_mps);
    success_held_s_ = 0;
  } else {
    phase_ = Seed003Phase::kStage2;
    if (z_f_ >= p_.blind_zone_m) o.cmd.vx_mps = clamp_abs(p_.z_kp * ez + p_.z_kd * dez, p_.z_max_mps);
    // X > 0 = target to the right = move right (−y).
    const Real vy = -clamp_abs(p_.x_kp * ex + p_.x_kd * dex, p_.x_max_mps);
    Real wz = p_.u_kp * eu + p_.u_kd * deu;
    if (p_.holonomic) {
      o.cmd.vy_mps = vy;
    } else {
      // Differential: the sideways demand becomes the yaw rate that swings the line of sight at that speed.
      const Real zmin = static_cast<Real>(0.2);
      wz += vy / (z_f_ > zmin ? z_f_ : zmin);
    }
    o.cmd.wz_radps = clamp_abs(wz, p_.u_max_radps);
    const bool ok = std::fabs(ez) < p_.success_z_m && std::fabs(ex) < p_.success_x_m &&
                    std::fabs(u - cx) < p_.success_u_px;
    success_held_s_ = ok ? success_held_s_ + dt : kZero;
    if (success_held_s_ >= p_.success_hold_s) {
      seed_success_ = true;
      phase_ = Seed003Phase::kSeedSuccess;
      return stopped(ControlStatus::kRunning, static_cast<std::uint8_t>(phase_));
    }
  }
  o.phase = static_cast<std::uint8_t>(phase_);
  return o;
}

// ====================================================================================================== smooth ========

const char* SmoothController::phase_name(std::uint8_t phase) const {
  switch (phase) {
    case 0: return "APPROACH";
    case 1: return "SLOWDOWN";
    case 2: return "CREEP";
    case 3: return "DOCKED";
    case 4: return "LINEUP";
    default: return "UNKNOWN";
  }
}

void SmoothController::reset() {
  phase_ = SmoothPhase::kApproach;
  lineup_ = false;
  stall_s_ = 0;
}

Real SmoothController::graceful_curvature(Real r_m, Real phi_rad, Real delta_rad, Real k_phi, Real k_delta) {
  const Real kp = k_phi * phi_rad;
  const Real prop = k_delta * (delta_rad - std::atan(-kp));
  const Real feedback = (kOne + k_phi / (kOne + kp * kp)) * std::sin(delta_rad);
  return -(prop + feedback) / r_m;
}

ControlOutput SmoothController::step(const ControlInput& in) {
  const DockingCommonParams& c = p_.common;
  const ControlStatus guard = common_guard(in, phase_ == SmoothPhase::kDocked, stall_s_, c, true);
  if (guard == ControlStatus::kArrived) phase_ = SmoothPhase::kDocked;
  if (guard != ControlStatus::kRunning) return stopped(guard, static_cast<std::uint8_t>(phase_));
  // The dock as aimed at: beside its axis while the task manager searches for the contacts sideways.
  Pose2 aside{};
  aside.y_m = in.aim_lateral_m;
  const Pose2 aim = in.aim_lateral_m == kZero ? in.dock_in_robot : in.dock_in_robot.compose(aside);
  // The law runs on the docking frame: the real body frame, or for rear pads the body frame turned by π.
  Pose2 robot = aim.inverse();
  if (p_.backwards) robot.yaw_rad = wrap_angle(robot.yaw_rad + kPi);
  const Vec2 pad = robot.transform(Vec2(c.pad_reach_m, 0));
  if (stalled(c, pad.x(), positive_dt(in), &stall_s_)) {
    return stopped(ControlStatus::kFailed, static_cast<std::uint8_t>(phase_));
  }
  // Goal: the docked centre pose (reach, 0, π), projected behind the dock along the docking axis.
  const Real gx = c.pad_reach_m - p_.goal_projection_m;
  const Real dx = gx - robot.x_m;
  const Real dy = -robot.y_m;
  const Real los = std::atan2(-dy, dx);
  Real r = std::sqrt(dx * dx + dy * dy);
  const Real r_min = static_cast<Real>(1e-3);
  if (r < r_min) r = r_min;
  const Real phi = wrap_angle(kPi + los);
  const Real delta = wrap_angle(robot.yaw_rad + los);
  const Real d = pad.x() > 0 ? pad.x() : kZero;  // pads to the contact plane
  if (p_.lineup_distance_m > 0) {
    if (pad.x() < p_.lineup_distance_m && std::fabs(robot.y_m) < p_.lineup_engage_lateral_m &&
        std::fabs(wrap_angle(robot.yaw_rad - kPi)) < p_.lineup_engage_heading_rad) {
      lineup_ = true;
    }
    if (pad.x() > p_.lineup_distance_m + p_.lineup_hysteresis_m) lineup_ = false;
  } else {
    lineup_ = false;
  }
  Real kappa = 0;
  if (lineup_) {
    // Axis tracker: the cubic y(s) from the centre's lateral offset and slope now to y = 0 with zero slope after a
    // horizon D of travel along −x (s = −x; dy/ds = −tan e, e = heading off the docked heading π, positive = turned
    // left); the curvature to command is the cubic's at s = 0. D = pads' distance − margin (aligned just before the
    // contacts), but at least lineup_horizon_min_m: that floor bounds the noise gain (6/D² per m of lateral,
    // 4/D per rad of heading) in the last centimetres, where the heading is held on the estimated axis.
    // The lateral term has its own, longer floor: near the contacts the heading matters more (±2° vs ±10 mm at the
    // pads, and a heading error moves the pads sideways by reach·sin e), and the estimate's lateral noise would
    // otherwise become heading noise there.
    const Real e = wrap_angle(robot.yaw_rad - kPi);
    const Real left = d - p_.lineup_margin_m;
    const Real dh = left > p_.lineup_horizon_min_m ? left : p_.lineup_horizon_min_m;
    const Real dl = left > p_.lineup_lateral_horizon_min_m ? left : p_.lineup_lateral_horizon_min_m;
    const Real slope = -std::tan(e);
    const Real k = static_cast<Real>(6) * robot.y_m / (dl * dl) + static_cast<Real>(4) * slope / dh;
    const Real s2 = kOne + slope * slope;
    kappa = clamp_abs(k / (s2 * std::sqrt(s2)), p_.lineup_max_curvature_inv_m);
  } else {
    kappa = graceful_curvature(r, phi, delta, p_.k_phi, p_.k_delta);
  }
  Real v = p_.v_max_mps / (kOne + p_.beta * std::pow(std::fabs(kappa), p_.lambda));
  const Real lineup_zone_m = (p_.lineup_distance_m > 0 ? p_.lineup_distance_m : kZero) + p_.lineup_hysteresis_m;
  if (p_.min_turn_rate_radps > 0 && in.dock_confirmed && d > lineup_zone_m && std::fabs(kappa) > 0) {
    Real v_turn = p_.min_turn_rate_radps / std::fabs(kappa);
    if (v_turn > p_.v_max_mps) v_turn = p_.v_max_mps;
    if (v_turn > v) v = v_turn;
  }
  SmoothPhase ph = SmoothPhase::kApproach;
  if (p_.slowdown_radius_m > 0) {
    const Real vs = p_.v_max_mps * d / p_.slowdown_radius_m;
    if (vs < v) {
      v = vs;
      ph = SmoothPhase::kSlowdown;
    }
  }
  if (p_.max_decel_mps2 > 0) {
    const Real vb = std::sqrt(static_cast<Real>(2) * p_.max_decel_mps2 * d);
    if (vb < v) {
      v = vb;
      ph = SmoothPhase::kSlowdown;
    }
  }
  if (v <= c.creep_speed_mps) {
    v = c.creep_speed_mps;
    if (ph == SmoothPhase::kSlowdown) ph = SmoothPhase::kCreep;
  }
  Real w = kappa * v;
  if (std::fabs(w) > p_.w_max_radps) {
    w = sign_of(w) * p_.w_max_radps;
    v = p_.w_max_radps / std::fabs(kappa);
    if (v < p_.min_turn_speed_mps) v = p_.min_turn_speed_mps;
  }
  if (lineup_ && ph != SmoothPhase::kCreep) ph = SmoothPhase::kLineup;
  phase_ = ph;
  ControlOutput o;
  o.phase = static_cast<std::uint8_t>(ph);
  o.cmd.vx_mps = p_.backwards ? -v : v;
  o.cmd.wz_radps = w;
  return o;
}

DockingController* ControllerSet::by_name(const char* name) {
  DockingController* const all[] = {&seed000, &seed004, &seed003, &smooth};
  for (DockingController* c : all) {
    if (std::strcmp(c->name(), name) == 0) return c;
  }
  return nullptr;
}

}  // namespace dockcore
