#pragma once
/// @file The four docking controllers: Seed000Controller ("seed000", rotate-then-drive), Seed004Controller
/// ("seed004", the nine-state alignment machine), Seed003Controller ("seed003", two-stage camera + lidar gaze docking)
/// and SmoothController ("smooth", dockcore's default: Park–Kuipers graceful law onto a goal projected behind the
/// dock). All are plain objects: fixed-size state, trivial constructors taking a Params struct, O(1) step(), zero
/// twist whenever the status is not kRunning. docs/controllers.md explains the laws, the seed mapping and measured
/// figures.
///
/// Shared geometry. The dock frame has its origin at the charging contacts' centre and x out of the dock face. The
/// robot's charging pads sit at body (pad_reach_m, 0) (front pads) — or (−pad_reach_m, 0) for SmoothController with
/// backwards = true. Docked = pads at the dock origin with the pad normal facing the dock: robot yaw in the dock frame
/// = π (front pads) or 0 (rear pads).

#include <cstddef>
#include <cstdint>

#include "dockcore/control/controller.hpp"
#include "dockcore/geometry.hpp"

namespace dockcore {

/// Settings every controller shares: pad placement, end of run, stall detection.
struct DockingCommonParams {
  /// Distance from the robot's kinematic centre to its charging pads' centre along the docking direction, m.
  /// Default: the simulated chassis' default footprint (0.45 m long, centred): 0.225.
  Real pad_reach_m = static_cast<Real>(0.225);
  /// Slowest commanded approach speed near the dock, m/s. Must exceed the drive's deadband (the simulated chassis:
  /// 0.3 rad/s · 0.05 m = 0.015 m/s) or the robot stops short of the contacts.
  Real creep_speed_mps = static_cast<Real>(0.03);
  /// Give up (kFailed) when the estimate says the pads are at least this far past the contact plane ...
  Real stall_press_m = static_cast<Real>(0.0);
  /// ... continuously for this long without the contacts closing, s (misaligned against the face: back off, retry).
  Real stall_timeout_s = static_cast<Real>(2.0);
};

// ---------------------------------------------------------------------------------------------------------------------
/// seed 000: rotate in place until the dock's bearing |atan2(y, x)| of ControlInput::dock_in_robot is below the angle
/// threshold, then drive straight in; whenever the bearing leaves the threshold again, stop and rotate again. Arrives
/// on contact. Only the bearing is used (the seed's breakpoint detector gives no dock orientation), so the robot meets
/// the face at whatever angle it approaches from.
struct Seed000Params {
  DockingCommonParams common{};
  Real angle_threshold_rad = deg_to_rad(static_cast<Real>(5));  ///< Seed: |centre angle| < 5° ends the correction.
  /// Once rotating, keep rotating until the bearing is below this (hysteresis, so the robot does not chatter at 5°).
  Real rotate_exit_rad = deg_to_rad(static_cast<Real>(1.5));
  Real rotate_kp = static_cast<Real>(1.0);             ///< Yaw rate per rad of bearing, 1/s.
  Real rotate_max_radps = static_cast<Real>(0.5);      ///< Fastest in-place turn, rad/s.
  Real rotate_min_radps = static_cast<Real>(0.15);     ///< Slowest in-place turn (above the deadband), rad/s.
  Real forward_speed_mps = static_cast<Real>(0.2);     ///< Cruise speed while driving in, m/s.
  Real slowdown_distance_m = static_cast<Real>(0.3);   ///< Pad-to-contact distance where the speed starts to fall, m.
};

/// Phase codes of Seed000Controller (stable).
enum class Seed000Phase : std::uint8_t { kRotate = 0, kDrive = 1, kDocked = 2 };

class Seed000Controller final : public DockingController {
 public:
  explicit Seed000Controller(const Seed000Params& p = Seed000Params{}) : p_(p) {}
  const char* name() const override { return "seed000"; }
  const char* phase_name(std::uint8_t phase) const override;
  void reset() override;
  ControlOutput step(const ControlInput& in) override;
  const Seed000Params& params() const { return p_; }

 private:
  Seed000Params p_;
  Seed000Phase phase_ = Seed000Phase::kRotate;
  Real stall_s_ = 0;
};

// ---------------------------------------------------------------------------------------------------------------------
/// seed 004: the alignment state machine of the seed's Table 2 with its Table 3 parameters. Errors are read each tick
/// from the dock estimate: robot centre (x, y) and heading θ in the dock frame; the aligned pose is x =
/// relative_distance_m, y = 0, θ = π. Sequence: READY picks the heading parallel to the dock face (θ = ±π/2, the one
/// nearer to the current heading); POSITION decides whether the lateral error needs correcting (|y| >
/// robot_distance_tolerance, always with the seed's −0.01); ROTATE turns in place to the parallel heading; LATERAL
/// drives forward/back along it until |y| < distance_tolerance; LATERAL_ORI_CONFIRM computes the heading that faces
/// the dock origin; LATERAL_ROTATE turns to it; FRONT_BACK_ORI_CONFIRM computes the distance error x −
/// relative_distance; FRONT_BACK drives until it is within distance_tolerance; FINISH (the seed's end) lasts one tick;
/// then — dockcore's addition for a charging dock — FINAL_APPROACH creeps straight ahead (heading held on the
/// estimate, no lateral correction) until the contacts close.
struct Seed004Params {
  DockingCommonParams common{};
  Real angle_tolerance_rad = static_cast<Real>(0.01);       ///< Table 3 angle_tolerance.
  Real distance_tolerance_m = static_cast<Real>(0.01);      ///< Table 3 distance_tolerance.
  Real relative_distance_m = static_cast<Real>(0.53);       ///< Table 3 relative_distance_tolerance (centre to marker).
  Real robot_distance_tolerance_m = static_cast<Real>(-0.01);///< Table 3: lateral correction skipped below; < 0 = never.
  Real angle_kp = static_cast<Real>(0.6);                   ///< Table 3: yaw rate per rad of heading error, 1/s.
  Real distance_kp = static_cast<Real>(0.4);                ///< Table 3: speed per m of distance error, 1/s.
  Real max_wz_radps = static_cast<Real>(0.5);               ///< Fastest in-place turn, rad/s.
  /// Slowest in-place turn, rad/s: the seed's P law alone gives 0.006 rad/s at the tolerance, far inside any drive's
  /// deadband, so the command is floored here (simulated chassis' diff deadband ≈ 0.1 rad/s).
  Real min_wz_radps = static_cast<Real>(0.12);
  Real max_speed_mps = static_cast<Real>(0.2);              ///< Fastest straight motion, m/s.
  /// Slowest straight motion in LATERAL / FRONT_BACK, m/s (floored for the deadband like min_wz_radps).
  Real min_speed_mps = static_cast<Real>(0.02);
  Real final_speed_mps = static_cast<Real>(0.08);           ///< Fastest FINAL_APPROACH speed, m/s.
  Real final_heading_kp = static_cast<Real>(0.6);           ///< FINAL_APPROACH heading hold, 1/s.
};

/// Phase codes of Seed004Controller (stable): 0..8 are the seed's Table 2 sub-states.
enum class Seed004Phase : std::uint8_t {
  kReady = 0,
  kPosition = 1,
  kRotate = 2,
  kLateral = 3,
  kLateralOriConfirm = 4,
  kLateralRotate = 5,
  kFrontBackOriConfirm = 6,
  kFrontBack = 7,
  kFinish = 8,
  kFinalApproach = 9,  ///< dockcore: straight creep from the relative distance onto the contacts.
  kDocked = 10,        ///< Contacts closed.
};

class Seed004Controller final : public DockingController {
 public:
  explicit Seed004Controller(const Seed004Params& p = Seed004Params{}) : p_(p) {}
  const char* name() const override { return "seed004"; }
  const char* phase_name(std::uint8_t phase) const override;
  void reset() override;
  ControlOutput step(const ControlInput& in) override;
  const Seed004Params& params() const { return p_; }

 private:
  Real turn_rate(Real err_rad) const;
  Real drive_speed(Real err_m, Real max_mps) const;

  Seed004Params p_;
  Seed004Phase phase_ = Seed004Phase::kReady;
  Real target_yaw_rad_ = 0;  // In the dock frame: set by READY / LATERAL_ORI_CONFIRM.
  Real stall_s_ = 0;
};

// ---------------------------------------------------------------------------------------------------------------------
/// seed 003: two-stage gaze docking. Per tick: the camera gives the target column u; the lidar range along the
/// camera ray, at camera bearing −atan((u − cx)/fx) (image u grows to the right, robot y to the left), converted into
/// the lidar frame with the mounts' yaws (the mounts' translation parallax is ignored, as in the seed), gives Z;
/// X = (u − cx)·Z/fx (positive = target to the right). Both go through a 10-sample sliding mean and an EMA
/// (X_f = α·X_raw + (1 − α)·mean). Stage 1 (Z_f > stage_switch_m): wz = k·(cx − u) ≤ 0.3, vx = 0.6·(Z_f − 0.8) ≤ 0.15.
/// Stage 2: PD on Z_f → 0.25 (vx), X_f → 0 (vy; on a differential drive folded into wz as vy/Z_f), u → cx (wz).
/// The seed's derivative term is a per-iteration difference at 20 Hz; here kd multiplies the error change per
/// seed_period_s, so gains mean the same at any tick rate. Seed success: |Z_f − 0.25| < 0.03, |X_f| < 0.03,
/// |u − cx| < 20 px held 1 s → phase kSeedSuccess for one tick, then FINAL_APPROACH creeps straight (wz still on u)
/// until contact. Z_f < blind_zone_m disables the longitudinal PD. Camera invalid or older than target_timeout_s, or no
/// lidar range and no history → kLost, zero twist, filter state kept (the seed resumes from the last coordinates).
struct Seed003Params {
  DockingCommonParams common{};
  CameraModel camera{};          ///< Intrinsics and mount of the camera that produces ControlInput::camera.
  bool holonomic = false;        ///< true: mecanum, X loop drives vy; false: differential, X folded into wz.
  std::size_t window = 10;       ///< Sliding window length, samples (1..kSeed003MaxWindow).
  Real ema_alpha = static_cast<Real>(0.2);
  Real stage_switch_m = static_cast<Real>(1.0);
  Real stage1_kw = static_cast<Real>(0.005);        ///< rad/s per px.
  Real stage1_max_wz_radps = static_cast<Real>(0.3);
  Real stage1_kv = static_cast<Real>(0.6);          ///< 1/s.
  Real stage1_target_m = static_cast<Real>(0.8);
  Real stage1_max_vx_mps = static_cast<Real>(0.15);
  Real goal_z_m = static_cast<Real>(0.25);
  Real z_kp = static_cast<Real>(1.0), z_kd = static_cast<Real>(0.4), z_max_mps = static_cast<Real>(0.08);
  Real x_kp = static_cast<Real>(1.8), x_kd = static_cast<Real>(0.7), x_max_mps = static_cast<Real>(0.08);
  Real u_kp = static_cast<Real>(0.006), u_kd = static_cast<Real>(0.0025), u_max_radps = static_cast<Real>(0.35);
  Real seed_period_s = static_cast<Real>(0.05);     ///< The seed's loop period the kd gains refer to.
  Real success_z_m = static_cast<Real>(0.03);
  Real success_x_m = static_cast<Real>(0.03);
  Real success_u_px = static_cast<Real>(20);
  Real success_hold_s = static_cast<Real>(1.0);
  Real blind_zone_m = static_cast<Real>(0.1);
  Real target_timeout_s = static_cast<Real>(0.3);   ///< Camera target older than this counts as lost.
  Real final_speed_mps = static_cast<Real>(0.04);   ///< FINAL_APPROACH creep, m/s (>= common.creep_speed_mps).
  /// FINAL_APPROACH gives up (kFailed) after this much odometry travel without contact, m.
  Real final_max_travel_m = static_cast<Real>(0.4);
};

/// Largest sliding window Seed003Controller holds.
constexpr std::size_t kSeed003MaxWindow = 32;

enum class Seed003Phase : std::uint8_t {
  kStage1 = 0,         ///< Far: gaze + P approach to 0.8 m.
  kStage2 = 1,         ///< Near: three PD loops.
  kSeedSuccess = 2,    ///< The seed's own success test held for 1 s (lasts one tick).
  kFinalApproach = 3,  ///< dockcore: straight creep onto the contacts.
  kDocked = 4,
};

class Seed003Controller final : public DockingController {
 public:
  explicit Seed003Controller(const Seed003Params& p = Seed003Params{}) : p_(p) {}
  const char* name() const override { return "seed003"; }
  const char* phase_name(std::uint8_t phase) const override;
  void reset() override;
  ControlOutput step(const ControlInput& in) override;
  const Seed003Params& params() const { return p_; }
  /// Latest filtered lateral offset X_f and range Z_f, m (for logs/tests).
  Real filtered_x_m() const { return x_f_; }
  Real filtered_z_m() const { return z_f_; }
  /// True once the seed's own success test has held (reported even after the final approach).
  bool seed_success() const { return seed_success_; }

 private:
  bool lidar_range(const ControlInput& in, Real u_px, Real* z_m) const;

  Seed003Params p_;
  Seed003Phase phase_ = Seed003Phase::kStage1;
  Real win_x_[kSeed003MaxWindow] = {};
  Real win_z_[kSeed003MaxWindow] = {};
  std::size_t win_n_ = 0, win_head_ = 0;
  Real x_f_ = 0, z_f_ = 0;
  bool have_prev_err_ = false;
  Real prev_ez_ = 0, prev_ex_ = 0, prev_eu_ = 0;
  Real success_held_s_ = 0;
  bool seed_success_ = false;
  Pose2 final_start_{};
  Real stall_s_ = 0;
};

// ---------------------------------------------------------------------------------------------------------------------
/// smooth (dockcore's default): the Park–Kuipers graceful control law, as Nav2's docking server uses it, steering the
/// robot centre onto a goal projected `goal_projection_m` behind the docked pose along the docking axis, so the law's
/// 1/r stays regular at the contacts. With r, φ, δ the egocentric polar coordinates (Nav2's convention):
///   κ = −(1/r)·[k_δ(δ − atan(−k_φ φ)) + (1 + k_φ/(1 + (k_φ φ)²))·sin δ],
///   v = v_max/(1 + β|κ|^λ), raised to min_turn_rate/|κ| (≤ v_max) outside the line-up zone towards a confirmed
///   estimate, then v ≤ v_max·d/slowdown_radius, v ≤ √(2·a_dec·d) (d = pad distance to the contact plane),
///   v ≥ creep_speed (the deadband floor), ω = κ·v ≤ ω_max with v recomputed to keep κ.
/// Never commands v ≤ 0 while running: one forward motion, no reversals, no in-place rotation (v is floored at
/// min_turn_speed_mps when ω saturates). vy is always 0: the same law serves mecanum drives (a vy assist on the pads'
/// lateral error destabilises the heading loop, see docs/controllers.md). backwards = true docks with
/// rear pads: the law runs on the reversed robot frame and v is negated. In the last lineup_distance_m, once near the
/// axis, LINEUP replaces the graceful curvature with an axis tracker (see the lineup_* fields and docs/controllers.md).
struct SmoothParams {
  DockingCommonParams common{};
  bool backwards = false;                          ///< Pads at the rear (body x = −pad_reach_m).
  Real k_phi = static_cast<Real>(5.0);    ///< Nav2 default 3.0; see docs/controllers.md for why higher here.
  Real k_delta = static_cast<Real>(4.0);  ///< Nav2 default 2.0.
  Real beta = static_cast<Real>(0.4);
  Real lambda = static_cast<Real>(2.0);
  Real v_max_mps = static_cast<Real>(0.25);
  Real w_max_radps = static_cast<Real>(0.75);
  Real slowdown_radius_m = static_cast<Real>(0.25);
  Real max_decel_mps2 = static_cast<Real>(0.25);   ///< Braking profile towards the contact plane, m/s².
  /// Goal behind the docked pose, m (Nav2: 0.25 from a staging pose on the axis; 0.10 here, see the docs).
  Real goal_projection_m = static_cast<Real>(0.10);
  /// Smallest forward speed when ω saturates, m/s (keeps the turn an arc: radius ≥ this/ω_max).
  Real min_turn_speed_mps = static_cast<Real>(0.03);
  /// Slowest turn along a tight curve of the graceful law, rad/s (0: off). The law's speed falls as 1/|κ|^λ, so a
  /// robot turning towards the axis would crawl round it at the creep speed, at |κ|·creep rad/s; instead the speed
  /// along the curve is at least this/|κ| (never above v_max_mps), the curve itself unchanged. Only outside the
  /// line-up zone (pads beyond lineup_distance_m + lineup_hysteresis_m from the contact plane), where the heading is
  /// settled before the contacts judge it, and only towards a confirmed estimate (ControlInput::dock_confirmed): one
  /// detection may be clutter, and a slow approach gives the next scans time to say so.
  Real min_turn_rate_radps = static_cast<Real>(0.3);
  /// Line-up: once the pads are this close to the contact plane (m), the graceful law hands over to an axis tracker
  /// (the graceful goal sits only goal_projection_m behind the pads, so its 1/r turns the estimate's lateral noise
  /// into heading noise right where the contacts judge the heading). ≤ 0 disables the line-up.
  Real lineup_distance_m = static_cast<Real>(0.40);
  /// ... and the robot centre is within this of the axis, m, and its heading within lineup_engage_heading_rad of
  /// the docked heading (otherwise the graceful law keeps going: it is the one that can swing a far-off robot in).
  Real lineup_engage_lateral_m = static_cast<Real>(0.03);
  Real lineup_engage_heading_rad = deg_to_rad(static_cast<Real>(10));
  /// Leave the line-up again only beyond lineup_distance_m + this, m (hysteresis against estimate jumps).
  Real lineup_hysteresis_m = static_cast<Real>(0.10);
  /// Axis tracker: the planned path meets the axis with zero heading error this far before the contact plane, m.
  Real lineup_margin_m = static_cast<Real>(0.03);
  /// Axis tracker: shortest planning horizon, m (bounds the noise gain on the estimate near the contacts).
  Real lineup_horizon_min_m = static_cast<Real>(0.10);
  /// Axis tracker: shortest horizon for the lateral term, m (≥ lineup_horizon_min_m: the heading is held harder
  /// than the lateral offset near the contacts).
  Real lineup_lateral_horizon_min_m = static_cast<Real>(0.30);
  /// Axis tracker: largest path curvature, 1/m. Keeps both wheels above the drive deadband at creep speed (diff drive,
  /// 0.30 m track, 0.05 m wheels: at 0.03 m/s and 3 1/m the inner wheel turns at 0.33 rad/s, above the 0.3 deadband).
  Real lineup_max_curvature_inv_m = static_cast<Real>(3.0);
};

enum class SmoothPhase : std::uint8_t {
  kApproach = 0,  ///< Graceful law at cruise speed.
  kSlowdown = 1,  ///< Inside the slowdown radius / braking profile.
  kCreep = 2,     ///< At the creep floor, waiting for the contacts.
  kDocked = 3,
  kLineup = 4,    ///< Axis tracker near the dock (speed still from the slowdown / braking / creep profile).
};

class SmoothController final : public DockingController {
 public:
  explicit SmoothController(const SmoothParams& p = SmoothParams{}) : p_(p) {}
  const char* name() const override { return "smooth"; }
  const char* phase_name(std::uint8_t phase) const override;
  void reset() override;
  ControlOutput step(const ControlInput& in) override;
  const SmoothParams& params() const { return p_; }

  /// The graceful law's path curvature (1/m, positive = left) for polar coordinates r > 0, φ, δ. O(1).
  static Real graceful_curvature(Real r_m, Real phi_rad, Real delta_rad, Real k_phi, Real k_delta);

 private:
  SmoothParams p_;
  SmoothPhase phase_ = SmoothPhase::kApproach;
  bool lineup_ = false;
  Real stall_s_ = 0;
};

/// The four controllers, each with its parameters; a host drives one of them by name (dockd's `[controller] name`,
/// a scenario's controller, a loop record's). The object owns them, so pointers from by_name() live as long as it.
struct ControllerSet {
  ControllerSet(const Seed000Params& p000, const Seed004Params& p004, const Seed003Params& p003, const SmoothParams& ps)
      : seed000(p000), seed004(p004), seed003(p003), smooth(ps) {}
  Seed000Controller seed000;
  Seed004Controller seed004;
  Seed003Controller seed003;
  SmoothController smooth;
  /// The controller called `name` ("seed000", "seed004", "seed003", "smooth"); nullptr for any other. O(1).
  DockingController* by_name(const char* name);
};

}  // namespace dockcore
