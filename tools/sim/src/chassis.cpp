#include "docksim/chassis.hpp"
#include "docksim/angles.hpp"

#include <algorithm>
#include <cmath>

namespace docksim {
namespace {

double wrap_d(double a) {
  double r = std::remainder(a, kTwoPiD);
  if (r <= -kPiD) r += kTwoPiD;
  return r;
}

// Converts modulo 2^32 without relying on implementation-defined narrowing.
std::int32_t wrap_to_i32(std::uint32_t u) {
  return u <= 0x7FFFFFFFu ? static_cast<std::int32_t>(u)
                          : static_cast<std::int32_t>(static_cast<std::int64_t>(u) - 0x100000000LL);
}

// sin(t)/t and (1 - cos t)/t, with series near 0 where the quotients lose precision.
void arc_factors(double th, double* a, double* b) {
  if (std::fabs(th) < 1e-6) {
    const double t2 = th * th;
    *a = 1.0 - t2 / 6.0;
    *b = th / 2.0 - th * t2 / 24.0;
  } else {
    *a = std::sin(th) / th;
    *b = (1.0 - std::cos(th)) / th;
  }
}

// SE(2) exponential: displacement (dx, dy, dth) given in the body frame at the start of the motion.
void integrate_d(double* x, double* y, double* yaw, double dx, double dy, double dth) {
  double a, b;
  arc_factors(dth, &a, &b);
  const double bx = a * dx - b * dy;
  const double by = b * dx + a * dy;
  const double c = std::cos(*yaw), s = std::sin(*yaw);
  *x += c * bx - s * by;
  *y += s * bx + c * by;
  *yaw = wrap_d(*yaw + dth);
}

// Forward kinematics in wheel surface units: u_i = r_i·ω_i (or travel), returns body (vx, vy, wz) in the same time
// base. `k` is wheel_base (diff) or lx + ly (mecanum).
BodyTwist surface_fk(DriveKind kind, double k, const WheelRadps& u) {
  BodyTwist t;
  if (kind == DriveKind::kMecanum) {
    t.vx_mps = (u[0] + u[1] + u[2] + u[3]) / 4.0;
    t.vy_mps = (-u[0] + u[1] + u[2] - u[3]) / 4.0;
    t.wz_radps = (-u[0] + u[1] - u[2] + u[3]) / (4.0 * k);
  } else {
    t.vx_mps = (u[0] + u[1]) / 2.0;
    t.wz_radps = (u[1] - u[0]) / k;
  }
  return t;
}

WheelRadps surface_ik(DriveKind kind, double k, const BodyTwist& t) {
  WheelRadps u{};
  if (kind == DriveKind::kMecanum) {
    u[0] = t.vx_mps - t.vy_mps - k * t.wz_radps;
    u[1] = t.vx_mps + t.vy_mps + k * t.wz_radps;
    u[2] = t.vx_mps + t.vy_mps - k * t.wz_radps;
    u[3] = t.vx_mps - t.vy_mps + k * t.wz_radps;
  } else {
    u[0] = t.vx_mps - 0.5 * k * t.wz_radps;
    u[1] = t.vx_mps + 0.5 * k * t.wz_radps;
  }
  return u;
}

double geometry_k(const DriveGeometry& g) {
  return g.kind == DriveKind::kMecanum ? g.lx_m + g.ly_m : g.wheel_base_m;
}

}  // namespace

WheelRadps body_twist_to_wheel_radps(const DriveGeometry& g, const BodyTwist& twist) {
  WheelRadps w = surface_ik(g.kind, geometry_k(g), twist);
  for (double& v : w) v /= g.wheel_radius_m;
  return w;
}

BodyTwist wheel_radps_to_body_twist(const DriveGeometry& g, const WheelRadps& wheels) {
  WheelRadps u{};
  for (std::size_t i = 0; i < wheel_count(g.kind); ++i) u[i] = wheels[i] * g.wheel_radius_m;
  return surface_fk(g.kind, geometry_k(g), u);
}

Pose2 integrate_twist(const Pose2& pose, const BodyTwist& twist, double dt_s) {
  double x = static_cast<double>(pose.x_m), y = static_cast<double>(pose.y_m);
  double yaw = static_cast<double>(pose.yaw_rad);
  integrate_d(&x, &y, &yaw, twist.vx_mps * dt_s, twist.vy_mps * dt_s, twist.wz_radps * dt_s);
  return Pose2{static_cast<dockcore::Real>(x), static_cast<dockcore::Real>(y), static_cast<dockcore::Real>(yaw)};
}

dockcore::Vec2 pad_point_body(const FootprintParams& f) {
  const double sign = f.pad_side == PadSide::kFront ? 1.0 : -1.0;
  double reach;
  if (f.shape == FootprintShape::kCircle) {
    reach = std::sqrt(std::max(0.0, f.radius_m * f.radius_m - f.pad_offset_y_m * f.pad_offset_y_m));
  } else {
    reach = 0.5 * f.length_m;
  }
  return dockcore::Vec2(static_cast<dockcore::Real>(f.centre_x_m + sign * reach),
                        static_cast<dockcore::Real>(f.pad_offset_y_m));
}

double pad_normal_yaw_body(const FootprintParams& f) { return f.pad_side == PadSide::kFront ? 0.0 : kPiD; }

const char* check_chassis_params(const ChassisParams& p) {
  if (!(p.dt_s > 0)) return "dt_s must be > 0";
  const DriveGeometry& g = p.geometry;
  if (!(g.wheel_radius_m > 0)) return "geometry.wheel_radius_m must be > 0";
  if (g.kind == DriveKind::kDifferential && !(g.wheel_base_m > 0)) return "geometry.wheel_base_m must be > 0";
  if (g.kind == DriveKind::kMecanum && !(g.lx_m >= 0 && g.ly_m >= 0 && g.lx_m + g.ly_m > 0))
    return "geometry.lx_m + ly_m must be > 0";
  if (p.motor.latency_steps > kMaxLatencySteps) return "motor.latency_steps exceeds kMaxLatencySteps";
  if (p.motor.time_constant_s < 0) return "motor.time_constant_s must be >= 0";
  if (p.motor.deadband_radps < 0) return "motor.deadband_radps must be >= 0";
  if (!std::isfinite(p.motor.deadband_diff_radps)) return "motor.deadband_diff_radps must be finite";
  if (p.noise.slip_sigma < 0) return "noise.slip_sigma must be >= 0";
  if (p.noise.encoder_cpr <= 0) return "noise.encoder_cpr must be > 0";
  if (p.noise.speed_window_steps < 1 || p.noise.speed_window_steps > kMaxSpeedWindowSteps)
    return "noise.speed_window_steps must be in 1..kMaxSpeedWindowSteps";
  if (!(p.noise.odom_radius_error > -1) || !(p.noise.odom_base_error > -1)) return "odometry errors must be > -1";
  const FootprintParams& f = p.footprint;
  if (f.shape == FootprintShape::kRectangle && !(f.length_m > 0 && f.width_m > 0))
    return "footprint length/width must be > 0";
  if (f.shape == FootprintShape::kCircle && !(f.radius_m > 0)) return "footprint.radius_m must be > 0";
  const double half_side = f.shape == FootprintShape::kCircle ? f.radius_m : 0.5 * f.width_m;
  if (std::fabs(f.pad_offset_y_m) > half_side) return "footprint.pad_offset_y_m lies off the footprint";
  const ContactParams& c = p.contact;
  if (c.lateral_tolerance_m < 0 || c.yaw_tolerance_rad < 0) return "contact tolerances must be >= 0";
  if (!(c.min_press_m >= 0 && c.press_limit_m >= c.min_press_m)) return "need 0 <= contact.min_press_m <= press_limit_m";
  if (c.charge_delay_s < 0 || c.charge_current_a < 0) return "contact.charge_delay_s/charge_current_a must be >= 0";
  if (!(p.battery.capacity_ah > 0)) return "battery.capacity_ah must be > 0";
  return nullptr;
}

Chassis::Chassis(const ChassisParams& params, std::uint64_t seed) : p_(params), rng_(seed), battery_(params.battery) {
  // Clamp what would index out of bounds or divide by zero; everything else is the caller's business
  // (check_chassis_params tells them).
  if (!(p_.dt_s > 0)) p_.dt_s = 0.005;
  p_.motor.latency_steps = std::min(p_.motor.latency_steps, kMaxLatencySteps);
  p_.noise.speed_window_steps = std::clamp<std::size_t>(p_.noise.speed_window_steps, 1, kMaxSpeedWindowSteps);
  p_.noise.encoder_cpr = std::max<std::int32_t>(p_.noise.encoder_cpr, 1);
  n_ = wheel_count(p_.geometry.kind);

  odom_geom_ = p_.geometry;
  odom_geom_.wheel_base_m *= 1.0 + p_.noise.odom_base_error;
  odom_geom_.lx_m *= 1.0 + p_.noise.odom_base_error;
  odom_geom_.ly_m *= 1.0 + p_.noise.odom_base_error;
  for (std::size_t i = 0; i < n_; ++i) {
    const double side = is_left_wheel(p_.geometry.kind, i) ? 0.5 : -0.5;
    odom_radius_m_[i] = p_.geometry.wheel_radius_m * (1.0 + p_.noise.odom_radius_error + side * p_.noise.odom_radius_diff);
    deadband_radps_[i] = std::max(0.0, p_.motor.deadband_radps + side * p_.motor.deadband_diff_radps);
  }

  // Start the slip processes in their stationary distribution so early steps are statistically like late ones.
  if (p_.noise.slip_sigma > 0) {
    for (std::size_t i = 0; i < n_; ++i) slip_[i] = rng_.normal(0.0, p_.noise.slip_sigma);
  }

  for (std::size_t i = 0; i < kMaxWheels; ++i) odom_last_counts_[i] = p_.noise.encoder_initial_count;
  state_.wheel_count = n_;
  publish_reported();
}

void Chassis::command_wheels(const WheelRadps& wheel_radps) {
  if (frozen_) return;
  latest_cmd_ = wheel_radps;
  for (std::size_t i = n_; i < kMaxWheels; ++i) latest_cmd_[i] = 0;
  since_cmd_s_ = 0;
}

void Chassis::command_twist(const BodyTwist& twist) { command_wheels(body_twist_to_wheel_radps(p_.geometry, twist)); }

void Chassis::step() {
  const double dt = p_.dt_s;
  const MotorParams& m = p_.motor;
  const double r = p_.geometry.wheel_radius_m;
  const double k = geometry_k(p_.geometry);

  // 1. Command source: the latest command, unless the drive has stopped itself.
  since_cmd_s_ += dt;
  WheelRadps cmd = latest_cmd_;
  const bool hold = frozen_ && freeze_motion_ == FreezeMotion::kHoldLastCommand;
  if (frozen_ && freeze_motion_ == FreezeMotion::kStop) cmd = WheelRadps{};
  if (!hold && m.command_timeout_s > 0 && since_cmd_s_ > m.command_timeout_s + 1e-12) cmd = WheelRadps{};

  // 2. Transport delay: a ring of latency_steps + 1 slots; with latency 0 the slot written is the one read.
  constexpr std::size_t cap = kMaxLatencySteps + 1;
  delay_[delay_head_] = cmd;
  WheelRadps target = delay_[(delay_head_ + cap - m.latency_steps) % cap];
  delay_head_ = (delay_head_ + 1) % cap;

  // 3. Drive electronics: deadband, saturation. 4. Motor: first-order lag (exact for a held target), accel limit.
  const double lag = m.time_constant_s > 0 ? 1.0 - std::exp(-dt / m.time_constant_s) : 1.0;
  const double slip_a = p_.noise.slip_correlation_s > 0 ? std::exp(-dt / p_.noise.slip_correlation_s) : 0.0;
  const double slip_b = std::sqrt(1.0 - slip_a * slip_a) * p_.noise.slip_sigma;
  WheelRadps dphi{};    // wheel rotation this step, rad
  WheelRadps ground{};  // ground travel under each wheel this step, m
  WheelRadps w_end{};
  for (std::size_t i = 0; i < n_; ++i) {
    double t = target[i];
    if (std::fabs(t) < deadband_radps_[i]) t = 0;
    if (m.max_speed_radps > 0) t = std::clamp(t, -m.max_speed_radps, m.max_speed_radps);
    target[i] = t;
    const double w0 = omega_[i];
    double dw = (t - w0) * lag;
    if (m.max_accel_radps2 > 0) dw = std::clamp(dw, -m.max_accel_radps2 * dt, m.max_accel_radps2 * dt);
    w_end[i] = w0 + dw;
    dphi[i] = 0.5 * (w0 + w_end[i]) * dt;
    // 5. Slip: the wheel turns by dphi but the ground moves by a slightly different amount.
    if (p_.noise.slip_sigma > 0) slip_[i] = slip_a * slip_[i] + slip_b * rng_.normal();
    ground[i] = r * dphi[i] * (1.0 + slip_[i]);
  }

  // 6. Exact arc for the displacement the wheels' ground travel implies.
  const double x0 = x_, y0 = y_, yaw0 = yaw_;
  const BodyTwist disp = surface_fk(p_.geometry.kind, k, ground);
  double xc = x0, yc = y0, yawc = yaw0;
  integrate_d(&xc, &yc, &yawc, disp.vx_mps, disp.vy_mps, disp.wz_radps);

  // 7. Dock hard stop: the pads may go at most press_limit past the contact plane. A step that would push them
  // further is cut short where they reach the stop (bisection on the fraction of the step's arc, fixed 48
  // iterations); the pressed robot neither slides along the face nor turns — friction and the pads seated in the
  // contacts hold it — so only motion that moves the pads off the face frees it. Only a crossing from the front is
  // stopped, so a robot placed behind the dock is not yanked through it.
  double frac = 1.0;
  bool at_stop = false;
  if (has_dock_) {
    const dockcore::Vec2 pad = pad_point_body(p_.footprint);
    const double px = static_cast<double>(pad.x()), py = static_cast<double>(pad.y());
    const double dxw = static_cast<double>(dock_.pose_world.x_m), dyw = static_cast<double>(dock_.pose_world.y_m);
    const double dc = std::cos(static_cast<double>(dock_.pose_world.yaw_rad));
    const double ds = std::sin(static_cast<double>(dock_.pose_world.yaw_rad));
    auto pad_in_dock = [&](double x, double y, double yaw, double* out_x, double* out_y) {
      const double wx = x + std::cos(yaw) * px - std::sin(yaw) * py - dxw;
      const double wy = y + std::sin(yaw) * px + std::cos(yaw) * py - dyw;
      *out_x = dc * wx + ds * wy;
      *out_y = -ds * wx + dc * wy;
    };
    double prev_x, prev_y, cand_x, cand_y;
    pad_in_dock(x0, y0, yaw0, &prev_x, &prev_y);
    pad_in_dock(xc, yc, yawc, &cand_x, &cand_y);
    // The spring contacts' end of travel, or what holds the pads short of the contacts.
    const double limit = dock_.stop_short_m > 0 ? -dock_.stop_short_m : p_.contact.press_limit_m;
    if (prev_x >= -limit - 1e-9 && cand_x < -limit && std::fabs(cand_y) <= dock_.face_half_width_m) {
      double lo = 0.0, hi = 1.0;
      for (int it = 0; it < 48; ++it) {
        const double mid = 0.5 * (lo + hi);
        double xm = x0, ym = y0, yawm = yaw0, mx, my;
        integrate_d(&xm, &ym, &yawm, mid * disp.vx_mps, mid * disp.vy_mps, mid * disp.wz_radps);
        pad_in_dock(xm, ym, yawm, &mx, &my);
        (mx < -limit ? hi : lo) = mid;
      }
      frac = lo;
      xc = x0, yc = y0, yawc = yaw0;
      integrate_d(&xc, &yc, &yawc, frac * disp.vx_mps, frac * disp.vy_mps, frac * disp.wz_radps);
      at_stop = true;
    }
  }
  x_ = xc;
  y_ = yc;
  yaw_ = yawc;

  // Blocked wheels turn only as far as the robot moved; their speed collapses with it.
  if (at_stop) {
    for (std::size_t i = 0; i < n_; ++i) {
      dphi[i] *= frac;
      w_end[i] *= frac;
    }
  }
  const BodyTwist achieved{frac * disp.vx_mps / dt, frac * disp.vy_mps / dt, frac * disp.wz_radps / dt};
  omega_ = w_end;

  double sum_target = 0, sum_actual = 0, sum_surface = 0;
  for (std::size_t i = 0; i < n_; ++i) {
    sum_target += std::fabs(target[i]);
    sum_actual += std::fabs(dphi[i]) / dt;
    sum_surface += std::fabs(dphi[i]) / dt * r;
  }
  const bool stalled = at_stop && sum_target > 0 && sum_actual <= p_.stall_speed_ratio * sum_target;

  // 8. Encoders: integer counts of the wheel rotation, carrying the fraction of a count forward.
  const double counts_per_rad = static_cast<double>(p_.noise.encoder_cpr) / kTwoPiD;
  for (std::size_t i = 0; i < n_; ++i) {
    count_frac_[i] += dphi[i] * counts_per_rad;
    const double whole = std::floor(count_frac_[i]);
    count_total_[i] += static_cast<std::int64_t>(whole);
    count_frac_[i] -= whole;
  }
  constexpr std::size_t hcap = kMaxSpeedWindowSteps + 1;
  count_hist_[hist_head_] = count_total_;
  const std::size_t win = p_.noise.speed_window_steps;
  const std::array<std::int64_t, kMaxWheels>& old = count_hist_[(hist_head_ + hcap - win) % hcap];
  hist_head_ = (hist_head_ + 1) % hcap;

  std::array<std::int32_t, kMaxWheels> counts{};
  for (std::size_t i = 0; i < n_; ++i) {
    counts[i] = wrap_to_i32(static_cast<std::uint32_t>(p_.noise.encoder_initial_count) +
                            static_cast<std::uint32_t>(count_total_[i]));
  }

  // 9. Odometry as the firmware computes it: wrap-aware counter deltas, its own (wrong) geometry. A frozen firmware
  // does not integrate; on recovery the accumulated delta goes in as one arc.
  if (!frozen_) {
    WheelRadps travel{};
    for (std::size_t i = 0; i < n_; ++i) {
      const std::int32_t dc = wrap_to_i32(static_cast<std::uint32_t>(counts[i]) -
                                          static_cast<std::uint32_t>(odom_last_counts_[i]));
      travel[i] = static_cast<double>(dc) / counts_per_rad * odom_radius_m_[i];
      odom_last_counts_[i] = counts[i];
    }
    const BodyTwist od = surface_fk(odom_geom_.kind, geometry_k(odom_geom_), travel);
    integrate_d(&ox_, &oy_, &oyaw_, od.vx_mps, od.vy_mps, od.wz_radps);
  }

  // Ground truth.
  state_.time_s += dt;
  state_.steps += 1;
  state_.true_twist = achieved;
  state_.wheel_target_radps = target;
  state_.wheel_true_radps = omega_;
  state_.at_hard_stop = at_stop;
  state_.stalled = stalled;
  state_.true_pose = Pose2{static_cast<dockcore::Real>(x_), static_cast<dockcore::Real>(y_),
                           static_cast<dockcore::Real>(yaw_)};

  // 10. Contacts, charger, battery.
  update_contact(dt);
  const LoadParams& ld = p_.load;
  const double draw = ld.idle_current_a + ld.motion_current_a_per_mps * sum_surface / static_cast<double>(n_) +
                      (stalled ? ld.stall_current_a : 0.0);
  battery_.step(state_.charge_current_a - draw, dt);

  // 11. Reported values (what the chassis would send).
  if (!frozen_) {
    state_.encoder_counts = counts;
    for (std::size_t i = 0; i < n_; ++i) {
      state_.wheel_measured_radps[i] =
          static_cast<double>(count_total_[i] - old[i]) / counts_per_rad / (static_cast<double>(win) * dt);
    }
    publish_reported();
  }
}

void Chassis::publish_reported() {
  state_.responding = !frozen_;
  if (state_.steps == 0) {
    for (std::size_t i = 0; i < n_; ++i) state_.encoder_counts[i] = p_.noise.encoder_initial_count;
    state_.true_pose = Pose2{static_cast<dockcore::Real>(x_), static_cast<dockcore::Real>(y_),
                             static_cast<dockcore::Real>(yaw_)};
  }
  state_.odom_pose = Pose2{static_cast<dockcore::Real>(ox_), static_cast<dockcore::Real>(oy_),
                           static_cast<dockcore::Real>(oyaw_)};
  state_.battery_current_a = battery_.current_a();
  state_.battery_voltage_v = battery_.voltage_v();
  state_.battery_soc = battery_.soc();
}

void Chassis::update_contact(double dt) {
  if (!has_dock_) {
    state_.press_m = 0;
    state_.pad_lateral_m = 0;
    state_.pad_yaw_error_rad = 0;
    state_.contact = false;
  } else {
    const dockcore::Vec2 pad = pad_point_body(p_.footprint);
    const double px = static_cast<double>(pad.x()), py = static_cast<double>(pad.y());
    const double wx = x_ + std::cos(yaw_) * px - std::sin(yaw_) * py - static_cast<double>(dock_.pose_world.x_m);
    const double wy = y_ + std::sin(yaw_) * px + std::cos(yaw_) * py - static_cast<double>(dock_.pose_world.y_m);
    const double dyaw = static_cast<double>(dock_.pose_world.yaw_rad);
    const double dx = std::cos(dyaw) * wx + std::sin(dyaw) * wy;
    const double dy = -std::sin(dyaw) * wx + std::cos(dyaw) * wy;
    // Facing the dock squarely means the pads' outward normal points along the dock's −x.
    const double yaw_err = wrap_d(yaw_ + pad_normal_yaw_body(p_.footprint) - dyaw - kPiD);
    const ContactParams& c = p_.contact;
    state_.press_m = -dx;
    state_.pad_lateral_m = dy;
    state_.pad_yaw_error_rad = yaw_err;
    // The small slack on the press bound absorbs the rounding of the hard-stop projection.
    state_.contact = std::fabs(dy) <= c.lateral_tolerance_m && std::fabs(dy) <= dock_.face_half_width_m &&
                     std::fabs(yaw_err) <= c.yaw_tolerance_rad && -dx >= c.min_press_m &&
                     -dx <= c.press_limit_m + 1e-9;
  }
  const bool can_charge = state_.contact && has_dock_ && !dock_.dead && !charge_inhibited_;
  if (can_charge) {
    contact_held_s_ += dt;
  } else {
    contact_held_s_ = 0;
  }
  // The step in which contact closes counts as 0 s held, so current starts charge_delay_s after that step.
  const bool on = can_charge && contact_held_s_ - dt >= p_.contact.charge_delay_s - 1e-9;
  state_.charging = on;
  double i_chg = 0;
  if (on) {
    i_chg = p_.contact.charge_current_a;
    const double ts = p_.contact.taper_start_soc;
    if (ts < 1.0 && battery_.soc() > ts) i_chg *= std::max(0.0, (1.0 - battery_.soc()) / (1.0 - ts));
  }
  state_.charge_current_a = i_chg;
}

std::size_t Chassis::run_for(double duration_s) {
  const double n = std::ceil(duration_s / p_.dt_s - 1e-9);
  const std::size_t steps = n > 0 ? static_cast<std::size_t>(n) : 0;
  for (std::size_t i = 0; i < steps; ++i) step();
  return steps;
}

void Chassis::set_true_pose(const Pose2& pose_world) {
  x_ = static_cast<double>(pose_world.x_m);
  y_ = static_cast<double>(pose_world.y_m);
  yaw_ = wrap_d(static_cast<double>(pose_world.yaw_rad));
  state_.true_pose = Pose2{static_cast<dockcore::Real>(x_), static_cast<dockcore::Real>(y_),
                           static_cast<dockcore::Real>(yaw_)};
}

void Chassis::reset_odometry(const Pose2& odom_pose) {
  ox_ = static_cast<double>(odom_pose.x_m);
  oy_ = static_cast<double>(odom_pose.y_m);
  oyaw_ = wrap_d(static_cast<double>(odom_pose.yaw_rad));
  if (!frozen_) state_.odom_pose = odom_pose;
}

void Chassis::set_dock(const DockPlacement& dock) {
  dock_ = dock;
  has_dock_ = true;
  contact_held_s_ = 0;
}

void Chassis::clear_dock() {
  has_dock_ = false;
  contact_held_s_ = 0;
}

void Chassis::set_battery_soc(double soc) {
  battery_.set_soc(soc);
  if (!frozen_) state_.battery_soc = battery_.soc();
}

void Chassis::apply_pose_jump(double dx_world_m, double dy_world_m, double dyaw_rad) {
  x_ += dx_world_m;
  y_ += dy_world_m;
  yaw_ = wrap_d(yaw_ + dyaw_rad);
  state_.true_pose = Pose2{static_cast<dockcore::Real>(x_), static_cast<dockcore::Real>(y_),
                           static_cast<dockcore::Real>(yaw_)};
}

void Chassis::set_frozen(bool on, FreezeMotion motion) {
  frozen_ = on;
  freeze_motion_ = motion;
  state_.responding = !on;
  if (!on) since_cmd_s_ = 0;  // the watchdog restarts with the firmware
}

void Chassis::set_charging_inhibited(bool inhibited) { charge_inhibited_ = inhibited; }

}  // namespace docksim
