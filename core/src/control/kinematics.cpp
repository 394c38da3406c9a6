#include "dockcore/control/kinematics.hpp"

#include <cmath>

namespace dockcore {
namespace {

bool finite_twist(const Twist2& t) {
  return std::isfinite(t.vx_mps) && std::isfinite(t.vy_mps) && std::isfinite(t.wz_radps);
}

// Tightens *factor so that factor·|value| <= limit (limit <= 0: no limit).
void tighten(Real value, Real limit, Real* factor) {
  const Real a = std::fabs(value);
  if (limit > 0 && a > limit) {
    const Real f = limit / a;
    if (f < *factor) *factor = f;
  }
}

// Intersects [*lo, *hi] with the k for which |k·d − p| <= a (a <= 0: unlimited). Returns false when empty.
bool intersect_reachable(Real d, Real p, Real a, Real* lo, Real* hi) {
  if (!(a > 0)) return true;
  if (d == 0) return std::fabs(p) <= a;
  Real k1 = (p - a) / d;
  Real k2 = (p + a) / d;
  if (k1 > k2) {
    const Real t = k1;
    k1 = k2;
    k2 = t;
  }
  if (k1 > *lo) *lo = k1;
  if (k2 < *hi) *hi = k2;
  return *lo <= *hi;
}

}  // namespace

Twist2 drive_feasible(const DriveGeometry& g, const Twist2& twist) {
  Twist2 t = twist;
  if (g.kind != DriveKind::kMecanum) t.vy_mps = 0;
  return t;
}

WheelSpeeds twist_to_wheels(const DriveGeometry& g, const Twist2& t) {
  WheelSpeeds w;
  w.count = drive_wheel_count(g.kind);
  const Real inv_r = static_cast<Real>(1) / g.wheel_radius_m;
  if (g.kind == DriveKind::kMecanum) {
    const Real k = g.lx_m + g.ly_m;
    w.radps[0] = (t.vx_mps - t.vy_mps - k * t.wz_radps) * inv_r;
    w.radps[1] = (t.vx_mps + t.vy_mps + k * t.wz_radps) * inv_r;
    w.radps[2] = (t.vx_mps + t.vy_mps - k * t.wz_radps) * inv_r;
    w.radps[3] = (t.vx_mps - t.vy_mps + k * t.wz_radps) * inv_r;
  } else {
    const Real half_b = static_cast<Real>(0.5) * g.wheel_base_m;
    w.radps[0] = (t.vx_mps - half_b * t.wz_radps) * inv_r;
    w.radps[1] = (t.vx_mps + half_b * t.wz_radps) * inv_r;
  }
  return w;
}

Twist2 wheels_to_twist(const DriveGeometry& g, const WheelSpeeds& w) {
  Twist2 t;
  const Real r = g.wheel_radius_m;
  if (g.kind == DriveKind::kMecanum) {
    const Real k = g.lx_m + g.ly_m;
    const Real q = static_cast<Real>(0.25) * r;
    t.vx_mps = q * (w.radps[0] + w.radps[1] + w.radps[2] + w.radps[3]);
    t.vy_mps = q * (-w.radps[0] + w.radps[1] + w.radps[2] - w.radps[3]);
    t.wz_radps = q * (-w.radps[0] + w.radps[1] - w.radps[2] + w.radps[3]) / k;
  } else {
    t.vx_mps = static_cast<Real>(0.5) * r * (w.radps[0] + w.radps[1]);
    t.wz_radps = r * (w.radps[1] - w.radps[0]) / g.wheel_base_m;
  }
  return t;
}

Real saturation_factor(const DriveGeometry& g, const DriveLimits& lim, const Twist2& twist) {
  if (!finite_twist(twist)) return 0;
  const Twist2 t = drive_feasible(g, twist);
  Real f = 1;
  tighten(t.vx_mps, lim.max_vx_mps, &f);
  tighten(t.vy_mps, lim.max_vy_mps, &f);
  tighten(t.wz_radps, lim.max_wz_radps, &f);
  // Wheel speeds are linear in the twist, so one factor scales them all alike.
  const WheelSpeeds w = twist_to_wheels(g, t);
  for (std::size_t i = 0; i < w.count; ++i) tighten(w.radps[i], lim.max_wheel_radps, &f);
  return f;
}

Twist2 saturate_twist(const DriveGeometry& g, const DriveLimits& lim, const Twist2& twist, Real* factor_out) {
  const Real f = saturation_factor(g, lim, twist);
  if (factor_out != nullptr) *factor_out = f;
  if (!(f > 0)) return Twist2{};
  const Twist2 t = drive_feasible(g, twist);
  return Twist2{t.vx_mps * f, t.vy_mps * f, t.wz_radps * f};
}

Twist2 limit_acceleration(const DriveLimits& lim, const Twist2& previous, const Twist2& desired, Real dt_s) {
  if (!finite_twist(previous)) return Twist2{};
  if (!(dt_s > 0) || !std::isfinite(dt_s) || !finite_twist(desired)) return previous;
  const Real a_lin = lim.max_linear_accel_mps2 > 0 ? lim.max_linear_accel_mps2 * dt_s : 0;
  const Real a_ang = lim.max_angular_accel_radps2 > 0 ? lim.max_angular_accel_radps2 * dt_s : 0;

  // Preference 1: a scaled copy of the desired twist (same curvature), as large as reachable.
  Real lo = 0;
  Real hi = 1;
  if (intersect_reachable(desired.vx_mps, previous.vx_mps, a_lin, &lo, &hi) &&
      intersect_reachable(desired.vy_mps, previous.vy_mps, a_lin, &lo, &hi) &&
      intersect_reachable(desired.wz_radps, previous.wz_radps, a_ang, &lo, &hi)) {
    return Twist2{hi * desired.vx_mps, hi * desired.vy_mps, hi * desired.wz_radps};
  }
  // Preference 2: one common step along the change.
  const Twist2 d{desired.vx_mps - previous.vx_mps, desired.vy_mps - previous.vy_mps,
                 desired.wz_radps - previous.wz_radps};
  Real s = 1;
  tighten(d.vx_mps, a_lin, &s);
  tighten(d.vy_mps, a_lin, &s);
  tighten(d.wz_radps, a_ang, &s);
  return Twist2{previous.vx_mps + s * d.vx_mps, previous.vy_mps + s * d.vy_mps, previous.wz_radps + s * d.wz_radps};
}

}  // namespace dockcore
