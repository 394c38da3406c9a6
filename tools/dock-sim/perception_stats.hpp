#pragma once
// Error measures shared by the `dock-sim perception` sections (perception.cpp, perception_generated.cpp).
#include <algorithm>
#include <cmath>
#include <vector>

#include "dockcore/geometry.hpp"

namespace docksim_cli {

/// Errors of one detection against the truth, in the dock frame (longitudinal = along the dock's x axis).
struct Errors {
  double pos_m = 0, lon_m = 0, lat_m = 0, yaw_rad = 0;
};

/// Errors of `est` against `truth`, both in the same frame. O(1).
inline Errors errors_of(const dockcore::Pose2& truth, const dockcore::Pose2& est) {
  const dockcore::Vec2 d(est.x_m - truth.x_m, est.y_m - truth.y_m);
  const dockcore::Vec2 ex(std::cos(truth.yaw_rad), std::sin(truth.yaw_rad));
  Errors e;
  e.pos_m = static_cast<double>(d.norm());
  e.lon_m = std::fabs(static_cast<double>(d.dot(ex)));
  e.lat_m = std::fabs(static_cast<double>(ex.x() * d.y() - ex.y() * d.x()));
  e.yaw_rad = std::fabs(static_cast<double>(dockcore::wrap_angle(est.yaw_rad - truth.yaw_rad)));
  return e;
}

/// The p-quantile (0..1) of v, linearly interpolated; NaN for an empty v. O(n log n).
inline double percentile(std::vector<double> v, double p) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const double idx = p * static_cast<double>(v.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(std::floor(idx));
  const std::size_t hi = std::min(v.size() - 1, lo + 1);
  return v[lo] + (v[hi] - v[lo]) * (idx - static_cast<double>(lo));
}

}  // namespace docksim_cli
