#pragma once
/// @file Robot starts around a dock for the controller suites (test_controllers, test_controllers_closed_loop): the
/// dock frame is the world frame, the dock origin is the contact point, control runs at 50 Hz.
#include <cmath>

#include "dockcore/geometry.hpp"

namespace dockcore_test {

constexpr double kPiD = 3.14159265358979323846;
constexpr double kCtlDt = 0.02;      // 50 Hz control
constexpr double kPadReach = 0.225;  // the controllers' default pad_reach_m: docksim's default 0.45 m footprint

/// Degrees to radians. O(1).
inline double deg(double d) {
  return d * kPiD / 180.0;
}

/// `a` wrapped into (-π, π]. O(1).
inline double wrapd(double a) {
  double r = std::remainder(a, 2.0 * kPiD);
  if (r <= -kPiD) r += 2.0 * kPiD;
  return r;
}

struct Start {
  double dist_m, bearing_deg, heading_deg;
};

/// Robot centre at dist from the dock origin at `bearing` in the dock frame, heading = facing the dock origin +
/// offset. backwards: the rear faces the dock origin instead. O(1).
inline dockcore::Pose2 start_pose(const Start& s, bool backwards) {
  using dockcore::Real;
  const double x = s.dist_m * std::cos(deg(s.bearing_deg));
  const double y = s.dist_m * std::sin(deg(s.bearing_deg));
  const double yaw = std::atan2(-y, -x) + deg(s.heading_deg) + (backwards ? kPiD : 0.0);
  return dockcore::Pose2{static_cast<Real>(x), static_cast<Real>(y), static_cast<Real>(wrapd(yaw))};
}

}  // namespace dockcore_test
