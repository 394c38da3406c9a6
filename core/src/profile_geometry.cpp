#include "dockcore/profile_geometry.hpp"

namespace dockcore {

void PlacedProfile::place(const DockProfile& profile, const Pose2& dock_in_sensor) {
  const Real c = std::cos(dock_in_sensor.yaw_rad);
  const Real s = std::sin(dock_in_sensor.yaw_rad);
  const std::size_t nv = profile.vertex_count;
  for (std::size_t i = 0; i < nv; ++i) {
    const Vec2& p = profile.vertices_m[i];
    v_m[i] = Vec2(dock_in_sensor.x_m + c * p.x() - s * p.y(), dock_in_sensor.y_m + s * p.x() + c * p.y());
  }
  segments = profile.segment_count();
  for (std::size_t i = 0; i < segments; ++i) {
    const Vec2 d = v_m[i + 1] - v_m[i];
    n[i] = Vec2(d.y(), -d.x()) / d.norm();
    c_m[i] = n[i].dot(v_m[i]);
    // The sensor sits at the origin: it sees the outward side when n·(0 - v) > 0, i.e. c < 0.
    visible[i] = c_m[i] < 0;
  }
}

bool PlacedProfile::raycast(const Vec2& dir, Real* range_m, std::size_t* segment) const {
  bool hit = false;
  Real best = 0;
  std::size_t best_seg = 0;
  for (std::size_t i = 0; i < segments; ++i) {
    if (!visible[i]) continue;
    const Real denom = n[i].dot(dir);
    if (denom >= 0) continue;  // grazing or from behind
    const Real t = c_m[i] / denom;
    if (t <= 0) continue;
    const Vec2 p = t * dir;
    // Inside the segment: the projection on its direction lies within [0, len].
    const Vec2 d = v_m[i + 1] - v_m[i];
    const Real u = (p - v_m[i]).dot(d);
    if (u < 0 || u > d.squaredNorm()) continue;
    if (!hit || t < best) {
      hit = true;
      best = t;
      best_seg = i;
    }
  }
  if (hit) {
    *range_m = best;
    *segment = best_seg;
  }
  return hit;
}

bool PlacedProfile::nearest(const Vec2& p, std::size_t* segment, Real* distance_m, Real* signed_line_distance_m,
                            Real* overhang_m) const {
  bool any = false;
  Real best_sq = 0;
  Real best_over = 0;
  for (std::size_t i = 0; i < segments; ++i) {
    if (!visible[i]) continue;
    const Vec2 d = v_m[i + 1] - v_m[i];
    const Vec2 w = p - v_m[i];
    const Real u_raw = w.dot(d) / d.squaredNorm();
    const Real u = u_raw < 0 ? 0 : (u_raw > 1 ? 1 : u_raw);
    const Real dist_sq = (w - u * d).squaredNorm();
    if (!any || dist_sq < best_sq) {
      any = true;
      best_sq = dist_sq;
      best_over = std::fabs(u_raw - u) * d.norm();
      *segment = i;
    }
  }
  if (any) {
    *distance_m = std::sqrt(best_sq);
    *overhang_m = best_over;
    *signed_line_distance_m = n[*segment].dot(p) - c_m[*segment];
  }
  return any;
}

void PlacedProfile::angular_span(Real* lo_rad, Real* hi_rad) const {
  const Real ref = std::atan2(v_m[0].y(), v_m[0].x());
  Real lo = 0;
  Real hi = 0;
  for (std::size_t i = 1; i <= segments; ++i) {
    const Real rel = wrap_angle(std::atan2(v_m[i].y(), v_m[i].x()) - ref);
    lo = rel < lo ? rel : lo;
    hi = rel > hi ? rel : hi;
  }
  *lo_rad = ref + lo;
  *hi_rad = ref + hi;
}

}  // namespace dockcore
