#pragma once
// The simulator's angle constants, in double whatever core's Real: the world is simulated in double.

namespace docksim {

/// π in double.
constexpr double kPiD = 3.14159265358979323846;
/// 2π in double.
constexpr double kTwoPiD = 2.0 * kPiD;
/// Radians per degree: `deg * kDegD` is radians, `rad / kDegD` is degrees.
constexpr double kDegD = kPiD / 180.0;

}  // namespace docksim
