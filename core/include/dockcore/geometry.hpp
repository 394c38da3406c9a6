#pragma once
/// @file Scalar type, 2D vectors and SE(2) poses shared by every core module.
/// Units: metres and radians, right-handed frames, x forward, y left, yaw counter-clockwise.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>

namespace dockcore {

#if defined(DOCKCORE_REAL_FLOAT) && DOCKCORE_REAL_FLOAT
using Real = float;  ///< Core scalar: float for MCUs with a single-precision FPU.
#else
using Real = double;  ///< Core scalar: double by default.
#endif

using Vec2 = Eigen::Matrix<Real, 2, 1>;
using Vec3 = Eigen::Matrix<Real, 3, 1>;
using Mat2 = Eigen::Matrix<Real, 2, 2>;
using Mat3 = Eigen::Matrix<Real, 3, 3>;

constexpr Real kPi = static_cast<Real>(3.14159265358979323846);
constexpr Real kTwoPi = static_cast<Real>(6.28318530717958647692);

/// Degrees to radians. O(1).
constexpr Real deg_to_rad(Real deg) { return deg * kPi / static_cast<Real>(180); }
/// Radians to degrees. O(1).
constexpr Real rad_to_deg(Real rad) { return rad * static_cast<Real>(180) / kPi; }
/// A double constant (a literal, a datasheet or tolerance value) as a Real. O(1).
constexpr Real to_real(double v) {
  return static_cast<Real>(v);
}

/// `v` limited to [-limit, limit]; `limit` >= 0. A NaN `v` is returned unchanged. O(1).
inline Real clamp_abs(Real v, Real limit) {
  if (v > limit) return limit;
  if (v < -limit) return -limit;
  return v;
}

/// Wraps an angle to (-pi, pi]. Finite input required; O(1) for any magnitude (uses remainder, no loop).
inline Real wrap_angle(Real angle_rad) {
  // Within three half-turns of zero one subtraction is the remainder, exactly (Sterbenz: the operands are within a
  // factor of two), and far cheaper than std::remainder on a microcontroller.
  Real a = angle_rad;
  if (a > kPi && a < 3 * kPi) {
    a -= kTwoPi;
  } else if (a < -kPi && a > -3 * kPi) {
    a += kTwoPi;
  } else if (!(a >= -kPi && a <= kPi)) {
    a = std::remainder(angle_rad, kTwoPi);  // [-pi, pi]
  }
  if (a <= -kPi) a += kTwoPi;
  return a;
}

/// Rotation by `angle_rad` about axis `axis` (0 = x, 1 = y, 2 = z) as a 3×3 matrix; about z it also turns an
/// (x, y, yaw) covariance by a yaw. Precondition: axis in 0..2. O(1): one cos and one sin.
inline Mat3 axis_rotation(int axis, Real angle_rad) {
  const Real c = std::cos(angle_rad);
  const Real s = std::sin(angle_rad);
  const int i = (axis + 1) % 3;
  const int j = (axis + 2) % 3;
  Mat3 r = Mat3::Identity();
  r(i, i) = c;
  r(i, j) = -s;
  r(j, i) = s;
  r(j, j) = c;
  return r;
}

/// Inverse of a symmetric 3x3 matrix by cofactors (closed form: no pivoting loops, no Eigen decompositions, whose
/// generic code paths reference malloc). Returns false, leaving `out` alone, when |det| is not above
/// `min_abs_det` or not finite. O(1).
inline bool invert_sym3(const Mat3& a, Mat3* out, Real min_abs_det = 0) {
  const Real c00 = a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1);
  const Real c01 = a(1, 2) * a(2, 0) - a(1, 0) * a(2, 2);
  const Real c02 = a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0);
  const Real det = a(0, 0) * c00 + a(0, 1) * c01 + a(0, 2) * c02;
  if (!std::isfinite(det) || !(std::fabs(det) > min_abs_det)) return false;
  const Real inv_det = static_cast<Real>(1) / det;
  Mat3 r;
  r(0, 0) = c00 * inv_det;
  r(1, 0) = c01 * inv_det;
  r(2, 0) = c02 * inv_det;
  r(0, 1) = (a(0, 2) * a(2, 1) - a(0, 1) * a(2, 2)) * inv_det;
  r(1, 1) = (a(0, 0) * a(2, 2) - a(0, 2) * a(2, 0)) * inv_det;
  r(2, 1) = (a(0, 1) * a(2, 0) - a(0, 0) * a(2, 1)) * inv_det;
  r(0, 2) = (a(0, 1) * a(1, 2) - a(0, 2) * a(1, 1)) * inv_det;
  r(1, 2) = (a(0, 2) * a(1, 0) - a(0, 0) * a(1, 2)) * inv_det;
  r(2, 2) = (a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0)) * inv_det;
  *out = r;
  return true;
}

/// A pose in SE(2): position of a frame's origin and the heading of its x axis, expressed in a parent frame.
struct Pose2 {
  Real x_m = 0;
  Real y_m = 0;
  Real yaw_rad = 0;

  /// Maps a point given in this pose's frame to the parent frame. O(1).
  Vec2 transform(const Vec2& p) const {
    const Real c = std::cos(yaw_rad);
    const Real s = std::sin(yaw_rad);
    return {x_m + c * p.x() - s * p.y(), y_m + s * p.x() + c * p.y()};
  }
  /// Maps a point given in the parent frame into this pose's frame. O(1).
  Vec2 inverse_transform(const Vec2& p) const {
    const Real c = std::cos(yaw_rad);
    const Real s = std::sin(yaw_rad);
    const Real dx = p.x() - x_m;
    const Real dy = p.y() - y_m;
    return {c * dx + s * dy, -s * dx + c * dy};
  }
  /// Composition this ∘ b: b is expressed in this pose's frame; the result is in the parent frame. O(1).
  Pose2 compose(const Pose2& b) const {
    const Vec2 t = transform(Vec2(b.x_m, b.y_m));
    return Pose2{t.x(), t.y(), wrap_angle(yaw_rad + b.yaw_rad)};
  }
  /// Inverse pose: the parent frame expressed in this frame. O(1).
  Pose2 inverse() const {
    const Vec2 t = inverse_transform(Vec2(0, 0));
    return Pose2{t.x(), t.y(), wrap_angle(-yaw_rad)};
  }
};

/// True when the position and the heading of `p` are all finite. O(1).
inline bool finite_pose(const Pose2& p) {
  return std::isfinite(p.x_m) && std::isfinite(p.y_m) && std::isfinite(p.yaw_rad);
}

}  // namespace dockcore
