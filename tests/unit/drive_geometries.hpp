#pragma once
/// @file The drive geometries the kinematics and odometry suites share: a differential drive (r 5 cm, track 30 cm) and
/// a mecanum base (r 4 cm, lx 20 cm, ly 15 cm), with twists built from double test values.
#include "dockcore/control/kinematics.hpp"
#include "dockcore/geometry.hpp"

namespace dockcore_test {

inline dockcore::DriveGeometry diff_geom() {
  dockcore::DriveGeometry g;
  g.kind = dockcore::DriveKind::kDifferential;
  g.wheel_radius_m = static_cast<dockcore::Real>(0.05);
  g.wheel_base_m = static_cast<dockcore::Real>(0.30);
  return g;
}

inline dockcore::DriveGeometry mec_geom() {
  dockcore::DriveGeometry g;
  g.kind = dockcore::DriveKind::kMecanum;
  g.wheel_radius_m = static_cast<dockcore::Real>(0.04);
  g.lx_m = static_cast<dockcore::Real>(0.2);
  g.ly_m = static_cast<dockcore::Real>(0.15);
  return g;
}

/// A core twist from double test values (Real may be float). O(1).
inline dockcore::Twist2 tw(double vx, double vy, double wz) {
  return dockcore::Twist2{static_cast<dockcore::Real>(vx), static_cast<dockcore::Real>(vy),
                          static_cast<dockcore::Real>(wz)};
}

}  // namespace dockcore_test
