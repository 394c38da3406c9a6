#pragma once
// Scripted robot chassis for closed-loop docking simulation: wheel-level kinematics (differential or mecanum),
// command latency, motor lag, acceleration limits, PWM deadband, wheel slip, quantised wrapping encoders, drifting
// odometry, contact with the dock's charging contacts and a battery.
//
// Host-side (tools/). Construction may allocate; step() does not (fixed-size arrays only). Deterministic: every
// random draw comes from the docksim::Rng seeded at construction, in a fixed order.
//
// Frames: world, robot body (origin at the kinematic centre — the axle midpoint for a differential drive, the wheel
// rectangle's centre for mecanum; x forward, y left), dock (dockcore/perception/dock_profile.hpp: origin at the centre of the
// dock's charging contacts, x out of the dock face towards an approaching robot).
#include <array>
#include <cstddef>
#include <cstdint>

#include "dockcore/geometry.hpp"
#include "docksim/battery.hpp"
#include "docksim/rng.hpp"

namespace docksim {

using dockcore::Pose2;

/// Most wheels any drive has (mecanum: 4).
constexpr std::size_t kMaxWheels = 4;
/// Longest command delay line, in steps.
constexpr std::size_t kMaxLatencySteps = 256;
/// Longest encoder speed-measurement window, in steps.
constexpr std::size_t kMaxSpeedWindowSteps = 64;

/// Wheel arrangement. Wheel order — differential: 0 left, 1 right. Mecanum: 0 front-left, 1 front-right,
/// 2 rear-left, 3 rear-right, rollers in the usual "X" (O-from-below) layout so that +ω on all four drives forward.
enum class DriveKind : std::uint8_t { kDifferential, kMecanum };

/// Per-wheel angular velocity, rad/s, positive when the wheel rolls the robot forward (both sides; a real right motor
/// is often mounted mirrored — the CAN layer flips that sign, not this model). Unused entries are ignored.
using WheelRadps = std::array<double, kMaxWheels>;

/// Drive geometry.
struct DriveGeometry {
  DriveKind kind = DriveKind::kDifferential;
  double wheel_radius_m = 0.05;  ///< Rolling radius of every wheel.
  /// Differential: distance between the left and right wheel contact points (ROS diff_drive "wheel_separation").
  double wheel_base_m = 0.30;
  double lx_m = 0.15;  ///< Mecanum: half the front-rear wheel distance (half wheelbase).
  double ly_m = 0.15;  ///< Mecanum: half the left-right wheel distance (half track).
};

/// Number of driven wheels for a kind: 2 or 4. O(1).
inline std::size_t wheel_count(DriveKind k) { return k == DriveKind::kMecanum ? 4 : 2; }
/// Whether wheel `i` (the order above) is on the left side. O(1).
inline bool is_left_wheel(DriveKind kind, std::size_t i) {
  return kind == DriveKind::kMecanum ? (i % 2 == 0) : (i == 0);
}

/// Body velocity in the body frame.
struct BodyTwist {
  double vx_mps = 0;    ///< Forward.
  double vy_mps = 0;    ///< Left (always 0 for a differential drive's forward kinematics).
  double wz_radps = 0;  ///< Counter-clockwise.
};

/// Inverse kinematics: the wheel angular velocities (rad/s) that realise `twist` without slip. A differential drive
/// ignores vy (it cannot move sideways). Entries beyond wheel_count are 0. O(1).
WheelRadps body_twist_to_wheel_radps(const DriveGeometry& g, const BodyTwist& twist);

/// Forward kinematics: the body twist produced by wheel angular velocities (rad/s). For mecanum the four wheels
/// over-determine three twist components; this is the least-squares twist (exact when the wheels are consistent,
/// e.g. produced by body_twist_to_wheel_radps). O(1).
BodyTwist wheel_radps_to_body_twist(const DriveGeometry& g, const WheelRadps& wheels);

/// Exact pose update for a twist held constant for dt_s (the SE(2) exponential: a circular arc for a differential
/// drive, an arc with a sideways component for mecanum). Returns the new pose; yaw wrapped. O(1).
Pose2 integrate_twist(const Pose2& pose, const BodyTwist& twist, double dt_s);

/// Wheel motor and drive-electronics behaviour.
struct MotorParams {
  /// Command delay: a command given before step k takes effect in step k + latency_steps (0 = same step).
  /// Clamped to kMaxLatencySteps. Default 4 steps = 20 ms at the default dt.
  std::size_t latency_steps = 4;
  double time_constant_s = 0.05;      ///< First-order lag of wheel speed towards the target; 0 = none.
  double max_accel_radps2 = 40.0;     ///< Largest |dω/dt| per wheel; <= 0 = unlimited.
  double max_speed_radps = 30.0;      ///< Commands are saturated to ±this; <= 0 = unlimited.
  /// Commands with |ω| below this produce no motion (PWM drives do not overcome static friction). 0 = none.
  double deadband_radps = 0.3;
  /// Left wheels' deadband minus the right ones': they get deadband_radps ± this/2 (each at least 0). Two motors of
  /// one model rarely stick alike.
  double deadband_diff_radps = 0.0;
  /// Stop the motors when no command_wheels() arrived for this long (AgileX "communication protection": 0.5 s).
  /// <= 0 = never.
  double command_timeout_s = 0.0;
};

/// Wheel/ground and sensing imperfections.
struct NoiseParams {
  /// Wheel slip: ground travel = wheel rotation · r · (1 + e), e per wheel a Gauss-Markov process with this
  /// stationary 1-sigma (fraction). 0 = no slip.
  double slip_sigma = 0.01;
  /// Correlation time of e in seconds; <= 0 makes e white (a new draw every step, so its effect depends on dt).
  double slip_correlation_s = 0.2;
  std::int32_t encoder_cpr = 4096;          ///< Encoder counts per wheel revolution (> 0).
  std::int32_t encoder_initial_count = 0;   ///< Start value of every counter (to exercise int32 wrap-around).
  /// Window for the measured wheel speed, in steps: speed = Δcounts over the window (as a drive reports it).
  std::size_t speed_window_steps = 4;
  /// Systematic odometry errors (the chassis firmware's geometry versus the true one), fractions:
  double odom_radius_error = 0.0;   ///< Odometry wheel radius = r·(1 + this), all wheels.
  double odom_radius_diff = 0.0;    ///< Left wheels get +this/2, right wheels −this/2 on top (Borenstein's E_d).
  double odom_base_error = 0.0;     ///< Odometry wheel_base (diff) or lx+ly (mecanum) = true·(1 + this).
};

/// Robot outline, used to place the charging pads.
enum class FootprintShape : std::uint8_t { kRectangle, kCircle };
/// Which side of the footprint carries the charging pads: front (pads face +x, forward docking) or rear (−x,
/// backwards docking).
enum class PadSide : std::uint8_t { kFront, kRear };

struct FootprintParams {
  FootprintShape shape = FootprintShape::kRectangle;
  double length_m = 0.45;        ///< Rectangle: extent along body x.
  double width_m = 0.40;         ///< Rectangle: extent along body y.
  double radius_m = 0.20;        ///< Circle.
  double centre_x_m = 0.0;       ///< Footprint centre's x in the body frame (a diff drive's axle is often off-centre).
  PadSide pad_side = PadSide::kFront;
  double pad_offset_y_m = 0.0;   ///< Lateral position of the pads' centre along that side (body y).
};

/// Where the pads' centre is in the body frame (on the footprint boundary). O(1).
dockcore::Vec2 pad_point_body(const FootprintParams& f);
/// Outward direction of the pads in the body frame, rad: 0 (front) or π (rear). O(1).
double pad_normal_yaw_body(const FootprintParams& f);

/// Dock contacts and charger.
struct ContactParams {
  double lateral_tolerance_m = 0.010;  ///< Contacts close only with |pad y in dock frame| <= this.
  double yaw_tolerance_rad = 2.0 * dockcore::kPi / 180.0;  ///< ... and |pad heading error| <= this.
  double min_press_m = 0.003;          ///< ... and pressed at least this far past the contact plane.
  double press_limit_m = 0.008;        ///< Spring travel: hard stop this far past the contact plane.
  double charge_delay_s = 0.5;         ///< Charger switches on after the contacts stay closed this long.
  double charge_current_a = 5.0;       ///< Constant-current charge.
  /// The charger delivers only while the robot requests it (a relay the host switches, dockcore CAN v1's
  /// ChargeRequest); false: live whenever the contacts close (AgileX bases have no relay frame).
  bool switched = true;
  double taper_start_soc = 0.95;       ///< Above this SOC the charge current falls linearly to 0 at SOC 1.
};

/// Where the dock is. The dock face is the line x = 0 of the dock frame, |y| <= face_half_width_m.
///
/// Contact model: only the pads' centre point touches the dock (the rest of the footprint is assumed to fit the
/// dock's recess). Coming from the front within the face width, the pads may travel press_limit_m past x = 0 (spring
/// contacts); a step that would take them further is cut short exactly at that stop, and while pressed the robot
/// neither slides along the face nor turns (friction, pads seated in the contacts) — only motion that takes the pads
/// back off the face is free. So a robot that arrives misaligned stays misaligned until it backs off.
/// Outside the face width the robot passes by (the dock's sides are not modelled).
///
/// stop_short_m > 0 moves that stop in front of the contacts: something the lidar does not see (a raised lip of the
/// dock's base plate, a cable, a door sill across the face's width) holds the pads stop_short_m before the contact
/// plane, with the same hard-stop mechanics, so the contacts never close and pushing only stalls the wheels.
struct DockPlacement {
  Pose2 pose_world;                ///< Dock frame in the world.
  double face_half_width_m = 0.15; ///< Half-width of the face that stops the robot.
  bool dead = false;               ///< True: contacts may close but the charger never delivers current.
  double stop_short_m = 0;         ///< > 0: the pads are stopped this far in front of the contact plane, m.
};

/// Electrical load of the robot.
struct LoadParams {
  double idle_current_a = 0.8;           ///< Electronics, always drawn.
  double motion_current_a_per_mps = 4.0; ///< Extra draw per m/s of mean |wheel surface speed|.
  double stall_current_a = 3.0;          ///< Extra draw while stalled against the dock.
};

/// Everything that defines a chassis.
struct ChassisParams {
  double dt_s = 0.005;  ///< Fixed integration step (> 0). Latency and windows are counted in these steps.
  DriveGeometry geometry;
  MotorParams motor;
  NoiseParams noise;
  FootprintParams footprint;
  ContactParams contact;
  BatteryParams battery;
  LoadParams load;
  /// Stalled = pressed against the hard stop while commanded, with Σ|actual ω| <= this · Σ|target ω|.
  double stall_speed_ratio = 0.5;
};

/// Returns nullptr when `p` is usable, else a static message naming the first bad field. O(1).
const char* check_chassis_params(const ChassisParams& p);

/// What freeze() does to the motors while the chassis is not answering.
enum class FreezeMotion : std::uint8_t {
  kHoldLastCommand,  ///< Firmware hung with the last PWM latched: keeps driving.
  kStop,             ///< Drives brake to zero.
};

/// Everything observable after a step. "Reported" fields are what the chassis sends to the host; they are not
/// refreshed while the chassis is frozen (responding == false). The rest is ground truth, always current.
struct ChassisState {
  double time_s = 0;                 ///< Simulated time since construction.
  std::uint64_t steps = 0;           ///< Steps taken.
  std::size_t wheel_count = 2;

  // Ground truth.
  Pose2 true_pose;                   ///< Body frame in the world.
  BodyTwist true_twist;              ///< Mean body velocity over the last step (after slip and the hard stop).
  WheelRadps wheel_target_radps{};   ///< Command in force this step (after latency, timeout, deadband, saturation).
  WheelRadps wheel_true_radps{};     ///< Actual wheel angular velocity at the end of the step.
  bool stalled = false;              ///< Pushing against the dock's hard stop; wheels blocked (measured ω ≈ 0).
  bool at_hard_stop = false;         ///< The dock face cut this step's motion short.
  /// Pad travel past the contact plane, m: −(pad x in the dock frame). Negative = still this far in front of the
  /// contacts; at most press_limit_m while the hard stop holds. 0 without a dock.
  double press_m = 0;
  double pad_lateral_m = 0;          ///< Pad centre's y in the dock frame.
  double pad_yaw_error_rad = 0;      ///< Pad heading versus facing the dock squarely, wrapped.
  bool contact = false;              ///< Charging contacts closed (within every tolerance).
  bool charging = false;             ///< Charger delivering (contact held for charge_delay_s, dock alive, not forced off).
  double charge_current_a = 0;       ///< Charger current into the battery (>= 0).

  // Reported by the chassis (stale while frozen).
  bool responding = true;            ///< False while frozen: the caller must drop feedback.
  std::array<std::int32_t, kMaxWheels> encoder_counts{};  ///< Wrapping int32 counters, + forward.
  WheelRadps wheel_measured_radps{}; ///< From encoder counts over speed_window_steps.
  Pose2 odom_pose;                   ///< The chassis' dead-reckoned pose from its encoders and its geometry.
  double battery_current_a = 0;      ///< + charging, − discharging.
  double battery_voltage_v = 0;
  double battery_soc = 0;            ///< 0..1.
};

/// The simulated chassis. Typical loop: command_wheels() whenever the controller runs, step() every dt_s.
class Chassis {
 public:
  /// Parameters are sanitised (see check_chassis_params for what is expected; out-of-range values are clamped to
  /// something safe). `seed` fixes every random draw. Starts at rest at the world origin, odometry at the origin.
  Chassis(const ChassisParams& params, std::uint64_t seed);

  /// Latest wheel command (rad/s per wheel); held until replaced. Ignored while frozen. O(1).
  void command_wheels(const WheelRadps& wheel_radps);
  /// Convenience: commands the wheel speeds that realise `twist` under the true geometry. O(1).
  void command_twist(const BodyTwist& twist);
  /// Advances one fixed step of params().dt_s. O(wheels); never allocates.
  void step();
  /// Steps until at least `duration_s` has elapsed (rounded to whole steps); returns the number of steps. O(steps).
  std::size_t run_for(double duration_s);

  const ChassisState& state() const { return state_; }
  const ChassisParams& params() const { return p_; }

  // --- Set-up ---
  /// Places the robot (ground truth) without touching odometry or encoders. Motors keep their state. O(1).
  void set_true_pose(const Pose2& pose_world);
  /// Resets the odometry pose (like a host "reset odometry" request). O(1).
  void reset_odometry(const Pose2& odom_pose = Pose2{});
  /// Puts a dock in the world (replaces any previous one). O(1).
  void set_dock(const DockPlacement& dock);
  /// Removes the dock. O(1).
  void clear_dock();
  bool has_dock() const { return has_dock_; }
  /// Sets the battery's state of charge. O(1).
  void set_battery_soc(double soc);

  // --- Disturbance hooks (a scripted timeline calls these) ---
  /// Robot pushed: the true pose jumps by (dx, dy) in the world and dyaw; encoders and odometry do not see it. O(1).
  void apply_pose_jump(double dx_world_m, double dy_world_m, double dyaw_rad);
  /// Freeze (on = true): the chassis stops answering — commands are ignored and reported fields go stale —
  /// while the motors do what `motion` says. Unfreezing resumes with the counters' true values. O(1).
  void set_frozen(bool on, FreezeMotion motion = FreezeMotion::kHoldLastCommand);
  bool frozen() const { return frozen_; }
  /// Forces the charger off (true) regardless of contact, or releases it. O(1).
  void set_charging_inhibited(bool inhibited);

 private:
  void update_contact(double dt);
  void publish_reported();

  ChassisParams p_;
  std::size_t n_ = 2;
  Rng rng_;
  Battery battery_;

  // Ground truth, integrated in double regardless of dockcore::Real.
  double x_ = 0, y_ = 0, yaw_ = 0;
  WheelRadps omega_{};          // actual wheel speed (motor state)
  WheelRadps slip_{};           // Gauss-Markov slip state per wheel

  // Command path.
  WheelRadps latest_cmd_{};
  double since_cmd_s_ = 0;
  std::array<WheelRadps, kMaxLatencySteps + 1> delay_{};
  std::size_t delay_head_ = 0;

  // Encoders: exact count since start, plus the fraction of a count not yet reached.
  std::array<std::int64_t, kMaxWheels> count_total_{};
  std::array<double, kMaxWheels> count_frac_{};
  std::array<std::array<std::int64_t, kMaxWheels>, kMaxSpeedWindowSteps + 1> count_hist_{};
  std::size_t hist_head_ = 0;

  // Odometry, as the chassis firmware would compute it from wrapping counters.
  std::array<std::int32_t, kMaxWheels> odom_last_counts_{};
  double ox_ = 0, oy_ = 0, oyaw_ = 0;
  DriveGeometry odom_geom_;
  std::array<double, kMaxWheels> odom_radius_m_{};
  std::array<double, kMaxWheels> deadband_radps_{};  ///< Each wheel's: deadband_radps ± deadband_diff_radps / 2.

  // Dock and charger.
  bool has_dock_ = false;
  DockPlacement dock_;
  double contact_held_s_ = 0;
  bool charge_inhibited_ = false;

  bool frozen_ = false;
  FreezeMotion freeze_motion_ = FreezeMotion::kHoldLastCommand;

  ChassisState state_;
};

}  // namespace docksim
