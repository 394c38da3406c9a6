#pragma once
// Degree conversions for dock-sim's printed figures and command-line angles (SI radians inside).

#include "docksim/angles.hpp"

namespace docksim_cli {

/// Radians per degree: `deg * kDeg` is radians, `rad / kDeg` is degrees.
constexpr double kDeg = docksim::kDegD;
/// Degrees per radian, for printed figures.
constexpr double kRadToDeg = 180.0 / docksim::kPiD;

}  // namespace docksim_cli
