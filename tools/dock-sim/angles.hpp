#pragma once
// Degree conversions for dock-sim's printed figures and command-line angles (SI radians inside).

namespace docksim_cli {

/// Radians per degree: `deg * kDeg` is radians, `rad / kDeg` is degrees.
constexpr double kDeg = 3.14159265358979323846 / 180.0;
/// Degrees per radian, for printed figures.
constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

}  // namespace docksim_cli
