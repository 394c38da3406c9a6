#pragma once
/// @file Tolerances for checks on values that passed through core's `Real` (double, or float with
/// DOCKCORE_REAL_FLOAT), for tests that run in both builds.
///
/// REAL_EQUAL(expected, actual, tol) is DOUBLES_EQUAL with the tolerance floored at 4 units in the last place of
/// `Real` at the magnitude of `expected` (at least 1). Why: a float cannot hold 0.1 closer than 1.5e-9, so a 1e-9
/// check on a value stored in a float fails by representation alone, whatever the code does. With Real = double the
/// floor is 8.9e-16 × max(1, |expected|), below every tolerance the suites use, so the double build is exactly as
/// strict as before. Differences beyond a few float ulps are not hidden by this: they still fail and are handled
/// (and explained) where they occur.
#include <algorithm>
#include <cmath>
#include <limits>

#include "dockcore/geometry.hpp"

namespace dockcore_test {

/// max(tol, `ulps` units in the last place of Real at max(1, |magnitude|)). Use more than the default 4 ulps only
/// where the value went through a chain of roundings, and say which at the call. O(1).
inline double real_tol(double magnitude, double tol, double ulps = 4.0) {
  const double ulp = static_cast<double>(std::numeric_limits<dockcore::Real>::epsilon()) *
                     std::max(1.0, std::fabs(magnitude));
  return std::max(tol, ulps * ulp);
}

/// A core pose from double test values (the simulator and test arithmetic are double; Real may be float, where a
/// braced Pose2{double, ...} is a narrowing error). O(1).
inline dockcore::Pose2 pose(double x_m, double y_m, double yaw_rad) {
  return dockcore::Pose2{static_cast<dockcore::Real>(x_m), static_cast<dockcore::Real>(y_m),
                         static_cast<dockcore::Real>(yaw_rad)};
}

}  // namespace dockcore_test

#define REAL_EQUAL(expected, actual, tol) \
  DOUBLES_EQUAL((expected), (actual), ::dockcore_test::real_tol(static_cast<double>(expected), (tol)))
