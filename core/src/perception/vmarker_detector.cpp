#include "dockcore/perception/vmarker_detector.hpp"

namespace dockcore {
namespace {

Real cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

/// Unsigned angle between two unit vectors, accurate at 0 and pi (atan2 rather than acos).
Real angle_between(const Vec2& a, const Vec2& b) { return std::atan2(std::fabs(cross2(a, b)), a.dot(b)); }

Real clamp01(Real v) {
  if (!(v > 0)) return 0;
  return v > 1 ? static_cast<Real>(1) : v;
}

bool finite_nonneg(Real v) { return std::isfinite(v) && v >= 0; }
bool finite_pos(Real v) { return std::isfinite(v) && v > 0; }

/// Validity of a geometry's numbers (shared by the profile path and configure()).
VMarkerError check_geometry(const VMarkerGeometry& g) {
  const Real lo = deg_to_rad(static_cast<Real>(5));
  const Real hi = deg_to_rad(static_cast<Real>(175));
  if (!std::isfinite(g.notch_angle_rad) || g.notch_angle_rad < lo || g.notch_angle_rad > hi) {
    return VMarkerError::kBadAngle;
  }
  for (Real len : g.arm_length_m) {
    if (!std::isfinite(len) || len <= static_cast<Real>(0.001)) return VMarkerError::kBadLength;
  }
  if (!std::isfinite(g.dock_in_v.x_m) || !std::isfinite(g.dock_in_v.y_m) || !std::isfinite(g.dock_in_v.yaw_rad)) {
    return VMarkerError::kBadParams;
  }
  return VMarkerError::kOk;
}

/// One arm of a candidate, oriented away from the apex.
struct Arm {
  Vec2 u = Vec2::Zero();  // unit direction apex -> far end
  Real length_m = 0;      // apex -> far end
  Real gap_m = 0;         // apex -> near end
};

Arm make_arm(const LineSegment& s, const Vec2& apex) {
  Arm a;
  const Real ds = (s.start_m - apex).norm();
  const Real de = (s.end_m - apex).norm();
  const Vec2 far = ds > de ? s.start_m : s.end_m;
  a.gap_m = ds > de ? de : ds;
  a.length_m = ds > de ? ds : de;
  a.u = a.length_m > 0 ? Vec2((far - apex) / a.length_m) : Vec2(Vec2::Zero());
  return a;
}

/// Mean distance between an arm's samples along its line.
Real mean_spacing(const LineSegment& s) {
  return s.point_count > 1 ? s.length_m() / static_cast<Real>(s.point_count - 1) : static_cast<Real>(0);
}

/// Fisher information of an arm's direction, up to a constant: spread along the line (n·L²/12 for evenly spaced
/// points) over the residual variance.
Real arm_information(const LineSegment& s, Real length_m, Real rms_floor_m) {
  const Real rms = s.rms_m > rms_floor_m ? s.rms_m : rms_floor_m;
  return static_cast<Real>(s.point_count) * length_m * length_m / (rms * rms);
}

}  // namespace

const char* to_string(VMarkerError e) {
  switch (e) {
    case VMarkerError::kOk: return "ok";
    case VMarkerError::kNotThreeVertices: return "V-marker profile needs exactly 3 vertices";
    case VMarkerError::kNotConcave: return "V-marker profile is not a concave notch";
    case VMarkerError::kBadAngle: return "V-marker notch angle outside 5..175 degrees";
    case VMarkerError::kBadLength: return "V-marker arm length not finite or under 1 mm";
    case VMarkerError::kBadParams: return "V-marker tolerance negative, not finite or out of range";
  }
  return "unknown V-marker error";
}

const char* to_string(VMarkerStatus s) {
  switch (s) {
    case VMarkerStatus::kFound: return "found";
    case VMarkerStatus::kNoSegments: return "fewer than 2 segments";
    case VMarkerStatus::kNoCandidate: return "no segment pair forms the V";
    case VMarkerStatus::kNoneNearHint: return "no V near the pose hint";
    case VMarkerStatus::kBadParams: return "detector parameters invalid";
  }
  return "unknown V-marker status";
}

VMarkerError vmarker_geometry_from_profile(const DockProfile& profile, VMarkerGeometry& out) {
  if (profile.vertex_count != 3) return VMarkerError::kNotThreeVertices;
  const Vec2 v0 = profile.vertices_m[0];
  const Vec2 apex = profile.vertices_m[1];
  const Vec2 v2 = profile.vertices_m[2];
  const Real l0 = (v0 - apex).norm();
  const Real l2 = (v2 - apex).norm();
  if (!std::isfinite(l0) || !std::isfinite(l2) || l0 <= static_cast<Real>(0.001) || l2 <= static_cast<Real>(0.001)) {
    return VMarkerError::kBadLength;
  }
  const Vec2 u0 = (v0 - apex) / l0;
  const Vec2 u2 = (v2 - apex) / l2;
  // Concave notch: each segment's outward (visible) face looks at the other arm.
  if (!(profile.normal(0).dot(u2) > 0) || !(profile.normal(1).dot(u0) > 0)) return VMarkerError::kNotConcave;
  VMarkerGeometry g;
  g.notch_angle_rad = angle_between(u0, u2);
  const Vec2 b = (u0 + u2).normalized();
  const bool u0_right = cross2(b, u0) < 0;
  g.arm_length_m[0] = u0_right ? l0 : l2;
  g.arm_length_m[1] = u0_right ? l2 : l0;
  const Pose2 v_in_dock{apex.x(), apex.y(), std::atan2(b.y(), b.x())};
  g.dock_in_v = v_in_dock.inverse();
  const VMarkerError e = check_geometry(g);
  if (e != VMarkerError::kOk) return e;
  out = g;
  return VMarkerError::kOk;
}

VMarkerGeometry symmetric_vmarker_geometry(Real notch_angle_rad, Real arm_length_m, Real apex_to_origin_m) {
  VMarkerGeometry g;
  g.notch_angle_rad = notch_angle_rad;
  g.arm_length_m[0] = arm_length_m;
  g.arm_length_m[1] = arm_length_m;
  g.dock_in_v = Pose2{apex_to_origin_m, 0, 0};
  return g;
}

VMarkerError VMarkerDetector::configure(const VMarkerParams& params) {
  VMarkerError e = check_geometry(params.geometry);
  if (e == VMarkerError::kOk) {
    const bool ok = finite_pos(params.angle_tolerance_rad) && finite_nonneg(params.arm_length_tolerance_m) &&
                    finite_nonneg(params.min_arm_fraction) && params.min_arm_fraction <= 1 &&
                    finite_pos(params.max_apex_gap_m) && finite_nonneg(params.apex_gap_spacing_factor) && finite_pos(params.max_arm_rms_m) && params.pair_span >= 1 &&
                    finite_pos(params.hint_gate_m) && finite_pos(params.max_apex_distance_m) &&
                    std::isfinite(params.min_score) && params.min_score <= 1;
    if (!ok) e = VMarkerError::kBadParams;
  }
  error_ = e;
  if (e == VMarkerError::kOk) params_ = params;
  return e;
}

VMarkerDetection VMarkerDetector::detect(const LineSegmentBuffer& segments, const Pose2* hint) const {
  return detect(segments.data(), segments.size(), hint);
}

VMarkerDetection VMarkerDetector::detect(const LineSegment* segments, std::size_t count, const Pose2* hint) const {
  VMarkerDetection best;
  if (error_ != VMarkerError::kOk) {
    best.status = VMarkerStatus::kBadParams;
    return best;
  }
  if (segments == nullptr || count < 2) {
    best.status = VMarkerStatus::kNoSegments;
    return best;
  }
  const VMarkerParams& p = params_;
  const VMarkerGeometry& g = p.geometry;
  // Lines closer to parallel than this cannot give a stable intersection; far below any notch the tolerance admits.
  const Real min_sin = std::sin(deg_to_rad(static_cast<Real>(2)));
  std::uint32_t candidates = 0;
  Real best_hint_dist = 0;
  const std::size_t span = p.pair_span < count ? p.pair_span : count - 1;

  for (std::size_t i = 0; i < count; ++i) {
    for (std::size_t d = 1; d <= span; ++d) {
      // Visit each unordered pair once on the circle: the shorter way round, and only from i < j on a tie.
      const std::size_t j = (i + d) % count;
      if (2 * d > count || (2 * d == count && j < i)) continue;
      const LineSegment& sa = segments[i];
      const LineSegment& sb = segments[j];
      if (sa.point_count < p.min_arm_points || sb.point_count < p.min_arm_points) continue;
      if (sa.rms_m > p.max_arm_rms_m || sb.rms_m > p.max_arm_rms_m) continue;
      const Real det = cross2(sa.normal, sb.normal);
      if (std::fabs(det) < min_sin) continue;
      const Vec2 apex((sa.offset_m * sb.normal.y() - sb.offset_m * sa.normal.y()) / det,
                      (sa.normal.x() * sb.offset_m - sb.normal.x() * sa.offset_m) / det);
      if (apex.norm() > p.max_apex_distance_m) continue;
      const Arm a = make_arm(sa, apex);
      const Arm b = make_arm(sb, apex);
      if (a.length_m <= 0 || b.length_m <= 0) continue;
      // The true corner lies between samples: an arm's nearest sample can be up to one sample spacing short of it
      // (8 cm on a 75°-incidence arm at 1.5 m with 0.8° steps), so each arm is allowed its own spacing on top.
      const Real allow_a = p.max_apex_gap_m + p.apex_gap_spacing_factor * mean_spacing(sa);
      const Real allow_b = p.max_apex_gap_m + p.apex_gap_spacing_factor * mean_spacing(sb);
      if (a.gap_m > allow_a || b.gap_m > allow_b) continue;
      const Real gap_ratio_a = a.gap_m / allow_a;
      const Real gap_ratio_b = b.gap_m / allow_b;
      const Real gap_ratio = gap_ratio_a > gap_ratio_b ? gap_ratio_a : gap_ratio_b;
      // Concave from the viewer: each arm's visible face (its normal) looks at the other arm. A convex box corner
      // has the faces looking away from each other.
      if (!(sa.normal.dot(b.u) > 0) || !(sb.normal.dot(a.u) > 0)) continue;
      const Real angle = angle_between(a.u, b.u);
      const Real angle_err = std::fabs(angle - g.notch_angle_rad);
      if (angle_err > p.angle_tolerance_rad) continue;
      const Vec2 plain_bis = (a.u + b.u).normalized();
      const bool a_right = cross2(plain_bis, a.u) < 0;
      const Arm& right = a_right ? a : b;
      const Arm& left = a_right ? b : a;
      const LineSegment& s_right = a_right ? sa : sb;
      const LineSegment& s_left = a_right ? sb : sa;
      bool lengths_ok = true;
      Real visibility = 0;
      const Arm* arms[2] = {&right, &left};
      for (int k = 0; k < 2; ++k) {
        const Real expect = g.arm_length_m[k];
        const Real len = arms[k]->length_m;
        if (len > expect + p.arm_length_tolerance_m || len < p.min_arm_fraction * expect) lengths_ok = false;
        visibility += clamp01(len / expect) * static_cast<Real>(0.5);
      }
      if (!lengths_ok) continue;
      const Real rms_max = s_right.rms_m > s_left.rms_m ? s_right.rms_m : s_left.rms_m;
      const Real e_sum = clamp01(angle_err / p.angle_tolerance_rad) + clamp01(gap_ratio) +
                         clamp01(rms_max / p.max_arm_rms_m);
      const Real score = visibility * (1 - e_sum / static_cast<Real>(3));
      if (score < p.min_score) continue;
      Vec2 bis = plain_bis;
      if (p.weight_arms_by_information) {
        // Right arm = bisector turned clockwise by half the notch: turning it back gives a bisector estimate.
        const Real half = g.notch_angle_rad * static_cast<Real>(0.5);
        const Real c = std::cos(half);
        const Real sn = std::sin(half);
        const Vec2 from_right(c * right.u.x() - sn * right.u.y(), sn * right.u.x() + c * right.u.y());
        const Vec2 from_left(c * left.u.x() + sn * left.u.y(), -sn * left.u.x() + c * left.u.y());
        const Real w_right = arm_information(s_right, right.length_m, p.weight_rms_floor_m);
        const Real w_left = arm_information(s_left, left.length_m, p.weight_rms_floor_m);
        const Vec2 sum = from_right * w_right + from_left * w_left;
        if (sum.norm() > 0) bis = sum.normalized();
      }

      VMarkerDetection c;
      c.found = true;
      c.status = VMarkerStatus::kFound;
      c.apex_m = apex;
      c.bisector_yaw_rad = std::atan2(bis.y(), bis.x());
      c.dock_pose = Pose2{apex.x(), apex.y(), c.bisector_yaw_rad}.compose(g.dock_in_v);
      c.notch_angle_rad = angle;
      c.arm_length_m[0] = right.length_m;
      c.arm_length_m[1] = left.length_m;
      c.arm_rms_m[0] = s_right.rms_m;
      c.arm_rms_m[1] = s_left.rms_m;
      c.score = score;
      c.segment_index[0] = static_cast<std::uint32_t>(a_right ? i : j);
      c.segment_index[1] = static_cast<std::uint32_t>(a_right ? j : i);
      ++candidates;

      if (hint != nullptr) {
        const Real dist = (Vec2(c.dock_pose.x_m, c.dock_pose.y_m) - Vec2(hint->x_m, hint->y_m)).norm();
        if (dist > p.hint_gate_m) continue;
        if (!best.found || dist < best_hint_dist || (dist == best_hint_dist && score > best.score)) {
          best = c;
          best_hint_dist = dist;
        }
      } else if (!best.found || score > best.score) {
        best = c;
      }
    }
  }
  best.candidates = candidates;
  if (!best.found) {
    best.status = candidates > 0 ? VMarkerStatus::kNoneNearHint : VMarkerStatus::kNoCandidate;
  }
  return best;
}

}  // namespace dockcore
