#pragma once
/// @file Drive kinematics: body twist <-> wheel angular velocities for differential and mecanum drives, saturation
/// that keeps the commanded path's curvature, and an acceleration limiter. Wheel order and signs are exactly those of
/// the simulated chassis (tools/sim/include/docksim/chassis.hpp) and of the CAN wheel frames: differential 0 left,
/// 1 right; mecanum 0 front-left, 1 front-right, 2 rear-left, 3 rear-right (rollers in "X" layout); rad/s, positive
/// when the wheel rolls the robot forward on either side.

#include <cstddef>
#include <cstdint>

#include "dockcore/control/controller.hpp"
#include "dockcore/geometry.hpp"

namespace dockcore {

/// Wheel arrangement.
enum class DriveKind : std::uint8_t { kDifferential = 0, kMecanum = 1 };

/// Most wheels any supported drive has.
constexpr std::size_t kMaxDriveWheels = 4;

/// Drive geometry. Positive, finite lengths are a precondition of every function below.
struct DriveGeometry {
  DriveKind kind = DriveKind::kDifferential;
  Real wheel_radius_m = static_cast<Real>(0.05);  ///< Rolling radius of every wheel.
  Real wheel_base_m = static_cast<Real>(0.30);    ///< Differential: left-right contact point distance (track).
  Real lx_m = static_cast<Real>(0.15);            ///< Mecanum: half the front-rear wheel distance.
  Real ly_m = static_cast<Real>(0.15);            ///< Mecanum: half the left-right wheel distance.
};

/// Limits of the drive. A value <= 0 means "unlimited" for that entry.
struct DriveLimits {
  Real max_vx_mps = static_cast<Real>(0.5);        ///< |forward speed|.
  Real max_vy_mps = static_cast<Real>(0.3);        ///< |sideways speed| (mecanum only).
  Real max_wz_radps = static_cast<Real>(1.0);      ///< |yaw rate|.
  Real max_wheel_radps = static_cast<Real>(20.0);  ///< |any wheel's angular velocity|.
  Real max_linear_accel_mps2 = static_cast<Real>(0.5);    ///< |d vx/dt| and |d vy/dt|.
  Real max_angular_accel_radps2 = static_cast<Real>(2.0); ///< |d wz/dt|.
};

/// Wheel angular velocities, rad/s, in the order described in the file comment. Entries >= count are 0.
struct WheelSpeeds {
  Real radps[kMaxDriveWheels] = {0, 0, 0, 0};
  std::size_t count = 2;
};

/// Number of driven wheels: 2 (differential) or 4 (mecanum). O(1).
inline std::size_t drive_wheel_count(DriveKind k) { return k == DriveKind::kMecanum ? 4u : 2u; }

/// The part of `twist` the drive can realise: a differential drive cannot move sideways, so vy is dropped (set to 0);
/// mecanum keeps all three. O(1).
Twist2 drive_feasible(const DriveGeometry& g, const Twist2& twist);

/// Inverse kinematics: the wheel angular velocities that realise `twist` without slip. Differential: ωL = (vx −
/// wz·B/2)/r, ωR = (vx + wz·B/2)/r, vy ignored. Mecanum with k = lx + ly: ωFL = (vx − vy − k·wz)/r, ωFR = (vx + vy +
/// k·wz)/r, ωRL = (vx + vy − k·wz)/r, ωRR = (vx − vy + k·wz)/r. Identical to docksim::body_twist_to_wheel_radps. O(1).
WheelSpeeds twist_to_wheels(const DriveGeometry& g, const Twist2& twist);

/// Forward kinematics: the body twist produced by wheel speeds; for mecanum the least-squares twist (exact for
/// consistent wheels). Wheels beyond the drive's count are ignored. O(1).
Twist2 wheels_to_twist(const DriveGeometry& g, const WheelSpeeds& wheels);

/// The largest factor s in (0, 1] such that s·twist satisfies every velocity limit of `lim` (|vx|, |vy|, |wz| and
/// every wheel of twist_to_wheels). 1 when no limit binds. Non-finite twist components give 0. O(1).
Real saturation_factor(const DriveGeometry& g, const DriveLimits& lim, const Twist2& twist);

/// Scales the drive-feasible part of `twist` by saturation_factor: one common factor, so the ratios vx : vy : wz —
/// and hence the path's curvature — are kept while every limit holds. `factor_out` (optional) receives the factor.
/// Non-finite input gives a zero twist. O(1).
Twist2 saturate_twist(const DriveGeometry& g, const DriveLimits& lim, const Twist2& twist, Real* factor_out = nullptr);

/// Rate limit between ticks: moves from `previous` towards `desired` so that no component changes faster than
/// lim's accelerations over dt_s. Preference 1: output = k·desired with the largest k in [0, 1] that is reachable
/// from `previous` — the output then has exactly the desired curvature (always possible when previous is parallel to
/// desired, e.g. while accelerating or decelerating along one arc, or from rest). Preference 2 (no such k, e.g. the
/// curvature flips): output = previous + s·(desired − previous) with one common s, so the change keeps its direction.
/// dt_s <= 0 or non-finite input returns `previous` unchanged (or zero when previous itself is non-finite). O(1).
Twist2 limit_acceleration(const DriveLimits& lim, const Twist2& previous, const Twist2& desired, Real dt_s);

}  // namespace dockcore
