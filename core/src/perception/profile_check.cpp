#include "dockcore/perception/profile_check.hpp"

#include "dockcore/perception/profile_geometry.hpp"

namespace dockcore {
namespace {

/// Distance below which a point counts as lying on a line (metres): well under the 1 mm vertex spacing, well above
/// rounding at dock sizes.
constexpr double kOnLineM = 1e-6;

Real cross(const Vec2& a, const Vec2& b) {
  return a.x() * b.y() - a.y() * b.x();
}

/// Side of c relative to the directed line a->b: +1 left, -1 right, 0 within kOnLineM of it.
int side(const Vec2& a, const Vec2& b, const Vec2& c) {
  const Vec2 d = b - a;
  const Real dist = cross(d, c - a) / d.norm();
  if (dist > to_real(kOnLineM)) return 1;
  if (dist < -to_real(kOnLineM)) return -1;
  return 0;
}

/// c lies within the bounding box of a-b (used once c is known to be on the line a-b).
bool within(const Vec2& a, const Vec2& b, const Vec2& c) {
  const Real tol = to_real(kOnLineM);
  return c.x() >= (a.x() < b.x() ? a.x() : b.x()) - tol && c.x() <= (a.x() > b.x() ? a.x() : b.x()) + tol &&
         c.y() >= (a.y() < b.y() ? a.y() : b.y()) - tol && c.y() <= (a.y() > b.y() ? a.y() : b.y()) + tol;
}

/// Segments a-b and c-d share at least one point (crossing, touching or overlapping).
bool segments_meet(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const int s1 = side(a, b, c);
  const int s2 = side(a, b, d);
  const int s3 = side(c, d, a);
  const int s4 = side(c, d, b);
  if (s1 * s2 < 0 && s3 * s4 < 0) return true;
  return (s1 == 0 && within(a, b, c)) || (s2 == 0 && within(a, b, d)) || (s3 == 0 && within(c, d, a)) ||
         (s4 == 0 && within(c, d, b));
}

/// Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations (Eigen's solvers reference malloc in
/// their generic paths). Eigenvalues unsorted in `values`, unit eigenvectors in the columns of `vectors`.
void sym3_eigen(const Mat3& a, Vec3* values, Mat3* vectors) {
  Mat3 m = a;
  Mat3 v = Mat3::Identity();
  const Eigen::Index pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
  for (int sweep = 0; sweep < 32; ++sweep) {
    const Real off = m(0, 1) * m(0, 1) + m(0, 2) * m(0, 2) + m(1, 2) * m(1, 2);
    const Real diag = m(0, 0) * m(0, 0) + m(1, 1) * m(1, 1) + m(2, 2) * m(2, 2);
    if (!(off > to_real(1e-30) * diag)) break;
    for (const auto& pq : pairs) {
      const Eigen::Index p = pq[0];
      const Eigen::Index q = pq[1];
      if (m(p, q) == 0) continue;
      const Real theta = (m(q, q) - m(p, p)) / (2 * m(p, q));
      const Real abs_theta = std::fabs(theta);
      Real t = abs_theta > to_real(1e15) ? 1 / (2 * abs_theta) : 1 / (abs_theta + std::sqrt(theta * theta + 1));
      if (theta < 0) t = -t;
      const Real c = 1 / std::sqrt(t * t + 1);
      const Real s = t * c;
      Mat3 j = Mat3::Identity();
      j(p, p) = c;
      j(q, q) = c;
      j(p, q) = s;
      j(q, p) = -s;
      m = (j.transpose() * m * j).eval();
      v = (v * j).eval();
    }
  }
  *values = Vec3(m(0, 0), m(1, 1), m(2, 2));
  *vectors = v;
}

/// Ratio of the smallest to the largest eigenvalue of `info`, and the smallest's unit eigenvector.
Real weakest(const Mat3& info, Vec3* direction) {
  Vec3 values;
  Mat3 vectors;
  sym3_eigen(info, &values, &vectors);
  std::size_t lo = 0;
  std::size_t hi = 0;
  for (std::size_t i = 1; i < 3; ++i) {
    lo = values(static_cast<Eigen::Index>(i)) < values(static_cast<Eigen::Index>(lo)) ? i : lo;
    hi = values(static_cast<Eigen::Index>(i)) > values(static_cast<Eigen::Index>(hi)) ? i : hi;
  }
  *direction = vectors.col(static_cast<Eigen::Index>(lo));
  const Real top = values(static_cast<Eigen::Index>(hi));
  if (!(top > 0)) return 0;
  const Real ratio = values(static_cast<Eigen::Index>(lo)) / top;
  return ratio > 0 ? ratio : 0;
}

PoseComponent dominant(const Vec3& w) {
  const Real ax = std::fabs(w.x());
  const Real ay = std::fabs(w.y());
  const Real az = std::fabs(w.z());
  if (az >= ax && az >= ay) return PoseComponent::kYaw;
  return ay >= ax ? PoseComponent::kY : PoseComponent::kX;
}

bool finite_positive(Real v) {
  return std::isfinite(v) && v > 0;
}

}  // namespace

const char* to_string(ProfileCheckReason reason) {
  switch (reason) {
    case ProfileCheckReason::kOk:
      return "ok";
    case ProfileCheckReason::kSelfIntersecting:
      return "self-intersecting";
    case ProfileCheckReason::kTooSmall:
      return "too small";
    case ProfileCheckReason::kAmbiguous:
      return "ambiguous";
    case ProfileCheckReason::kNotVisible:
      return "not visible from the front";
    case ProfileCheckReason::kBadArguments:
      return "bad arguments";
  }
  return "unknown";
}

const char* to_string(PoseComponent c) {
  switch (c) {
    case PoseComponent::kNone:
      return "none";
    case PoseComponent::kX:
      return "x";
    case PoseComponent::kY:
      return "y";
    case PoseComponent::kYaw:
      return "yaw";
  }
  return "none";
}

ProfileCheck check_profile(const DockProfile& profile, Real beam_spacing_rad, Real max_range_m) {
  ProfileCheck out;
  const std::size_t segs = profile.segment_count();
  if (!finite_positive(beam_spacing_rad) || !finite_positive(max_range_m) || segs == 0 ||
      profile.vertex_count > kMaxProfileVertices) {
    out.reason = ProfileCheckReason::kBadArguments;
    return out;
  }
  const Vec2* v = profile.vertices_m;

  // 1. Self-intersection.
  for (std::size_t i = 0; i < segs; ++i) {
    if (i + 1 < segs) {
      // Adjacent segments share a vertex; they overlap only when the second doubles back along the first.
      const Vec2 d0 = v[i + 1] - v[i];
      const Vec2 d1 = v[i + 2] - v[i + 1];
      if (std::fabs(cross(d0, d1)) <= to_real(kOnLineM) * d0.norm() * d1.norm() && d0.dot(d1) < 0) {
        out.reason = ProfileCheckReason::kSelfIntersecting;
        out.segment_a = i;
        out.segment_b = i + 1;
        return out;
      }
    }
    for (std::size_t j = i + 2; j < segs; ++j) {
      if (segments_meet(v[i], v[i + 1], v[j], v[j + 1])) {
        out.reason = ProfileCheckReason::kSelfIntersecting;
        out.segment_a = i;
        out.segment_b = j;
        return out;
      }
    }
  }

  // 2. The whole dock against the beam spacing at max range.
  const Real min_width_m = static_cast<Real>(kProfileCheckMinBeams - 1) * max_range_m * beam_spacing_rad;
  out.min_width_m = min_width_m;
  if (profile.width_m() < min_width_m) {
    out.reason = ProfileCheckReason::kTooSmall;
    out.width_m = profile.width_m();
    return out;
  }

  // Surfaces: runs of consecutive segments bending by less than kProfileCheckSurfaceJointRad at each joint.
  Real run_m[kMaxProfileVertices] = {};
  const Real smooth_cos = std::cos(kProfileCheckSurfaceJointRad);
  for (std::size_t i = 0; i < segs;) {
    std::size_t end = i + 1;
    Real len = (v[i + 1] - v[i]).norm();
    while (end < segs && profile.normal(end).dot(profile.normal(end - 1)) > smooth_cos) {
      len += (v[end + 1] - v[end]).norm();
      ++end;
    }
    for (std::size_t k = i; k < end; ++k) run_m[k] = len;
    i = end;
  }

  // Fisher information per segment, dock frame, unscaled: (x, y, yaw) with rotation about the dock origin.
  Mat3 info[kMaxProfileVertices];
  for (std::size_t i = 0; i < segs; ++i) info[i] = Mat3::Zero();
  Real sum_sq_m2 = 0;
  PlacedProfile placed;
  const Real bearings[kProfileCheckViews] = {0, kProfileCheckViewBearingRad, -kProfileCheckViewBearingRad};
  for (const Real bearing : bearings) {
    // The lidar kProfileCheckViewRangeM out along `bearing`, its x axis pointing at the dock origin.
    const Pose2 lidar{kProfileCheckViewRangeM * std::cos(bearing), kProfileCheckViewRangeM * std::sin(bearing),
                      wrap_angle(bearing + kPi)};
    placed.place(profile, lidar.inverse());
    Real lo = 0;
    Real hi = 0;
    placed.angular_span(&lo, &hi);
    // Beams on the lidar's grid (one beam straight at the origin); evenly spread when there would be too many.
    Real first = std::ceil(lo / beam_spacing_rad) * beam_spacing_rad;
    Real step = beam_spacing_rad;
    std::size_t count = first > hi ? 0 : static_cast<std::size_t>(std::floor((hi - first) / step)) + 1;
    if (count > kProfileCheckMaxBeamsPerView) {
      count = kProfileCheckMaxBeamsPerView;
      first = lo;
      step = (hi - lo) / static_cast<Real>(count - 1);
    }
    for (std::size_t k = 0; k < count; ++k) {
      const Real a = first + static_cast<Real>(k) * step;
      const Vec2 dir(std::cos(a), std::sin(a));
      Real range_m = 0;
      std::size_t seg = 0;
      if (!placed.raycast(dir, &range_m, &seg)) continue;
      const Vec2 p = lidar.transform(range_m * dir);
      const Vec2 n = profile.normal(seg);
      const Vec3 j(n.x(), n.y(), cross(p, n));
      info[seg] += j * j.transpose();
      sum_sq_m2 += p.squaredNorm();
      ++out.beams;
    }
  }
  if (out.beams == 0) {
    out.reason = ProfileCheckReason::kNotVisible;
    return out;
  }

  // 3. All visible surfaces, yaw scaled by the lever L.
  const Real lever_m = std::sqrt(sum_sq_m2 / static_cast<Real>(out.beams));
  out.lever_m = lever_m;
  const Real yaw_scale = lever_m > to_real(1e-6) ? 1 / lever_m : 1;
  Mat3 scale = Mat3::Identity();
  scale(2, 2) = yaw_scale;
  Mat3 all = Mat3::Zero();
  Mat3 wide = Mat3::Zero();
  for (std::size_t i = 0; i < segs; ++i) {
    info[i] = (scale * info[i] * scale).eval();
    all += info[i];
    if (run_m[i] >= min_width_m) wide += info[i];
  }
  out.eigen_ratio = weakest(all, &out.weak_direction);
  if (out.eigen_ratio < kProfileCheckMinEigenRatio) {
    out.reason = ProfileCheckReason::kAmbiguous;
    out.component = dominant(out.weak_direction);
    return out;
  }

  // 4. Only the surfaces wide enough to be sampled at max range.
  Vec3 weak_wide;
  const Real ratio_wide = weakest(wide, &weak_wide);
  if (ratio_wide < kProfileCheckMinEigenRatio) {
    out.reason = ProfileCheckReason::kTooSmall;
    out.component = dominant(weak_wide);
    out.eigen_ratio = ratio_wide;
    out.weak_direction = weak_wide;
    // The widest of the narrow surfaces that carry information along the weak direction.
    const Real floor_info = kProfileCheckMinEigenRatio * all.trace();
    for (std::size_t i = 0; i < segs; ++i) {
      if (run_m[i] < min_width_m && weak_wide.dot(info[i] * weak_wide) > floor_info && run_m[i] > out.width_m) {
        out.width_m = run_m[i];
      }
    }
    return out;
  }
  return out;
}

}  // namespace dockcore
