// Scans raycast from seed 000's built-in "breakpoint" dock standing against a wall, for the tests of
// BreakpointDetector and of Dockcore with that detector. Include it after the standard and dockcore headers and
// before CppUTest's (it uses CppUTest's checks).
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>

#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/dock_profile.hpp"

#include <CppUTest/TestHarness.h>

namespace breakpoint_scene {

using dockcore::Pose2;
using dockcore::Real;
using dockcore::Vec2;

inline Real cross2(const Vec2& a, const Vec2& b) {
  return a.x() * b.y() - a.y() * b.x();
}

/// Line segments, and the nearest hit of a ray among them.
struct Scene {
  Vec2 a[64];
  Vec2 b[64];
  std::size_t n = 0;
  void add(const Vec2& p, const Vec2& q) {
    a[n] = p;
    b[n] = q;
    ++n;
  }
  /// Nearest hit of o + t (cos, sin)(angle), t > 0, or inf.
  Real cast(const Vec2& o, Real angle) const {
    const Vec2 d(std::cos(angle), std::sin(angle));
    Real best = std::numeric_limits<Real>::infinity();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2 e = b[i] - a[i];
      const Real den = cross2(d, e);
      if (std::fabs(den) < static_cast<Real>(1e-12)) continue;
      const Vec2 ao = a[i] - o;
      const Real t = cross2(ao, e) / den;
      const Real u = cross2(ao, d) / den;
      if (t > static_cast<Real>(1e-9) && u >= 0 && u <= 1 && t < best) best = t;
    }
    return best;
  }
};

/// The "breakpoint" profile at dock_pose (dock frame -> lidar frame) with its back (dock x = -0.10) flush against a
/// wall running wall_half_m either side of the dock's axis.
inline void add_dock_against_wall(Scene& s, const Pose2& dock_pose, Real wall_half_m = 3) {
  dockcore::DockProfile p;
  CHECK_EQUAL(static_cast<int>(dockcore::ProfileError::kOk),
              static_cast<int>(dockcore::builtin_profile("breakpoint", p)));
  for (std::size_t i = 0; i + 1 < p.vertex_count; ++i)
    s.add(dock_pose.transform(p.vertices_m[i]), dock_pose.transform(p.vertices_m[i + 1]));
  const Real back_x_m = static_cast<Real>(-0.10);
  s.add(dock_pose.transform(Vec2(back_x_m, -wall_half_m)), dock_pose.transform(Vec2(back_x_m, wall_half_m)));
}

/// Raycasts `count` beams from the lidar frame's origin into `scan`. Misses (and hits beyond 12 m) are inf, like a
/// ROS driver.
template <std::size_t N>
void render(const Scene& s, dockcore::LaserScanN<N>& scan, std::size_t count, Real angle_min_rad, Real inc_rad) {
  CHECK_TRUE(scan.reset(count, angle_min_rad, inc_rad, 0));
  for (std::size_t i = 0; i < count; ++i) {
    const Real r = s.cast(Vec2(0, 0), scan.angle_min_rad + static_cast<Real>(i) * inc_rad);
    scan.ranges_m[i] = r > 12 ? std::numeric_limits<Real>::infinity() : r;
  }
}

}  // namespace breakpoint_scene
