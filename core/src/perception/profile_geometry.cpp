#include "dockcore/perception/profile_geometry.hpp"

namespace dockcore {

void PlacedProfile::place(const DockProfile& profile, const Pose2& dock_in_sensor) {
  const Real c = std::cos(dock_in_sensor.yaw_rad);
  const Real s = std::sin(dock_in_sensor.yaw_rad);
  x_axis = Vec2(c, s);
  const std::size_t nv = profile.vertex_count;
  for (std::size_t i = 0; i < nv; ++i) {
    const Vec2& p = profile.vertices_m[i];
    v_m[i] = Vec2(dock_in_sensor.x_m + c * p.x() - s * p.y(), dock_in_sensor.y_m + s * p.x() + c * p.y());
  }

  segments = profile.segment_count();
  for (std::size_t i = 0; i < segments; ++i) {
    const Vec2 d = v_m[i + 1] - v_m[i];
    d_m[i] = d;
    len_m[i] = d.norm();
    inv_len_sq[i] = 1 / d.squaredNorm();
    u[i] = d / len_m[i];
    n[i] = Vec2(d.y(), -d.x()) / len_m[i];
    c_m[i] = n[i].dot(v_m[i]);
    // The sensor sits at the origin: it sees the outward side when n·(0 - v) > 0, i.e. c < 0.
    visible[i] = c_m[i] < 0;
  }
}

bool PlacedProfile::raycast(const Vec2& dir, Real* range_m, std::size_t* segment) const {
  // The ray's line separates a segment's ends exactly when it crosses the segment: the side of each vertex is the
  // sign of cross(dir, v). A visible segment faced from the front (n·dir < 0, c < 0) is then hit at t = c / (n·dir)
  // > 0, so only crossed segments cost a division.
  bool hit = false;
  Real best = 0;
  std::size_t best_seg = 0;
  Real side_a = dir.x() * v_m[0].y() - dir.y() * v_m[0].x();
  for (std::size_t i = 0; i < segments; ++i) {
    const Real side_b = dir.x() * v_m[i + 1].y() - dir.y() * v_m[i + 1].x();
    const bool crosses = (side_a <= 0 && side_b >= 0) || (side_a >= 0 && side_b <= 0);
    side_a = side_b;
    if (!visible[i] || !crosses) continue;
    const Real denom = n[i].dot(dir);
    if (denom >= 0) continue;  // grazing or from behind
    const Real t = c_m[i] / denom;
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
  std::size_t best_seg = 0;
  const Real px = p.x();
  const Real py = p.y();
  for (std::size_t i = 0; i < segments; ++i) {
    if (!visible[i]) continue;
    const Real wx = px - v_m[i].x();
    const Real wy = py - v_m[i].y();
    const Real dx = d_m[i].x();
    const Real dy = d_m[i].y();
    const Real u_raw = (wx * dx + wy * dy) * inv_len_sq[i];
    const Real t = u_raw < 0 ? 0 : (u_raw > 1 ? 1 : u_raw);
    const Real ex = wx - t * dx;
    const Real ey = wy - t * dy;
    const Real dist_sq = ex * ex + ey * ey;
    if (!any || dist_sq < best_sq) {
      any = true;
      best_sq = dist_sq;
      best_over = u_raw - t;
      best_seg = i;
    }
  }
  if (any) {
    *segment = best_seg;
    *distance_m = std::sqrt(best_sq);
    *overhang_m = std::fabs(best_over) * len_m[best_seg];
    *signed_line_distance_m = n[best_seg].dot(p) - c_m[best_seg];
  }
  return any;
}

void PlacedProfile::bounding_box(Vec2* lo_m, Vec2* hi_m) const {
  Vec2 lo = v_m[0];
  Vec2 hi = v_m[0];
  for (std::size_t i = 1; i <= segments; ++i) {
    lo = lo.cwiseMin(v_m[i]);
    hi = hi.cwiseMax(v_m[i]);
  }
  *lo_m = lo;
  *hi_m = hi;
}

void PlacedProfile::angular_span(Real* lo_rad, Real* hi_rad) const {
  // Each vertex's bearing relative to the first, from the cross and dot products: already within (-pi, pi].
  const Vec2& a = v_m[0];
  const Real ref = std::atan2(a.y(), a.x());
  // While every vertex lies within 90 degrees of the first, the sign of a cross product orders two bearings exactly,
  // so only the two extreme vertices need an arctangent. Otherwise (a sensor almost inside the dock) each does.
  bool half_plane = true;
  std::size_t i_lo = 0;
  std::size_t i_hi = 0;
  for (std::size_t i = 1; i <= segments && half_plane; ++i) {
    const Vec2& b = v_m[i];
    half_plane = a.dot(b) > 0;
    const Vec2& l = v_m[i_lo];
    const Vec2& h = v_m[i_hi];
    if (l.x() * b.y() - l.y() * b.x() < 0) i_lo = i;
    if (h.x() * b.y() - h.y() * b.x() > 0) i_hi = i;
  }
  Real lo = 0;
  Real hi = 0;
  auto rel = [&a](const Vec2& b) { return std::atan2(a.x() * b.y() - a.y() * b.x(), a.x() * b.x() + a.y() * b.y()); };
  if (half_plane) {
    if (i_lo != 0) lo = rel(v_m[i_lo]);
    if (i_hi != 0) hi = rel(v_m[i_hi]);
  } else {
    for (std::size_t i = 1; i <= segments; ++i) {
      const Real r = rel(v_m[i]);
      lo = r < lo ? r : lo;
      hi = r > hi ? r : hi;
    }
  }
  *lo_rad = ref + lo;
  *hi_rad = ref + hi;
}

}  // namespace dockcore
