#include "dockcore/perception/dock_pose_estimator.hpp"

#include <limits>


namespace dockcore {
namespace {

constexpr Real R(double v) { return static_cast<Real>(v); }

// Largest distance past a segment's end at which a point is still associated with it: about one beam footprint.
// Larger lets the surface adjoining the dock (a wall flush with its back) drag the fit.
constexpr Real kOverhangM = static_cast<Real>(0.002);

// Smallest |cos(incidence)| used to turn a point-to-line residual into a range residual.
constexpr Real kMinCosIncidence = static_cast<Real>(0.2);

// Registration stops when its last step was shorter than this many standard deviations of the pose estimate.
constexpr Real kStopSigmas = static_cast<Real>(0.2);

// Registration keeps the previous iteration's beams and association when its last step moved no point of the dock by
// more than this; after a larger step it takes the span's beams and searches every segment again.
constexpr Real kReuseStepM = static_cast<Real>(0.02);
// Window centres of the global search (add_window_hypotheses) step one scan point, or a sixteenth of the window's
// points on a dense scan: kept windows are a quarter of a segment apart, so finer steps add nothing there. (Every
// other point at 720 beams costs detection of near docks.)
constexpr std::size_t kWindowStepsPerWindow = 16;
// Rays a prescore casts at most: it only ranks hypotheses, so on a dense scan a sample of the span's beams will do.
constexpr std::size_t kPrescoreRays = 32;
// Beams registration fits at most while its steps are large (above kReuseStepM).
constexpr std::size_t kCoarseBeams = 64;

// A rough fit is compared with the verified poses after this many iterations and dropped when it lies within
// kConvergedDuplicateM and kConvergedDuplicateRad of one. Earlier, fits that pass close to a pose can still leave
// for another; later saves less.
constexpr std::uint8_t kDuplicateCheckIterations = 2;
constexpr Real kConvergedDuplicateM = static_cast<Real>(0.005);
constexpr Real kConvergedDuplicateRad = static_cast<Real>(0.01);

// Association with no segment yet (assoc_seg_).
constexpr std::uint8_t kNoSegment = 0xFF;

// Damping of the normal equations, as a share of their trace: a whisper that keeps a nearly degenerate view (one
// flat face) solvable without biasing a good fit. In float it must stand above the rounding of the Jacobian (a face
// seen head-on has n_y of order epsilon, not 0), or a step along the unfixed direction runs away.
constexpr Real kDampingShare = std::numeric_limits<Real>::epsilon() * 8 > static_cast<Real>(1e-9)
                                   ? std::numeric_limits<Real>::epsilon() * 8
                                   : static_cast<Real>(1e-9);
// Gauss-Newton iterations that use Huber weights before switching to Tukey's biweight.
constexpr std::uint8_t kHuberIterations = 3;
// Beams either side of where the pose puts a surface's end that edge_terms() looks at for the step: the fit is within a
// beam or two of the truth along a face once it has converged on the surfaces.
constexpr long kEdgeSearchBeams = 3;
// A surface's end is no measurement when an interior point 1 mm from it is hidden by another part of the dock.
constexpr Real kEdgeProbeM = static_cast<Real>(0.001);
// The surfaces' ends enter the fit only when its weakest direction carries less than this share of its information
// (the trace, yaw as arc length at the dock's radius): the profile check's ambiguity bound. Applied to every fit,
// their quantisation moved poses the surfaces fix and let more false docks through on the real dock-less scans.
constexpr Real kEdgeWeakShare = static_cast<Real>(0.01);
// At most this many steps with the ends (each may move the pose by a beam and change which beams bracket an end),
// stopping once a step moves the pose less than kEdgeStopM.
constexpr std::uint8_t kEdgeSteps = 3;
constexpr Real kEdgeStopM = static_cast<Real>(0.001);

// A return on the line of a long profile segment, this far past its end, means that surface carries on where the
// dock ends: a wall or a box face, not the dock. Closer than the minimum is ambiguous: a 45° wing is only 4 cm
// behind the face's line 4 cm past the face's end.
constexpr Real kExtensionMinM = static_cast<Real>(0.04);
constexpr Real kExtensionMaxM = static_cast<Real>(0.12);

// The decision's cue weights, nats per unit of each DecisionFeatures field. They are the coefficients of a logistic
// model (so the total is calibrated log-odds) fitted by `dock-sim features` + tools/fit-evidence to candidates from
// simulated docks of every built-in profile, mounting (flush, 0-10 cm gap, glass, free-standing), three lidar models
// and 5-20 mm noise, against the best candidates in half of the real dock-less recordings (docs/docks.md gives the
// commands); docs/performance.md gives the rates on the other half and on independently generated worlds. Dropped
// beams are left out: their fitted weight carried the simulator's habits, not the dock's.
constexpr Real kFitBaseNats = static_cast<Real>(-9.181);  // a dock-sized match by chance
constexpr Real kFitPerHitNats = static_cast<Real>(2.600);
constexpr Real kFitPerSqNats = static_cast<Real>(-0.382);
constexpr Real kBeyondNats = static_cast<Real>(-0.751);
constexpr Real kFrontNats = static_cast<Real>(-1.318);
constexpr Real kMissingNats = static_cast<Real>(-1.689);
constexpr Real kContinuesNats = static_cast<Real>(-6.399);
constexpr Real kStopsNats = static_cast<Real>(-3.583);
constexpr Real kConstraintNats = static_cast<Real>(1.274);  // per e-fold of `constraint`
constexpr Real kMinConstraint = static_cast<Real>(0.01);
// The inlier gate of the lidars the weights were fitted on (estimator_params_for_noise's floor).
constexpr Real kReferenceGateM = static_cast<Real>(0.015);
// How much of a wider gate's extra chance matches is charged: all of it (1) if chance surfaces were spread evenly in
// range; rooms are not, and charging all of it halves detection at 10 mm noise for little gain on real scans.
constexpr Real kGateGrowthShare = static_cast<Real>(0.5);
// Wall beams. Unknown mounting: the fitted weight of a wall seen; none seen is not held against the dock. A
// wall-mounted dock: log(0.85/0.2) for a wall where the gap range puts it and log(0.15/0.8) for none.
constexpr Real kWallSeenUnknownNats = static_cast<Real>(0.061);
constexpr Real kWallSeenMountedNats = static_cast<Real>(1.45);
constexpr Real kWallMissedMountedNats = static_cast<Real>(-1.67);
// The intensity cue, per region of the stripe pattern (a stripe or a gap) with a beam well inside it: on this dock a
// region reads as the profile says with probability 0.99; on another dock of this shape (another code, or no tape)
// with probability 0.5.
constexpr Real kRegionMatchNats = static_cast<Real>(0.683);      // ln(0.99 / 0.5)
constexpr Real kRegionMismatchNats = static_cast<Real>(-3.912);  // ln(0.01 / 0.5)
// A beam this close to a stripe's end (plus half its footprint) is left out: its footprint may straddle the edge.
constexpr Real kStripeEdgeMarginM = static_cast<Real>(0.005);
// A stripe or gap shorter than this is no region of the pattern (a stripe cut a little short of a corner leaves such
// a gap): none is read beyond a few decimetres, so a code must not rest on one.
constexpr Real kMinRegionM = static_cast<Real>(0.03);
// A code is read only where the fit fixes each region along the face to this many standard deviations of its width:
// a pose off along the face by a region reads another code's stripe where this code's should be. The fit's errors
// along a face have heavy tails (1 % of right poses on generated docks are off by 4 sigma), hence the wide bound.
constexpr Real kRegionAlongSigmas = static_cast<Real>(4.5);
// A bright run reaching this many standard deviations of the pose's along-face uncertainty (past the edge margin)
// into a gap is another code's stripe, not this code's stripe seen from a pose a little off along the face.
constexpr Real kRunAlongSigmas = static_cast<Real>(3);
// Between two verified objects, evidence stronger by this much (a likelihood ratio of e^3 = 20) decides over
// nearness; closer than that, both are taken for docks and the nearest is chosen.
constexpr Real kSelectMarginNats = static_cast<Real>(3);
// Beams closer together than this on a surface are not independent evidence: rooms are made of smooth surfaces, so
// where one beam lands on a dock-like surface by chance its neighbours do too.
constexpr Real kCorrelationLengthM = static_cast<Real>(0.05);

// Smallest eigenvalue of a symmetric 3x3 matrix (the trigonometric closed form). O(1).
Real min_eigen_sym3(const Mat3& a) {
  const Real p1 = a(0, 1) * a(0, 1) + a(0, 2) * a(0, 2) + a(1, 2) * a(1, 2);
  const Real q = a.trace() / 3;
  if (p1 <= 0) {
    Real m = a(0, 0) < a(1, 1) ? a(0, 0) : a(1, 1);
    return m < a(2, 2) ? m : a(2, 2);
  }
  const Real d0 = a(0, 0) - q;
  const Real d1 = a(1, 1) - q;
  const Real d2 = a(2, 2) - q;
  const Real p2 = d0 * d0 + d1 * d1 + d2 * d2 + 2 * p1;
  const Real p = std::sqrt(p2 / 6);
  const Mat3 b = (a - q * Mat3::Identity()) / p;
  const Real det = b(0, 0) * (b(1, 1) * b(2, 2) - b(1, 2) * b(2, 1)) - b(0, 1) * (b(1, 0) * b(2, 2) - b(1, 2) * b(2, 0)) +
                   b(0, 2) * (b(1, 0) * b(2, 1) - b(1, 1) * b(2, 0));
  Real rr = det / 2;
  rr = rr < -1 ? R(-1) : (rr > 1 ? R(1) : rr);
  const Real phi = std::acos(rr) / 3;
  return q + 2 * p * std::cos(phi + R(2.0943951023931957));
}

// Distance between segments [a, b] and [c, d] that do not cross: the least of the four end-to-segment distances.
Real segment_distance(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  auto point_segment = [](const Vec2& p, const Vec2& u, const Vec2& v) {
    const Vec2 uv = v - u;
    Real t = (p - u).dot(uv) / uv.squaredNorm();
    t = t < 0 ? R(0) : (t > 1 ? R(1) : t);
    return (p - u - t * uv).norm();
  };
  const Real d1 = point_segment(a, c, d);
  const Real d2 = point_segment(b, c, d);
  const Real d3 = point_segment(c, a, b);
  const Real d4 = point_segment(d, a, b);
  const Real m12 = d1 < d2 ? d1 : d2;
  const Real m34 = d3 < d4 ? d3 : d4;
  return m12 < m34 ? m12 : m34;
}

Real dist2(const Pose2& a, const Pose2& b) {
  const Real dx = a.x_m - b.x_m;
  const Real dy = a.y_m - b.y_m;
  return dx * dx + dy * dy;
}

// The placed dock's bounding box grown by `gate_m` and a hair, so that rounding cannot refuse a point the gate keeps:
// a point outside it is further than the gate from every segment.
void gated_box(const PlacedProfile& placed, Real gate_m, Vec2* lo, Vec2* hi) {
  placed.bounding_box(lo, hi);
  const Real margin = gate_m * (1 + R(1e-6));
  *lo -= Vec2(margin, margin);
  *hi += Vec2(margin, margin);
}

bool in_box(const Vec2& p, const Vec2& lo, const Vec2& hi) {
  return p.x() >= lo.x() && p.y() >= lo.y() && p.x() <= hi.x() && p.y() <= hi.y();
}

// Poses within d_m of each other and yaw_rad in heading.
bool near_pose(const Pose2& a, const Pose2& b, Real d_m, Real yaw_rad) {
  return dist2(a, b) < d_m * d_m && std::fabs(wrap_angle(a.yaw_rad - b.yaw_rad)) < yaw_rad;
}

}  // namespace

const char* to_string(RejectReason r) {
  switch (r) {
    case RejectReason::kNone: return "none";
    case RejectReason::kNoConvergence:
      return "no_convergence";
    case RejectReason::kTooFewInliers:
      return "too_few_inliers";
    case RejectReason::kMostlyHidden:
      return "mostly_hidden";
    case RejectReason::kOblique:
      return "oblique";
    case RejectReason::kOutOfRange:
      return "out_of_range";
    case RejectReason::kUncertain:
      return "uncertain";
    case RejectReason::kFarFromHint:
      return "far_from_hint";
    case RejectReason::kWeakEvidence:
      return "weak_evidence";
    case RejectReason::kWrongCode:
      return "wrong_code";
    case RejectReason::kCodeUnread:
      return "code_unread";
    case RejectReason::kCount: break;
  }
  return "unknown reason";
}

const char* to_string(EvidenceCue c) {
  switch (c) {
    case EvidenceCue::kFit: return "fit";
    case EvidenceCue::kSeeThrough: return "see_through";
    case EvidenceCue::kFreeSpace: return "free_space";
    case EvidenceCue::kSupport: return "support";
    case EvidenceCue::kEdges: return "edges";
    case EvidenceCue::kWall: return "wall";
    case EvidenceCue::kGeometry: return "geometry";
    case EvidenceCue::kPrior: return "prior";
    case EvidenceCue::kIntensity:
      return "intensity";
    case EvidenceCue::kCount: break;
  }
  return "unknown cue";
}

EvidenceCue DockEvidence::weakest() const {
  EvidenceCue w = EvidenceCue::kCount;
  Real lowest = 0;
  for (std::size_t i = 0; i < kEvidenceCueCount; ++i) {
    if (cue_nats[i] < lowest) {
      lowest = cue_nats[i];
      w = static_cast<EvidenceCue>(i);
    }
  }
  return w;
}

const char* to_string(EstimateStatus s) {
  switch (s) {
    case EstimateStatus::kOk: return "ok";
    case EstimateStatus::kNoProfile: return "no profile configured";
    case EstimateStatus::kNoPoints: return "no valid returns in range";
    case EstimateStatus::kNoCandidates: return "nothing in the scan resembles the dock";
    case EstimateStatus::kNotVerified: return "dock-like features found but none verified";
    case EstimateStatus::kBadScan: return "scan geometry invalid";
  }
  return "unknown status";
}

EstimatorParams estimator_params_for_noise(Real range_sigma_m) {
  EstimatorParams p;
  const Real s = range_sigma_m > 0 ? range_sigma_m : p.range_sigma_m;
  auto at_least = [](Real v, Real floor) { return v > floor ? v : floor; };
  p.range_sigma_m = s;
  p.inlier_gate_m = at_least(3 * s, R(0.015));
  p.extension_band_m = at_least(2 * s, R(0.01));
  p.association_gate_m = at_least(6 * s, R(0.06));
  return p;
}

bool DockPoseEstimatorBase::configure(const DockProfile& profile, const EstimatorParams& params) {
  counters_ = EstimatorCounters{};
  configured_ = false;
  if (profile.segment_count() < 1) return false;
  profile_ = profile;
  params_ = params;
  profile_radius_m_ = 0;
  back_x_m_ = profile.vertices_m[0].x();
  half_width_m_ = 0;
  // A wall-mounted dock's wall lies within its gap range; any other mounting allows the default range.
  wall_gap_max_m_ = profile.mounting.kind == DockMountKind::kWall ? profile.mounting.wall_gap_max_m
                                                                  : DockMounting{}.wall_gap_max_m;
  for (std::size_t i = 0; i < profile.vertex_count; ++i) {
    back_x_m_ = profile.vertices_m[i].x() < back_x_m_ ? profile.vertices_m[i].x() : back_x_m_;
    const Real ay = std::fabs(profile.vertices_m[i].y());
    half_width_m_ = ay > half_width_m_ ? ay : half_width_m_;
    const Real r = profile.vertices_m[i].norm();
    profile_radius_m_ = r > profile_radius_m_ ? r : profile_radius_m_;
  }
  // Where registration may keep a beam on its previous segment without searching the others (see
  // PlacedProfile::projects_well_inside): a long segment whose joints turn by at most 120°, for points closer to its
  // line than half its clearance from every segment it does not join.
  const std::size_t ns = profile.segment_count();
  for (std::size_t i = 0; i < ns; ++i) {
    const Vec2& a = profile.vertices_m[i];
    const Vec2& b = profile.vertices_m[i + 1];
    const Vec2 d = (b - a) / (b - a).norm();
    bool joints_ok = true;
    if (i > 0) {
      const Vec2 prev = (a - profile.vertices_m[i - 1]).normalized();
      joints_ok = joints_ok && prev.dot(d) >= R(-0.5);  // turn of at most 120°
    }
    if (i + 1 < ns) {
      const Vec2 next = (profile.vertices_m[i + 2] - b).normalized();
      joints_ok = joints_ok && d.dot(next) >= R(-0.5);
    }
    Real clearance = std::numeric_limits<Real>::infinity();
    for (std::size_t j = 0; j < ns; ++j) {
      if (j + 1 >= i && j <= i + 1) continue;  // itself and the segments it joins
      const Real dj = segment_distance(a, b, profile.vertices_m[j], profile.vertices_m[j + 1]);
      clearance = dj < clearance ? dj : clearance;
    }
    const bool long_enough = (b - a).norm() >= params.min_feature_length_m;
    shortcut_max_m_[i] = joints_ok && long_enough ? clearance / 2 : R(0);
  }
  for (bool& t : seg_taped_) t = false;
  for (std::size_t q = 0; q < profile.reflector_count; ++q) seg_taped_[profile.reflectors[q].segment] = true;
  configured_ = true;
  return true;
}

bool DockPoseEstimatorBase::load_scan(const ScanView& scan) {
  if (scan.count == 0 || scan.count > capacity_ || scan.ranges_m == nullptr || !(scan.angle_increment_rad > 0) ||
      !std::isfinite(scan.angle_min_rad) || static_cast<Real>(scan.count) * scan.angle_increment_rad > kTwoPi + scan.angle_increment_rad) {
    return false;
  }
  beams_ = scan.count;
  angle_min_rad_ = scan.angle_min_rad;
  angle_inc_rad_ = scan.angle_increment_rad;
  wraps_ = scan.wraps();
  ranges_m_ = scan.ranges_m;
  intensities_ = scan.intensities;
  // A lidar's scans keep their geometry from turn to turn: the beam directions are computed again only when it
  // changes, so a tracking scan reads just the beams near the dock.
  if (dir_beams_ == beams_ && dir_angle_min_rad_ == angle_min_rad_ && dir_angle_inc_rad_ == angle_inc_rad_) return true;
  // Beam directions by rotating a unit vector: one sin/cos pair per 64 beams instead of one per beam. The
  // periodic re-seed bounds the recurrence's rounding drift (matters for the float build).
  const Real ci = std::cos(angle_inc_rad_);
  const Real si = std::sin(angle_inc_rad_);
  Vec2 d(0, 0);
  for (std::size_t i = 0; i < beams_; ++i) {
    if ((i & 63u) == 0) {
      const Real a = scan.angle_rad(i);
      d = Vec2(std::cos(a), std::sin(a));
    } else {
      d = Vec2(ci * d.x() - si * d.y(), si * d.x() + ci * d.y());
    }
    dir_[i] = d;
  }
  dir_beams_ = beams_;
  dir_angle_min_rad_ = angle_min_rad_;
  dir_angle_inc_rad_ = angle_inc_rad_;
  return true;
}

void DockPoseEstimatorBase::build_points() {
  // Only the global search needs Cartesian points; tracking works on the beams directly.
  points_.clear();
  for (std::size_t i = 0; i < beams_; ++i) {
    const Real r = range_at(i);
    if (r == 0) continue;
    ScanPoint sp;
    sp.p_m = r * dir_[i];
    sp.range_m = r;
    sp.angle_rad = angle_min_rad_ + static_cast<Real>(i) * angle_inc_rad_;
    sp.index = static_cast<std::uint32_t>(i);
    points_.push_back(sp);
  }
}

void DockPoseEstimatorBase::wall_behind(const Pose2& pose, long first, std::size_t k_first_hit, std::size_t k_last_hit,
                                    std::uint16_t* seen, std::uint16_t* looked) const {
  // The wall lies behind the dock's back plane (dock frame x = back_x_m_) by the mounting's gap: beams just past
  // either end of the dock meet it there. Beams blocked well in front of it (an occluder) say nothing.
  *seen = 0;
  *looked = 0;
  const DockMounting& mount = profile_.mounting;
  const Vec2& nd = placed_.x_axis;  // verify() placed the profile at `pose`
  const Real back_c = nd.dot(Vec2(pose.x_m, pose.y_m)) + back_x_m_;
  const Real tol = params_.wall_tolerance_m + params_.inlier_gate_m;
  const Real gap_lo = mount.kind == DockMountKind::kWall ? mount.wall_gap_min_m : R(0);
  const Real gap_hi = wall_gap_max_m_;
  for (int side = 0; side < 2; ++side) {
    for (std::size_t step = 1; step <= 3; ++step) {
      const long k = side == 0 ? static_cast<long>(k_first_hit) - static_cast<long>(step)
                               : static_cast<long>(k_last_hit) + static_cast<long>(step);
      std::size_t i = 0;
      if (!beam_at(first + k, 0, &i)) break;
      const Real denom = nd.dot(dir_[i]);
      if (denom >= 0) continue;  // the plane faces away along this beam
      // Range along this beam to the wall plane at the near and the far end of the gap range.
      const Real near_m = (back_c - gap_lo) / denom;
      const Real far_m = (back_c - gap_hi) / denom;
      if (near_m <= 0) continue;
      const Real m = range_at(i);
      if (m != 0 && m < near_m - params_.free_space_m) continue;  // an occluder: neither for nor against
      ++*looked;
      if (m != 0 && m >= near_m - tol && m <= far_m + tol) ++*seen;
    }
  }
}

int DockPoseEstimatorBase::continues_past_end(const Vec2& p, const Vec2& box_lo, const Vec2& box_hi) const {
  // A point on the dock itself (e.g. the breakpoint dock's end blocks, in line with its face) is not an extension.
  // Outside the box it cannot be.
  std::size_t near_seg = 0;
  Real near_dist = 0;
  Real line_dist = 0;
  Real overhang_m = 0;
  if (in_box(p, box_lo, box_hi) && placed_.nearest(p, &near_seg, &near_dist, &line_dist, &overhang_m) &&
      near_dist <= params_.inlier_gate_m) {
    return 0;
  }
  int result = 0;
  for (std::size_t j = 0; j < placed_.segments; ++j) {
    if (!placed_.visible[j]) continue;
    const Real len = placed_.len_m[j];
    if (len < params_.min_feature_length_m) continue;
    const Real u = (p - placed_.v_m[j]).dot(placed_.u[j]);
    const Real overhang = u < 0 ? -u : u - len;
    if (overhang < kExtensionMinM || overhang > kExtensionMaxM) continue;
    const Real off_m = std::fabs(placed_.n[j].dot(p) - placed_.c_m[j]);
    if (off_m <= params_.extension_band_m) return 2;
    // Something right beside the dock's end, off its line (a look-alike's own next surface turning away, or clutter
    // at its side). Farther off the line it is a room behind or in front, which a free-standing dock has as well.
    if (off_m <= kExtensionMaxM) result = 1;
  }
  return result;
}

long DockPoseEstimatorBase::first_beam(Real angle_rad) const {
  return nearest_beam_index(angle_min_rad_, angle_inc_rad_, beams_, angle_rad);
}

DockPoseEstimatorBase::Refined DockPoseEstimatorBase::refine(const Pose2& initial, bool rough, const Pose2* verified,
                                                             std::size_t n_verified) {
  Refined out{};
  out.pose = initial;
  out.ok = false;
  out.duplicate = false;
  const Real k_huber = params_.huber_k * params_.range_sigma_m;
  const Real c_tukey = params_.tukey_c * params_.range_sigma_m;
  Pose2 pose = initial;
  // The beams of the dock's span and the segment each was nearest to in the previous iteration. Once the steps are
  // small (kReuseStepM) the span and the association barely change between iterations: each beam is then measured
  // against its previous segment, and searched again among all segments only when it nears that segment's ends.
  std::size_t n_assoc = 0;
  Real last_step_m = std::numeric_limits<Real>::infinity();
  bool coarse = false;
  for (std::uint8_t it = 0; it < params_.max_iterations; ++it) {
    placed_.place(profile_, pose);
    const Real dist_m = std::sqrt(pose.x_m * pose.x_m + pose.y_m * pose.y_m);
    if (!(dist_m > params_.min_range_m) || dist_m > params_.max_range_m + profile_radius_m_) return out;
    // The association gate shrinks as the fit converges so neighbours of the dock stop pulling on it.
    const Real shrink = static_cast<Real>(1u << (it < 4 ? it : 4));
    const Real gate = params_.association_gate_m / shrink > params_.inlier_gate_m ? params_.association_gate_m / shrink
                                                                                   : params_.inlier_gate_m;
    const Vec2 t(pose.x_m, pose.y_m);
    const Vec2& nd = placed_.x_axis;
    // A point outside the gated box needs no nearest-segment search. Worth it in a global search, whose rough fits take
    // the beams of clutter beside the dock; a hint's fit sits on the dock from the start.
    Vec2 box_lo(-std::numeric_limits<Real>::infinity(), -std::numeric_limits<Real>::infinity());
    Vec2 box_hi(std::numeric_limits<Real>::infinity(), std::numeric_limits<Real>::infinity());
    if (rough) gated_box(placed_, gate, &box_lo, &box_hi);
    // The beams to fit: every return in the dock's span plus a margin, taken again early on and kept later, with
    // wall points beside the dock left out (the wall explains them, not the dock's sides).
    const bool reuse = last_step_m <= kReuseStepM && n_assoc > 0 && !coarse;
    if (!reuse) {
      n_assoc = span_beams(dist_m, t, nd, gate);
      // While the steps are large, a sample of a dense span moves the pose as well as every beam would: every
      // stride-th beam, at most kCoarseBeams. Once the steps are small the full span is taken.
      coarse = rough && last_step_m > kReuseStepM && n_assoc > 2 * kCoarseBeams;
      if (coarse) {
        const std::size_t stride = n_assoc / kCoarseBeams;
        std::size_t kept = 0;
        for (std::size_t k = 0; k < n_assoc; k += stride) assoc_beam_[kept++] = assoc_beam_[k];
        n_assoc = kept;
      }
    }
    // Normal equations, upper triangle (h is symmetric), as scalars so they stay in registers.
    Real h00 = 0;
    Real h01 = 0;
    Real h02 = 0;
    Real h11 = 0;
    Real h12 = 0;
    Real h22 = 0;
    Real g0 = 0;
    Real g1 = 0;
    Real g2 = 0;
    std::uint16_t used = 0;
    Real sum_sq = 0;
    // The buffers through locals: a byte store (the association) may alias any member, so members read in the loop
    // would be loaded again for every beam.
    const Real* const ranges = ranges_m_;
    const Vec2* const dirs = dir_;
    const std::uint16_t* const beams = assoc_beam_;
    std::uint8_t* const segs = assoc_seg_;
    for (std::size_t k = 0; k < n_assoc; ++k) {
      const std::size_t i = beams[k];
      const Vec2 p = ranges[i] * dirs[i];  // span_beams() kept only returns within range
      // Its segment in the previous iteration, or (after a full pass) the neighbouring beam's, just found: the
      // shortcut below holds whatever segment it is tried on.
      std::size_t seg = segs[k];
      if (seg == kNoSegment && k > 0) seg = segs[k - 1];
      Real dist = 0;
      Real e = 0;
      // A point beyond a segment's end (overhang) belongs to whatever adjoins the dock, e.g. the wall behind it.
      Real overhang = 0;
      // Against the previous segment first: while the point projects well inside it (clear of its corners and of
      // the segments it does not join), its distance is the line distance.
      if (seg != kNoSegment && placed_.visible[seg] && placed_.projects_well_inside(p, seg, shortcut_max_m_[seg], &e)) {
        dist = std::fabs(e);
      } else if (!in_box(p, box_lo, box_hi) || !placed_.nearest(p, &seg, &dist, &e, &overhang)) {
        continue;
      }
      // Remembered even when refused now: a beam just outside the gate may come in at the next pose.
      segs[k] = static_cast<std::uint8_t>(seg);
      if (dist > gate || overhang > kOverhangM) continue;
      const Vec2& n = placed_.n[seg];
      // Work in range units: the lidar's noise is along the beam, so a residual of e across the surface is a range
      // error of e / cos(incidence). Weighting by that is the maximum-likelihood fit (and what the Cramér–Rao bound
      // assumes); plain point-to-line would under-use oblique surfaces such as wings. Capped at 78° incidence.
      Real cos_inc = std::fabs(n.dot(dirs[i]));
      cos_inc = cos_inc > kMinCosIncidence ? cos_inc : kMinCosIncidence;
      const Real inv_cos = 1 / cos_inc;
      e *= inv_cos;
      const Real jx = -n.x() * inv_cos;
      const Real jy = -n.y() * inv_cos;
      const Real jz = (n.x() * (p.y() - t.y()) - n.y() * (p.x() - t.x())) * inv_cos;
      const Real ae = std::fabs(e);
      // Huber while the pose is rough (convex, pulls in from afar); Tukey's biweight once it is close, so points
      // from depth edges (mixed pixels, jitter at a slot wall) stop pulling the fit at all.
      Real w = 0;
      if (it < kHuberIterations) {
        w = ae <= k_huber ? R(1) : k_huber / ae;
      } else if (ae < c_tukey) {
        const Real u = ae / c_tukey;
        w = (1 - u * u) * (1 - u * u);
      }
      if (w <= 0) continue;
      const Real wx = w * jx;
      const Real wy = w * jy;
      const Real wz = w * jz;
      h00 += wx * jx;
      h01 += wx * jy;
      h02 += wx * jz;
      h11 += wy * jy;
      h12 += wy * jz;
      h22 += wz * jz;
      g0 += wx * e;
      g1 += wy * e;
      g2 += wz * e;
      sum_sq += e * e;
      ++used;
    }
    Mat3 h;
    h << h00, h01, h02, h01, h11, h12, h02, h12, h22;
    const Vec3 g(g0, g1, g2);
    if (used < 3) return out;
    const Real damping = h.trace() * kDampingShare;
    const Mat3 hd = h + damping * Mat3::Identity();
    Mat3 hinv;
    if (!invert_sym3(hd, &hinv)) return out;
    const Vec3 delta = -(hinv * g);
    if (!delta.allFinite()) return out;
    pose.x_m += delta.x();
    pose.y_m += delta.y();
    pose.yaw_rad = wrap_angle(pose.yaw_rad + delta.z());
    last_step_m = std::fabs(delta.x()) + std::fabs(delta.y()) + profile_radius_m_ * std::fabs(delta.z());
    out.h = h;
    out.rms_m = std::sqrt(sum_sq / static_cast<Real>(used));
    out.iterations = static_cast<std::uint8_t>(it + 1);
    // Stop once the step is small against the estimate's own uncertainty: δᵀHδ / σ² is the step's squared
    // Mahalanobis length under the covariance σ²H⁻¹ the fit reports, so a step below kStopSigmas of a standard
    // deviation changes nothing the covariance can see. IRLS converges only linearly, so a fixed step size in
    // metres would spend most iterations on digits below the noise.
    const Real step_sq = delta.dot(h * delta);
    if (!coarse && step_sq < kStopSigmas * kStopSigmas * params_.range_sigma_m * params_.range_sigma_m) break;
    // A fit that has come this close to a verified pose after a few steps converges onto it: the rest of its
    // iterations and its verification would only repeat that candidate's.
    if (it + 1 == kDuplicateCheckIterations) {
      for (std::size_t q = 0; q < n_verified; ++q) {
        if (near_pose(pose, verified[q], kConvergedDuplicateM, kConvergedDuplicateRad)) {
          out.duplicate = true;
          return out;
        }
      }
    }
  }
  if (out.iterations > 0) {
    // Where the surfaces leave a direction of the pose almost unfixed (every visible surface parallel, or nearly),
    // their ends fix it: a few steps with them, and their information in the fit's. Elsewhere the ends add little and
    // their quantisation would only move a pose the surfaces fix.
    const Mat3 hs = arc_scaled(out.h);
    if (min_eigen_sym3(hs) < kEdgeWeakShare * hs.trace()) {
      const Mat3 h_surfaces = out.h;
      for (std::uint8_t step = 0; step < kEdgeSteps; ++step) {
        placed_.place(profile_, pose);
        Mat3 h_edge = Mat3::Zero();
        Vec3 g_edge = Vec3::Zero();
        if (edge_terms(pose, &h_edge, &g_edge) == 0) break;
        const Mat3 h = h_surfaces + h_edge;
        Mat3 hinv;
        if (!invert_sym3(h + h.trace() * kDampingShare * Mat3::Identity(), &hinv)) break;
        const Vec3 delta = -(hinv * g_edge);
        if (!delta.allFinite()) break;
        pose.x_m += delta.x();
        pose.y_m += delta.y();
        pose.yaw_rad = wrap_angle(pose.yaw_rad + delta.z());
        out.h = h;
        if (std::fabs(delta.x()) + std::fabs(delta.y()) + profile_radius_m_ * std::fabs(delta.z()) < kEdgeStopM) break;
      }
    }
  }
  out.pose = pose;
  out.ok = out.iterations > 0;
  return out;
}

std::size_t DockPoseEstimatorBase::span_beams(Real dist_m, const Vec2& t, const Vec2& nd, Real gate_m) {
  Real lo = 0;
  Real hi = 0;
  placed_.angular_span(&lo, &hi);
  const Real margin = std::atan2(gate_m, dist_m);
  lo -= margin;
  hi += margin;
  const std::size_t n_beams = static_cast<std::size_t>((hi - lo) / angle_inc_rad_) + 2;
  const long first = first_beam(lo);
  const bool wall_mounted = profile_.mounting.kind != DockMountKind::kFreeStanding;
  const Real band_hi = back_x_m_ + params_.inlier_gate_m;
  const Real band_lo = back_x_m_ - wall_gap_max_m_ - params_.inlier_gate_m;
  std::size_t n = 0;
  // Members through locals: the byte stores below may alias any of them (see refine()).
  const Real* const ranges = ranges_m_;
  const Vec2* const dirs = dir_;
  std::uint16_t* const beams = assoc_beam_;
  std::uint8_t* const segs = assoc_seg_;
  const Real min_m = params_.min_range_m;
  const Real max_m = params_.max_range_m;
  const Real half_width_m = half_width_m_;
  // The beams first + k for k below n_beams, as beam_at() gives them: consecutive indices, wrapped on a full-turn
  // scan, cut at a partial scan's ends.
  std::size_t k_begin = 0;
  std::size_t k_end = n_beams < beams_ ? n_beams : beams_;
  if (!wraps_) {
    const long room = static_cast<long>(beams_) - first;  // beams from `first` to the scan's end
    if (first < 0) k_begin = static_cast<std::size_t>(-first);
    if (room < static_cast<long>(k_end)) k_end = room > 0 ? static_cast<std::size_t>(room) : 0;
  }
  std::size_t i = 0;
  if (k_begin < k_end) beam_at(first, k_begin, &i);
  for (std::size_t k = k_begin; k < k_end; ++k, i = i + 1 == beams_ ? 0 : i + 1) {
    const Real r = usable_range(ranges[i], min_m, max_m);
    if (r == 0) continue;
    if (wall_mounted) {
      const Vec2 pt = r * dirs[i] - t;
      const Real qx = nd.dot(pt);
      const Real qy = nd.x() * pt.y() - nd.y() * pt.x();
      if (std::fabs(qy) > half_width_m && qx < band_hi && qx > band_lo) continue;
    }
    beams[n] = static_cast<std::uint16_t>(i);
    segs[n] = kNoSegment;
    ++n;
  }
  return n;
}

void DockPoseEstimatorBase::verify(Refined& r, const Pose2* hint) {
  r.inliers = r.expected = r.violations = r.occluded = r.extensions = r.wall_seen = r.wall_looked = 0;
  r.shape_rms_m = 0;
  r.evidence = DockEvidence{};
  if (!r.ok) {
    r.reject = RejectReason::kNoConvergence;
    return;
  }
  r.ok = false;
  placed_.place(profile_, r.pose);
  Real lo = 0;
  Real hi = 0;
  placed_.angular_span(&lo, &hi);
  const Real dist_to_dock = std::sqrt(r.pose.x_m * r.pose.x_m + r.pose.y_m * r.pose.y_m);
  // Look a little past the dock's ends as well: a surface that carries straight on past a dock edge is not a dock.
  const Real margin = std::atan2(kExtensionMaxM, dist_to_dock > R(0.05) ? dist_to_dock : R(0.05));
  const long first = first_beam(lo - margin);
  const std::size_t n_beams = static_cast<std::size_t>((hi - lo + 2 * margin) / angle_inc_rad_) + 2;
  // Only beams within the dock's angular span (and a beam of slack for rounding) can hit it: the margin's beams are
  // looked at for the edge cue alone.
  const long k_ray_lo = static_cast<long>(std::floor(margin / angle_inc_rad_)) - 1;
  const long k_ray_hi = static_cast<long>(std::ceil((hi - lo + margin) / angle_inc_rad_)) + 1;
  std::size_t k_first_hit = 0;
  std::size_t k_last_hit = 0;
  DecisionFeatures& f = r.evidence.features;
  const Real sigma = params_.range_sigma_m;
  const Real gate = params_.inlier_gate_m;
  auto weight = [this](Real range_m) {
    const Real spacing_m = range_m * angle_inc_rad_;
    return spacing_m < kCorrelationLengthM ? spacing_m / kCorrelationLengthM : R(1);
  };
  Real sum_sq = 0;
  Real sum_clamped = 0;
  const Real clamp_sq = gate * gate;
  // Per-surface tallies: every surface the dock shows must be there, not just most beams overall (a box face
  // explains a winged dock's face and half of each wing).
  std::uint16_t seg_expected[kMaxProfileVertices] = {};
  std::uint16_t seg_inliers[kMaxProfileVertices] = {};
  // Returns on the wall the mounting allows behind the dock are the wall's, not a dock surface carrying on: a wall
  // a few centimetres behind a winged dock crosses the wings' lines just past their tips.
  const DockMountKind mount = profile_.mounting.kind;
  const Vec2 t_dock(r.pose.x_m, r.pose.y_m);
  const Vec2& x_dock = placed_.x_axis;
  auto wall_band = [&](const Vec2& p) {
    const Real x = x_dock.dot(p - t_dock);
    return x < back_x_m_ + gate && x > back_x_m_ - wall_gap_max_m_ - gate;
  };
  const bool check_band = mount != DockMountKind::kFreeStanding;
  // A return outside the dock's box grown by the inlier gate is not on the dock.
  Vec2 box_lo;
  Vec2 box_hi;
  gated_box(placed_, gate, &box_lo, &box_hi);
  const bool read_stripes = profile_.reflector_count > 0 && intensity_usable_ && intensities_ != nullptr;
  // The stripe pattern's regions, read beam by beam: each stripe, the gap before it, the gap after a segment's last.
  // 16 bits: a fine lidar near the dock puts hundreds of beams on one stripe.
  std::uint16_t stripe_n[kMaxReflectors] = {};
  std::uint16_t stripe_bright[kMaxReflectors] = {};
  std::uint16_t gap_n[kMaxReflectors] = {};
  std::uint16_t gap_bright[kMaxReflectors] = {};
  std::uint16_t after_n[kMaxReflectors] = {};
  std::uint16_t after_bright[kMaxReflectors] = {};
  // A bright beam deep inside a gap next to another bright beam is tape, not a glint: another code's stripe reaching
  // into the gap. Neighbours are consecutive inlier beams on one segment, as the stripe reader's runs.
  bool gap_run[kMaxReflectors] = {};
  bool after_run[kMaxReflectors] = {};
  std::size_t run_prev_seg = kMaxProfileVertices;
  bool run_prev_bright = false;
  bool* run_prev_gap = nullptr;
  // A bright run's length does not depend on where the pose puts the dock along its face. A run of consecutive
  // bright inlier beams on a taped segment proves tape over its span less each end beam's edge margin: more than the
  // code's longest piece there is tape this code does not have, however far along the face the pose may be off.
  // Bounded by a dark beam at each end, it holds at most the span between those beams and the slack of a beam's
  // place either side (a dark beam is not mostly on tape): less than the piece under its middle is that piece lit in
  // part, or another code's shorter stripe. Across a corner a pose error moves the two segments' hits apart, so a
  // corner ends a run.
  bool long_run_open = false;
  Real long_run_lo = 0;  // the tape the run proves, along its segment
  Real long_run_hi = 0;
  Real long_run_mid = 0;
  std::size_t long_run_seg = kMaxProfileVertices;
  bool prev_dark = false;  // the previous inlier beam on long_run_seg read dark, at prev_dark_m along it
  Real prev_dark_m = 0;
  bool run_bounded = false;  // the open run began next to a dark beam, at run_dark_m
  Real run_dark_m = 0;
  bool run_misfit = false;
  // Closes the open run; `dark_end`: at a dark beam `dark_end_m` along the segment. O(stripes).
  auto close_run = [&](bool dark_end, Real dark_end_m) {
    if (long_run_open && seg_taped_[long_run_seg]) {
      Real longest_m = 0;
      Real under_m = 0;
      for (std::size_t q = 0; q < profile_.reflector_count;) {
        Real to_m = 0;
        const std::size_t next = tape_piece(q, &to_m);
        const ReflectorStripe& st = profile_.reflectors[q];
        q = next;
        if (st.segment != long_run_seg) continue;
        const Real piece_m = to_m - st.from_m;
        longest_m = piece_m > longest_m ? piece_m : longest_m;
        if (long_run_mid >= st.from_m && long_run_mid <= to_m) under_m = piece_m;
      }
      if (long_run_hi - long_run_lo > longest_m) run_misfit = true;
      if (run_bounded && dark_end && std::fabs(dark_end_m - run_dark_m) + 2 * kStripeEdgeMarginM < under_m) {
        run_misfit = true;
      }
    }
    long_run_open = false;
  };
  // The fit's covariance (as estimate() reports it), for how far along a taped segment a beam's hit may lie from
  // where this pose puts it.
  Mat3 pose_cov = Mat3::Zero();
  bool pose_fixed = false;
  if (read_stripes) {
    Mat3 h_inv;
    const Real fit_sigma = r.rms_m > params_.range_sigma_m ? r.rms_m : params_.range_sigma_m;
    pose_fixed = invert_sym3(r.h, &h_inv) && h_inv.allFinite();
    pose_cov = fit_sigma * fit_sigma * h_inv;
  }
  const Vec2 t_pose(r.pose.x_m, r.pose.y_m);
  // Standard deviation of the along-segment position of the ray's hit at point p of segment `seg`: a pose error
  // moves the segment by delta at p, and the ray then meets it (n·delta)·tan(incidence) - d·delta further along.
  // O(1).
  auto along_sigma_m = [&](std::size_t seg, const Vec2& p) {
    const Vec2& n = placed_.n[seg];
    const Vec2& d = placed_.u[seg];
    const Real dist = p.norm();
    if (dist <= 0) return R(0);
    Real nu = n.dot(p) / dist;
    if (std::fabs(nu) < kMinCosIncidence) nu = nu < 0 ? -kMinCosIncidence : kMinCosIncidence;
    const Vec2 a = n * (d.dot(p) / dist / nu) - d;
    const Vec2 rel = p - t_pose;
    const Vec3 j(a.x(), a.y(), a.y() * rel.x() - a.x() * rel.y());
    const Real var = j.dot(pose_cov * j);
    return var > 0 ? std::sqrt(var) : R(0);
  };
  for (std::size_t k = 0; k < n_beams && k < beams_; ++k) {
    std::size_t i = 0;
    if (!beam_at(first, k, &i)) continue;
    const Real m = range_at(i);
    Real expected_m = 0;
    std::size_t seg = 0;
    bool on_dock = false;
    const long kl = static_cast<long>(k);
    if (kl >= k_ray_lo && kl <= k_ray_hi && placed_.raycast(dir_[i], &expected_m, &seg)) {
      // The surface length this beam covers: its spacing stretched by the incidence (capped as in the fit).
      Real cos_inc = std::fabs(placed_.n[seg].dot(dir_[i]));
      cos_inc = cos_inc > kMinCosIncidence ? cos_inc : kMinCosIncidence;
      const Real w = weight(expected_m / cos_inc);
      if (r.expected == 0) k_first_hit = k;
      k_last_hit = k;
      ++r.expected;
      const Real diff = m - expected_m;
      if (m != 0 && std::fabs(diff) <= gate) {
        on_dock = true;
        if (read_stripes) {
          const Real len = placed_.len_m[seg];
          const Real s = placed_.along_m(seg, expected_m * dir_[i]);
          // Half the beam's footprint on the surface, and a little more: a beam closer to a stripe's end may
          // straddle it.
          const Real edge_m = kStripeEdgeMarginM + R(0.5) * expected_m * angle_inc_rad_ / cos_inc;
          const bool bright = intensities_[i] >= params_.reflector_min_intensity;
          // The region the beam lands in: a stripe q, the gap before it (from the previous stripe on this segment
          // or the segment's start), or the gap after the segment's last stripe.
          std::size_t last = kMaxReflectors;
          bool placed_in_region = false;
          bool* in_gap = nullptr;  // The gap this beam lies deep inside, if any.
          const Real deep_m = edge_m + kRunAlongSigmas * along_sigma_m(seg, expected_m * dir_[i]);
          // A bare end's margin at a corner with an untaped surface of the dock: a beam there, wherever the pose
          // error puts it, can find tape only on this end, so a bright one is read when this code's stripe could
          // not spill that far (three standard deviations of the pose's along-face error); a dark one may lie on
          // the other surface and tells nothing.
          const bool bright_at_start = bright && seg > 0 && !seg_taped_[seg - 1];
          const bool bright_at_end = bright && seg + 1 < placed_.segments && !seg_taped_[seg + 1];
          for (std::size_t q = 0; q < profile_.reflector_count && !placed_in_region; ++q) {
            const ReflectorStripe& st = profile_.reflectors[q];
            if (st.segment != seg) continue;
            if (s < st.from_m) {
              const Real gap_from = last < kMaxReflectors ? profile_.reflectors[last].to_m : R(0);
              const bool corner = last == kMaxReflectors && bright_at_start && s <= st.from_m - deep_m;
              if ((s >= gap_from + edge_m || corner) && s <= st.from_m - edge_m) {
                ++gap_n[q];
                if (bright) ++gap_bright[q];
                // A segment's bare start has no stripe of this code before it to spill over: the margin there is
                // the edge's alone.
                const Real from_deep_m = gap_from + (last < kMaxReflectors ? deep_m : edge_m);
                if (s >= from_deep_m && s <= st.from_m - deep_m) in_gap = &gap_run[q];
              }
              placed_in_region = true;
            } else if (s <= st.to_m) {
              if (s >= st.from_m + edge_m && s <= st.to_m - edge_m) {
                ++stripe_n[q];
                if (bright) ++stripe_bright[q];
              }
              placed_in_region = true;
            }
            last = q;
          }
          if (!placed_in_region && last < kMaxReflectors && s >= profile_.reflectors[last].to_m + edge_m &&
              (s <= len - edge_m || (bright_at_end && s >= profile_.reflectors[last].to_m + deep_m))) {
            ++after_n[last];
            if (bright) ++after_bright[last];
            // Nor has a bare end a stripe of this code after it: only the edge margin keeps a run off its end.
            if (s >= profile_.reflectors[last].to_m + deep_m) in_gap = &after_run[last];
          }
          if (bright && run_prev_bright && seg == run_prev_seg) {
            if (in_gap != nullptr) *in_gap = true;
            if (run_prev_gap != nullptr) *run_prev_gap = true;
          }
          run_prev_seg = seg;
          run_prev_bright = bright;
          run_prev_gap = in_gap;
          // A dark beam well inside a piece of this code's tape is left to the stripe's own tally (which forgives a
          // quarter of its beams): it neither ends nor bounds a run.
          bool dark_inside = false;
          for (std::size_t q = 0; q < profile_.reflector_count && !bright && !dark_inside;) {
            const ReflectorStripe& st = profile_.reflectors[q];
            Real to_m = 0;
            q = tape_piece(q, &to_m);
            dark_inside = st.segment == seg && s >= st.from_m + edge_m && s <= to_m - edge_m;
          }
          if (seg != long_run_seg) {
            close_run(false, 0);
            prev_dark = false;
          } else if (!bright && !dark_inside) {
            close_run(true, s);
          }
          if (bright) {
            if (!long_run_open) {
              long_run_open = true;
              long_run_lo = s + edge_m;
              long_run_hi = s - edge_m;
              run_bounded = prev_dark;
              run_dark_m = prev_dark_m;
            }
            // Whichever way the scan runs along the segment.
            long_run_lo = s + edge_m < long_run_lo ? s + edge_m : long_run_lo;
            long_run_hi = s - edge_m > long_run_hi ? s - edge_m : long_run_hi;
            long_run_mid = R(0.5) * (long_run_lo + long_run_hi);
          }
          if (!dark_inside) {
            prev_dark = !bright;
            prev_dark_m = s;
          }
          long_run_seg = seg;
        }
        ++r.inliers;
        ++seg_expected[seg];
        ++seg_inliers[seg];
        sum_sq += diff * diff;
        sum_clamped += diff * diff;
        f.hit += w;
        f.hit_sq += w * diff * diff / (sigma * sigma);
      } else if (m != 0 && diff < -params_.free_space_m) {
        // Something well in front of the dock hides it: partial occlusion, neither for nor against.
        ++r.occluded;
      } else {
        ++r.violations;
        ++seg_expected[seg];
        sum_clamped += clamp_sq;
        if (m == 0) {
          f.dropped += w;
        } else if (diff > 0) {
          f.beyond += w;
        } else {
          f.front += w;
        }
      }
    }
    // An inlier lies on the dock (within the gate along its beam, so within it of the surface): no extension.
    if (m != 0 && !on_dock && !(check_band && wall_band(m * dir_[i]))) {
      const int ext = continues_past_end(m * dir_[i], box_lo, box_hi);
      if (ext == 1) f.stops += weight(m);
      if (ext == 2) {
        ++r.extensions;
        f.continues += weight(m);
      }
    }
  }
  if (read_stripes) {
    close_run(false, 0);
    if (run_misfit) ++f.regions_unread;
    // A stripe reads as tape when three quarters of its beams or more are bright, as bare when under half are, and
    // neither way in between. A gap reads bare when at most a quarter of its beams are bright, as tape when two or
    // more and over a quarter are; one bright beam among fewer than four is either a glint or another dock's stripe
    // seen by one beam, so that gap is not read. The code is read only when every stripe and every gap between
    // stripes of kMinRegionM or more is: one with no beam well inside it (too narrow for the range, hidden) or read
    // neither way leaves the pattern unknown, and a pattern known in part could be another dock's. A bare end of a
    // segment is needed only where it is wide enough at this pose to hold a beam inside its margins (a margin the
    // tape was kept off a corner is no part of the code at range).
    auto read = [&](std::uint16_t n, std::uint16_t bright, bool tape_expected, bool needed, bool run) {
      bool reads_tape = 2 * bright >= n;
      // A stripe with over a quarter of its beams dark is lit in part: another code's stripe half over it, or
      // this one seen from a pose off along the face by part of a region. Neither way: not read.
      if (tape_expected && reads_tape && 4 * bright < 3 * n) n = 0;
      if (!tape_expected && n > 0) {
        if (run || (bright >= 2 && 4 * bright > n)) {
          reads_tape = true;
        } else if (4 * bright <= n) {
          reads_tape = false;
        } else {
          n = 0;  // neither way: not read
        }
      }
      if (n == 0) {
        if (needed) ++f.regions_unread;
        return;
      }
      ++(reads_tape == tape_expected ? f.regions_matched : f.regions_mismatched);
      if (tape_expected && reads_tape) ++f.stripes_matched;
      if (tape_expected) f.stripe_beams = static_cast<std::uint16_t>(f.stripe_beams + n);
      f.bright_beams = static_cast<std::uint16_t>(f.bright_beams + bright);
    };
    // Whether an end region [from_m, to_m] of segment `seg` holds a beam inside its margins at this pose.
    auto wide_enough = [&](std::uint8_t seg, Real from_m, Real to_m) {
      const Vec2 mid = placed_.v_m[seg] + placed_.d_m[seg] * ((from_m + to_m) * R(0.5) / placed_.len_m[seg]);
      const Real dist_m = mid.norm();
      Real cos_inc = dist_m > 0 ? std::fabs(placed_.n[seg].dot(mid)) / dist_m : R(1);
      cos_inc = cos_inc > kMinCosIncidence ? cos_inc : kMinCosIncidence;
      return to_m - from_m >= 2 * kStripeEdgeMarginM + 2 * dist_m * angle_inc_rad_ / cos_inc;
    };
    // Whether the pose fixes a region [from_m, to_m] of segment `seg` along the face well within its width.
    auto pinned = [&](std::uint8_t seg, Real from_m, Real to_m) {
      const Vec2 mid = placed_.v_m[seg] + placed_.d_m[seg] * ((from_m + to_m) * R(0.5) / placed_.len_m[seg]);
      return pose_fixed && to_m - from_m >= kRegionAlongSigmas * along_sigma_m(seg, mid);
    };
    for (std::size_t q = 0; q < profile_.reflector_count; ++q) {
      const ReflectorStripe& st = profile_.reflectors[q];
      if (st.to_m - st.from_m >= kMinRegionM && !pinned(st.segment, st.from_m, st.to_m)) ++f.regions_unread;
      const bool first_on_segment = q == 0 || profile_.reflectors[q - 1].segment != st.segment;
      const bool last_on_segment =
          q + 1 == profile_.reflector_count || profile_.reflectors[q + 1].segment != st.segment;
      const Real gap_from = first_on_segment ? R(0) : profile_.reflectors[q - 1].to_m;
      const Real seg_len = placed_.len_m[st.segment];
      if (st.from_m - gap_from >= kMinRegionM) {
        // An end seen by a beam must read as the profile says, wide enough or not: a bright beam there may be
        // another code's stripe.
        read(gap_n[q], gap_bright[q], false,
             !first_on_segment || gap_n[q] > 0 || wide_enough(st.segment, gap_from, st.from_m), gap_run[q]);
      }
      if (st.to_m - st.from_m >= kMinRegionM) read(stripe_n[q], stripe_bright[q], true, true, false);
      if (last_on_segment && seg_len - st.to_m >= kMinRegionM) {
        read(after_n[q], after_bright[q], false, after_n[q] > 0 || wide_enough(st.segment, st.to_m, seg_len),
             after_run[q]);
      }
    }
  }
  for (std::size_t j = 0; j < placed_.segments; ++j) {
    // Short features (slots, steps) are left out: mixed pixels at their depth edges make their beams unreliable.
    if ((placed_.v_m[j + 1] - placed_.v_m[j]).norm() < params_.min_feature_length_m) continue;
    // One stray beam per surface is forgiven (a mixed pixel at an edge would sink a 3-beam wing); past that, a
    // surface with under 70 % of its beams on it counts as partly missing, under 50 % as missing.
    if (seg_expected[j] < 3) continue;
    const Real absent = static_cast<Real>(seg_expected[j] - seg_inliers[j]);
    const Real allowed = R(0.3) * static_cast<Real>(seg_expected[j]);
    if (2 * seg_inliers[j] < seg_expected[j]) {
      f.missing += 1;
    } else if (absent > (allowed > 1 ? allowed : R(1))) {
      f.missing += R(0.5);
    }
  }
  const Real w_dock = weight(dist_to_dock);
  if (r.expected > 0 && mount != DockMountKind::kFreeStanding) {
    wall_behind(r.pose, first, k_first_hit, k_last_hit, &r.wall_seen, &r.wall_looked);
    f.wall_seen = w_dock * static_cast<Real>(r.wall_seen);
    f.wall_missed = w_dock * static_cast<Real>(r.wall_looked - r.wall_seen);
  }
  f.constraint = w_dock * min_eigen_sym3(arc_scaled(r.h));
  Real* cue = r.evidence.cue_nats;
  // A wider gate (a noisier lidar) catches chance surfaces more often: a hit is worth less by the gate's growth.
  const Real gate_growth = gate > kReferenceGateM ? kGateGrowthShare * std::log(gate / kReferenceGateM) : R(0);
  cue[static_cast<std::size_t>(EvidenceCue::kFit)] =
      kFitBaseNats + (kFitPerHitNats - gate_growth) * f.hit + kFitPerSqNats * f.hit_sq;
  cue[static_cast<std::size_t>(EvidenceCue::kSeeThrough)] = kBeyondNats * f.beyond;
  cue[static_cast<std::size_t>(EvidenceCue::kFreeSpace)] = kFrontNats * f.front;
  cue[static_cast<std::size_t>(EvidenceCue::kSupport)] = kMissingNats * f.missing;
  cue[static_cast<std::size_t>(EvidenceCue::kEdges)] = kContinuesNats * f.continues + kStopsNats * f.stops;
  // Unknown mounting: a wall seen is evidence, none seen is not held against the dock.
  cue[static_cast<std::size_t>(EvidenceCue::kWall)] =
      mount == DockMountKind::kWall ? kWallSeenMountedNats * f.wall_seen + kWallMissedMountedNats * f.wall_missed
                                    : kWallSeenUnknownNats * f.wall_seen;
  cue[static_cast<std::size_t>(EvidenceCue::kGeometry)] =
      kConstraintNats * std::log(f.constraint > kMinConstraint ? f.constraint : kMinConstraint);
  if (hint != nullptr && params_.hint_radius_m > 0) {
    // A Gaussian prior of σ = half the hint radius against a uniform spread over the search area.
    const Real s_prior = params_.hint_radius_m * R(0.5);
    const Real area_ratio = params_.max_range_m * params_.max_range_m / (2 * s_prior * s_prior);
    cue[static_cast<std::size_t>(EvidenceCue::kPrior)] =
        std::log(area_ratio > 1 ? area_ratio : R(1)) - dist2(r.pose, *hint) / (2 * s_prior * s_prior);
  }
  cue[static_cast<std::size_t>(EvidenceCue::kIntensity)] =
      kRegionMatchNats * static_cast<Real>(f.regions_matched) +
      kRegionMismatchNats * static_cast<Real>(f.regions_mismatched);
  for (std::size_t c = 0; c < kEvidenceCueCount; ++c) r.evidence.total_nats += cue[c];
  if (r.inliers > 0) r.rms_m = std::sqrt(sum_sq / static_cast<Real>(r.inliers));
  const std::uint16_t unoccluded_n = static_cast<std::uint16_t>(r.expected - r.occluded);
  r.shape_rms_m = unoccluded_n > 0 ? std::sqrt(sum_clamped / static_cast<Real>(unoccluded_n)) : R(0);
  const Real expected = static_cast<Real>(r.expected);
  const Vec2 t(r.pose.x_m, r.pose.y_m);
  const Real dist_m = t.norm();
  const Vec2& face = placed_.x_axis;
  const Real cos_view = dist_m > 0 ? -face.dot(t) / dist_m : R(-1);
  r.reject = RejectReason::kNone;
  if (r.inliers < min_inliers()) {
    r.reject = RejectReason::kTooFewInliers;
  } else if (static_cast<Real>(r.inliers) < params_.min_visible_fraction * expected) {
    r.reject = RejectReason::kMostlyHidden;
  } else if (cos_view < std::cos(params_.max_view_angle_rad)) {
    r.reject = RejectReason::kOblique;
  } else if (dist_m > params_.max_range_m) {
    r.reject = RejectReason::kOutOfRange;
  } else if (r.evidence.total_nats < params_.min_evidence_nats) {
    r.reject = RejectReason::kWeakEvidence;
  } else if (f.regions_mismatched > 0) {
    r.reject = RejectReason::kWrongCode;
  } else if (read_stripes && (f.stripes_matched == 0 || f.regions_unread > 0)) {
    r.reject = RejectReason::kCodeUnread;
  }
  if (r.reject != RejectReason::kNone) return;
  r.ok = true;
}

Mat3 DockPoseEstimatorBase::arc_scaled(const Mat3& h) const {
  const Real s = profile_radius_m_ > 0 ? 1 / profile_radius_m_ : R(1);
  Mat3 out = h;
  out.row(2) *= s;
  out.col(2) *= s;
  return out;
}

std::size_t DockPoseEstimatorBase::edge_terms(const Pose2& pose, Mat3* h, Vec3* g) const {
  const std::size_t segments = placed_.segments;
  if (segments == 0 || beams_ == 0) return 0;
  const Vec2 t(pose.x_m, pose.y_m);
  const Real gate = params_.inlier_gate_m;
  // In the surfaces' units: range_sigma_m is what one beam's residual is worth, and what the covariance scales by.
  const Real sigma_sq = params_.range_sigma_m * params_.range_sigma_m;
  std::size_t used = 0;
  for (std::size_t j = 0; j <= segments; ++j) {
    const bool vis_before = j > 0 && placed_.visible[j - 1];
    const bool vis_after = j < segments && placed_.visible[j];
    // Both visible: a corner, the rays either side meet one surface or the other at about the same range.
    if (vis_before == vis_after) continue;
    const std::size_t s_on = vis_before ? j - 1 : j;
    const Vec2& v = placed_.v_m[j];
    const Real rho = v.norm();
    if (!(rho > params_.min_range_m)) continue;
    // A point of the surface just inside its end must be what the ray meets: no other part of the dock hides it.
    const Vec2 inside = v + placed_.u[s_on] * (vis_before ? -kEdgeProbeM : kEdgeProbeM);
    const Real inside_m = inside.norm();
    Real hit_m = 0;
    std::size_t hit_seg = 0;
    if (!placed_.raycast(inside / inside_m, &hit_m, &hit_seg) || hit_seg != s_on) continue;
    const Vec2 v_dir = v / rho;
    // Which way (counter-clockwise +1) the surface lies from its end, as seen from the lidar.
    const Real on_side = v_dir.x() * inside.y() - v_dir.y() * inside.x() > 0 ? R(1) : R(-1);
    const Vec2& n = placed_.n[s_on];
    const Real c = placed_.c_m[s_on];
    const long centre = first_beam(std::atan2(v.y(), v.x()));
    // Walking from the side away from the surface towards it: the last beam past the surface's line before a beam on
    // it. Offsets are sines of the angle from the vertex, signed towards the surface.
    bool have_off = false;
    Real off_s = 0;
    std::size_t since_off = 0;
    bool found = false;
    Real best_mid = 0;
    Real best_width = 0;
    for (long q = -kEdgeSearchBeams; q <= kEdgeSearchBeams; ++q) {
      const long step = on_side > 0 ? q : -q;
      std::size_t i = 0;
      if (!beam_at(centre + step, 0, &i)) continue;
      const Vec2& d = dir_[i];
      const Real s = on_side * (v_dir.x() * d.y() - v_dir.y() * d.x());
      const Real m = range_at(i);
      const Real nd = n.dot(d);
      // Along this beam, the range at which it meets the surface's line (extended past its end).
      const Real line_m = nd < 0 ? c / nd : R(0);
      ++since_off;
      if (m == 0 || !(line_m > 0)) continue;
      if (m > line_m + gate) {
        have_off = true;
        off_s = s;
        since_off = 0;
      } else if (std::fabs(m - line_m) <= gate && have_off && since_off <= 2) {
        const Real mid = R(0.5) * (off_s + s);
        if (!found || std::fabs(mid) < std::fabs(best_mid)) {
          found = true;
          best_mid = mid;
          best_width = s - off_s;
        }
        have_off = false;
      }
    }
    if (!found || !(best_width > 0)) continue;
    // The vertex's bearing lies uniformly between the two beams: residual of the pose's bearing in metres across the
    // ray, standard deviation width/√12 in the same units.
    const Real e = -on_side * best_mid * rho;
    const Real var = rho * rho * best_width * best_width / 12;
    const Real w = sigma_sq / var;
    const Vec2 u_perp(-v_dir.y(), v_dir.x());
    const Vec2 rel = v - t;
    const Vec3 jac(u_perp.x(), u_perp.y(), u_perp.x() * -rel.y() + u_perp.y() * rel.x());
    *h += w * jac * jac.transpose();
    *g += w * e * jac;
    ++used;
  }
  return used;
}

void DockPoseEstimatorBase::decide(Refined& r, const Pose2* hint) {
  verify(r, hint);
  if (r.ok && hint != nullptr && params_.hint_radius_m > 0 &&
      dist2(r.pose, *hint) > params_.hint_radius_m * params_.hint_radius_m) {
    r.ok = false;
    r.reject = RejectReason::kFarFromHint;
  }
}

Real DockPoseEstimatorBase::prescore(const Pose2& pose, Real floor) {
  placed_.place(profile_, pose);
  Real lo = 0;
  Real hi = 0;
  placed_.angular_span(&lo, &hi);
  const std::size_t n_beams = static_cast<std::size_t>((hi - lo) / angle_inc_rad_) + 2;
  const long first = first_beam(lo);
  const Real gate = 2 * params_.inlier_gate_m;
  Real score = 0;
  // Every other beam, and no more than kPrescoreRays: ranking only needs a rough count, refinement and verification
  // look at all of them. Each ray counts for the beams it stands for, so near and far hypotheses compare fairly.
  const std::size_t step = n_beams > 2 * kPrescoreRays ? n_beams / kPrescoreRays : 2;
  const Real per_ray = static_cast<Real>(step) * R(0.5);
  const std::size_t limit = n_beams < beams_ ? n_beams : beams_;
  // The most the rays still to cast can add. Scores are multiples of a half, so the comparison is exact.
  const std::size_t rays = (limit + step - 1) / step;
  Real reachable = static_cast<Real>(rays) * per_ray;
  for (std::size_t k = 0; k < limit; k += step) {
    if (score + reachable < floor) return score + reachable;
    reachable -= per_ray;
    std::size_t i = 0;
    if (!beam_at(first, k, &i)) continue;
    Real expected_m = 0;
    std::size_t seg = 0;
    if (!placed_.raycast(dir_[i], &expected_m, &seg)) continue;
    const Real m = range_at(i);
    if (m != 0 && std::fabs(m - expected_m) <= gate) {
      score += per_ray;
    } else if (m == 0 || m > expected_m) {
      score -= 2 * per_ray;  // seeing through the dock is strong evidence against it
    }
  }
  return score;
}

Pose2 DockPoseEstimatorBase::hypothesis_pose(const Vec2& n_scan, const Vec2& anchor_scan, const Vec2& anchor_dock,
                                             std::size_t profile_segment) const {
  // The rotation taking the profile's unit normal onto the scan's: cosine and sine straight from the dot and cross
  // products (both normals are unit), so only the reported yaw needs an arctangent.
  const Vec2 n_j = profile_.normal(profile_segment);
  const Real c = n_j.dot(n_scan);
  const Real s = n_j.x() * n_scan.y() - n_j.y() * n_scan.x();
  const Vec2 t = anchor_scan - Vec2(c * anchor_dock.x() - s * anchor_dock.y(), s * anchor_dock.x() + c * anchor_dock.y());
  return Pose2{t.x(), t.y(), std::atan2(s, c)};
}

void DockPoseEstimatorBase::push_hypothesis(const Vec2& n_scan, const Vec2& anchor_scan, const Vec2& anchor_dock,
                                            std::size_t profile_segment, std::size_t* n) {
  if (*n >= kMaxHypotheses) {
    ++counters_.truncated_candidates;
    return;
  }
  hyps_[*n].pose = hypothesis_pose(n_scan, anchor_scan, anchor_dock, profile_segment);
  // Only the best max_candidates are refined: a hypothesis that cannot reach the current last of them needs no
  // exact score (it stays below that one, which only rises).
  const std::size_t keep = params_.max_candidates;
  const bool full = keep <= kMaxRanked && n_ranked_ == keep;
  const Real score = prescore(hyps_[*n].pose, full ? ranked_[keep - 1] : -std::numeric_limits<Real>::infinity());
  hyps_[*n].prescore = score;
  ++*n;
  if (keep > kMaxRanked || (full && !(score > ranked_[keep - 1]))) return;
  std::size_t pos = full ? keep - 1 : n_ranked_++;
  for (; pos > 0 && ranked_[pos - 1] < score; --pos) ranked_[pos] = ranked_[pos - 1];
  ranked_[pos] = score;
}

namespace {

// Running first and second moments of a point set, relative to a local origin (keeps float builds accurate).
struct RunningMoments {
  Vec2 origin = Vec2::Zero();
  Real n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
  void add(const Vec2& p, Real sign) {
    const Vec2 d = p - origin;
    n += sign;
    sx += sign * d.x();
    sy += sign * d.y();
    sxx += sign * d.x() * d.x();
    sxy += sign * d.x() * d.y();
    syy += sign * d.y() * d.y();
  }
  // Centroid (relative to origin) and covariance of the points, with half the difference of its diagonal and the
  // distance of its eigenvalues from their mean.
  struct Spread {
    Real mx, my, cxy, half_sum, half_diff, root;
  };
  Spread spread() const {
    const Real mx = sx / n;
    const Real my = sy / n;
    const Real cxx = sxx / n - mx * mx;
    const Real cxy = sxy / n - mx * my;
    const Real cyy = syy / n - my * my;
    const Real half_diff = (cxx - cyy) * R(0.5);
    return Spread{mx, my, cxy, (cxx + cyy) * R(0.5), half_diff, std::sqrt(half_diff * half_diff + cxy * cxy)};
  }
  // Mean squared orthogonal residual of the total-least-squares line: the smaller eigenvalue of the covariance.
  // Cheap (one square root), so a window is tested before its line is worked out.
  Real msr() const {
    const Spread c = spread();
    const Real lo = c.half_sum - c.root;
    return lo > 0 ? lo : 0;
  }
  // The line itself: centroid and unit normal. The principal axis is the eigenvector of the larger eigenvalue,
  // taken from whichever of the two equivalent forms has the larger components (no trigonometry).
  void line(Vec2* centroid, Vec2* normal) const {
    const Spread c = spread();
    // lambda_max - cyy = half_diff + root and lambda_max - cxx = root - half_diff: add, never cancel.
    Vec2 axis = c.half_diff >= 0 ? Vec2(c.half_diff + c.root, c.cxy) : Vec2(c.cxy, c.root - c.half_diff);
    const Real len = axis.norm();
    axis = len > 0 ? Vec2(axis / len) : Vec2(1, 0);
    *centroid = origin + Vec2(c.mx, c.my);
    *normal = Vec2(-axis.y(), axis.x());
  }
};

}  // namespace

std::size_t DockPoseEstimatorBase::tape_piece(std::size_t q, Real* to_m) const {
  const ReflectorStripe& first = profile_.reflectors[q];
  Real end_m = first.to_m;
  std::size_t next = q + 1;
  while (next < profile_.reflector_count && profile_.reflectors[next].segment == first.segment &&
         profile_.reflectors[next].from_m <= end_m + kStripeEdgeMarginM) {
    end_m = profile_.reflectors[next++].to_m;
  }
  *to_m = end_m;
  return next;
}

bool DockPoseEstimatorBase::depth_gap(const ScanPoint& a, const ScanPoint& b) const {
  const Real step_m = 5 * a.range_m * angle_inc_rad_;
  const Real allowed = step_m > R(0.05) ? step_m : R(0.05);
  return (b.p_m - a.p_m).squaredNorm() > allowed * allowed;
}

void DockPoseEstimatorBase::add_window_hypotheses(std::size_t* n) {
  // Split the points into contiguous runs (no range gap), in circular order on a full-turn scan.
  const std::size_t np = points_.size();
  if (np < 5) return;
  // Where a depth gap follows a point, worked out once for every profile segment's pass. assoc_seg_ holds nothing
  // until registration starts, so it serves as the scratch flags.
  std::uint8_t* const gap = assoc_seg_;
  for (std::size_t k = 0; k < np; ++k) {
    const ScanPoint& a = points_[k];
    const ScanPoint& b = points_[(k + 1) % np];
    gap[k] = depth_gap(a, b) ? 1 : 0;
  }
  auto gap_after = [gap](std::size_t k) { return gap[k] != 0; };
  // Start just after a gap so no run is cut by the array's end (only matters when the scan wraps).
  std::size_t start = 0;
  if (wraps_) {
    for (std::size_t k = 0; k < np; ++k) {
      if (gap_after(k)) {
        start = (k + 1) % np;
        break;
      }
    }
  }
  const Real gate = R(1.5) * params_.range_sigma_m;       // a dock surface is flat to the noise level
  const Real break_m = R(2.5) * params_.range_sigma_m;    // a neighbour this far off the line ends the surface
  // Segments of the same length (a symmetric dock's wings) find the same windows: the first one's kept windows are
  // staged in the unused tail of hyps_ and pushed again for the others, in the order a pass would find them.
  const std::size_t segments = profile_.segment_count();
  auto length_of = [this](std::size_t j) { return (profile_.vertices_m[j + 1] - profile_.vertices_m[j]).norm(); };
  Real staged_len = -1;
  std::size_t staged = 0;
  bool staging = false;
  for (std::size_t j = 0; j < segments; ++j) {
    const Vec2& a_j = profile_.vertices_m[j];
    const Vec2& b_j = profile_.vertices_m[j + 1];
    const Real len_j = length_of(j);
    if (len_j < params_.min_feature_length_m) continue;
    const Vec2 mid_j = (a_j + b_j) * R(0.5);
    // The staged windows are intact while the hypotheses pushed since have stayed below them; replaying pushes
    // `staged` more, which must stay below them too.
    if (staging && len_j == staged_len && *n + 2 * staged <= kMaxHypotheses) {
      for (std::size_t w = 0; w < staged; ++w) {
        const Hypothesis h = hyps_[kMaxHypotheses - 1 - w];
        push_hypothesis(Vec2(h.pose.yaw_rad, h.prescore), Vec2(h.pose.x_m, h.pose.y_m), mid_j, j, n);
      }
      continue;
    }
    bool stage = false;
    for (std::size_t k = j + 1; k < segments && !stage; ++k) stage = length_of(k) == len_j;
    if (stage) {
      staged_len = len_j;
      staged = 0;
      staging = true;
    }
    const Real half = len_j * R(0.5);
    const Real half_sq = half * half;
    const Real min_span_sq = R(0.49) * len_j * len_j;     // the window spans 70 % of the segment at least
    const Real min_apart_sq = R(0.0625) * len_j * len_j;  // kept windows a quarter of the segment apart
    std::size_t run_lo = 0;  // positions in circular order, relative to start
    while (run_lo < np) {
      std::size_t run_hi = run_lo;
      while (run_hi + 1 < np && !gap_after((start + run_hi) % np)) ++run_hi;
      auto at = [this, start, np](std::size_t pos) -> const Vec2& { return points_[(start + pos) % np].p_m; };
      RunningMoments m;
      m.origin = at(run_lo);
      std::size_t lo = run_lo;
      std::size_t hi = run_lo;
      m.add(at(run_lo), 1);
      Vec2 last_kept(std::numeric_limits<Real>::max(), 0);
      std::size_t step = 1;
      for (std::size_t c = run_lo; c <= run_hi; c += step) {
        const Vec2& pc = at(c);
        while (hi + 1 <= run_hi && (at(hi + 1) - pc).squaredNorm() <= half_sq) m.add(at(++hi), 1);
        while (lo < c && (at(lo) - pc).squaredNorm() > half_sq) m.add(at(lo++), -1);
        const std::size_t in_window = hi - lo + 1;
        step = in_window > kWindowStepsPerWindow ? in_window / kWindowStepsPerWindow : 1;
        if (m.n < 5 || (at(hi) - at(lo)).squaredNorm() < min_span_sq) continue;
        if (m.msr() > gate * gate) continue;
        Vec2 centroid;
        Vec2 normal;
        m.line(&centroid, &normal);
        // The surface must stop at one end at least: the middle of a wall is not a dock feature.
        const bool lo_break = lo == run_lo || std::fabs(normal.dot(at(lo - 1) - centroid)) > break_m;
        const bool hi_break = hi == run_hi || std::fabs(normal.dot(at(hi + 1) - centroid)) > break_m;
        if (!lo_break && !hi_break) continue;
        if ((centroid - last_kept).squaredNorm() < min_apart_sq) continue;  // neighbours of a kept window add nothing
        last_kept = centroid;
        if (normal.dot(centroid) > 0) normal = -normal;  // face the lidar
        if (stage && staging) {
          // A window, not a hypothesis: centroid in the position, normal in the yaw and the prescore.
          staging = *n + staged + 2 <= kMaxHypotheses;
          if (staging)
            hyps_[kMaxHypotheses - 1 - staged++] =
                Hypothesis{Pose2{centroid.x(), centroid.y(), normal.x()}, normal.y()};
        }
        push_hypothesis(normal, centroid, mid_j, j, n);
      }
      run_lo = run_hi + 1;
    }
  }
}

std::size_t DockPoseEstimatorBase::generate_candidates() {
  std::size_t n = 0;
  n_ranked_ = 0;
  add_window_hypotheses(&n);
  const SegmentStats stats = extract_line_segments(points_, angle_inc_rad_, wraps_, params_.segments, segs_);
  if (stats.truncated()) ++counters_.truncated_segments;
  for (std::size_t j = 0; j < profile_.segment_count(); ++j) {
    const Vec2& a_j = profile_.vertices_m[j];
    const Vec2& b_j = profile_.vertices_m[j + 1];
    const Real len_j = (b_j - a_j).norm();
    if (len_j < params_.min_feature_length_m) continue;
    const Vec2 mid_j = (a_j + b_j) * R(0.5);
    for (const LineSegment& seg : segs_) {
      const Real len_s = seg.length_m();
      // A partly hidden feature may be short; one much longer than the profile's is something else.
      if (len_s < R(0.35) * len_j || len_s > R(1.3) * len_j + 2 * params_.inlier_gate_m) continue;
      // Corners and mixed pixels inflate a feature's RMS.
      if (seg.rms_m > (3 * params_.range_sigma_m > R(0.012) ? 3 * params_.range_sigma_m : R(0.012))) continue;
      // Which end of the scan segment corresponds to the profile segment's first vertex: the rotation maps the
      // profile segment's direction onto the scan segment's, up to sign, and the normals agree.
      const Vec2 d_j = (b_j - a_j) / len_j;
      const Vec2 n_j = profile_.normal(j);
      const Vec2 d_s = seg.direction();
      // Rotation taking n_j to seg.normal (cosine and sine from the unit normals), applied to d_j, compared with
      // the scan direction.
      const Real c = n_j.dot(seg.normal);
      const Real s = n_j.x() * seg.normal.y() - n_j.y() * seg.normal.x();
      const Vec2 d_rot(c * d_j.x() - s * d_j.y(), s * d_j.x() + c * d_j.y());
      const bool same_dir = d_rot.dot(d_s) > 0;
      const Vec2& sa = same_dir ? seg.start_m : seg.end_m;
      const Vec2& sb = same_dir ? seg.end_m : seg.start_m;
      push_hypothesis(seg.normal, seg.midpoint_m(), mid_j, j, &n);
      if (len_s < R(0.85) * len_j) {
        push_hypothesis(seg.normal, sa, a_j, j, &n);
        push_hypothesis(seg.normal, sb, b_j, j, &n);
      }
    }
  }
  // Best prescores first (selection sort over at most max_candidates slots: n is small and bounded).
  const std::size_t keep = n < params_.max_candidates ? n : params_.max_candidates;
  for (std::size_t i = 0; i < keep; ++i) {
    std::size_t best = i;
    for (std::size_t k = i + 1; k < n; ++k) {
      if (hyps_[k].prescore > hyps_[best].prescore) best = k;
    }
    if (best != i) {
      const Hypothesis tmp = hyps_[i];
      hyps_[i] = hyps_[best];
      hyps_[best] = tmp;
    }
  }
  if (n > keep) counters_.truncated_candidates += static_cast<std::uint32_t>(n - keep);
  const bool stripes =
      params_.stripe_hypotheses && profile_.reflector_count > 0 && intensity_usable_ && intensities_ != nullptr;
  return keep + (stripes ? add_stripe_hypotheses(keep) : 0);
}

std::size_t DockPoseEstimatorBase::add_stripe_hypotheses(std::size_t at) {
  const std::size_t np = points_.size();
  const Real gate = params_.inlier_gate_m;
  auto bright = [this](std::size_t k) { return intensities_[points_[k].index] >= params_.reflector_min_intensity; };
  std::size_t added = 0;
  std::size_t k = 0;
  while (k < np && added < kMaxStripeHypotheses && at + added < kMaxHypotheses) {
    if (!bright(k)) {
      ++k;
      continue;
    }
    // The run: consecutive bright returns without a depth gap.
    std::size_t last = k;
    while (last + 1 < np && bright(last + 1) && !depth_gap(points_[last], points_[last + 1])) ++last;
    const Vec2 centre = (points_[k].p_m + points_[last].p_m) * R(0.5);
    // What the run lights: its span and a beam's spacing either side (the tape's ends lie between beams).
    const Real lit_m = (points_[last].p_m - points_[k].p_m).norm() + 2 * centre.norm() * angle_inc_rad_;
    const std::size_t run_n = last + 1 - k;
    k = last + 1;
    if (run_n < 2) continue;
    const LineSegment* line = nullptr;
    for (const LineSegment& seg : segs_) {
      if (std::fabs(seg.signed_distance_m(centre)) > gate) continue;
      const Real along_m = seg.direction().dot(centre - seg.start_m);
      if (along_m < -gate || along_m > seg.length_m() + gate) continue;
      line = &seg;
      break;
    }
    if (line == nullptr) continue;
    const Vec2 on_line = centre - line->normal * line->signed_distance_m(centre);
    // Each piece of tape (touching stripes read as one run).
    std::size_t q = 0;
    while (q < profile_.reflector_count && added < kMaxStripeHypotheses && at + added < kMaxHypotheses) {
      const ReflectorStripe& first = profile_.reflectors[q];
      Real to_m = 0;
      const std::size_t end = tape_piece(q, &to_m);
      const Real piece_m = to_m - first.from_m;
      // A run much longer than the piece lies on something else (another code's wider stripe, a taped sign).
      if (lit_m - 2 * gate <= piece_m + 2 * kStripeEdgeMarginM) {
        const std::size_t seg = first.segment;
        const Vec2& a = profile_.vertices_m[seg];
        const Vec2 d = profile_.vertices_m[seg + 1] - a;
        const Real len_m = d.norm();
        const Vec2 mid = a + d * ((first.from_m + to_m) * R(0.5) / len_m);
        hyps_[at + added].pose = hypothesis_pose(line->normal, on_line, mid, seg);
        hyps_[at + added].prescore = 0;
        ++added;
      }
      q = end;
    }
  }
  return added;
}

void DockPoseEstimatorBase::report(const Refined& r, DockEstimate* est) {
  est->inliers = r.inliers;
  est->expected = r.expected;
  est->violations = r.violations;
  est->occluded = r.occluded;
  est->extensions = r.extensions;
  est->wall_seen = r.wall_seen;
  est->wall_looked = r.wall_looked;
  est->evidence = r.evidence;
}

DockEstimate DockPoseEstimatorBase::estimate(const ScanView& scan, const Pose2& lidar_mount, const Pose2* hint) {
  DockEstimate est;
  ++counters_.scans;
  if (!configured_) {
    est.status = EstimateStatus::kNoProfile;
    return est;
  }
  if (!load_scan(scan)) {
    ++counters_.bad_scans;
    est.status = EstimateStatus::kBadScan;
    return est;
  }
  const Pose2 mount_inv = lidar_mount.inverse();
  Pose2 hint_lidar{};
  if (hint != nullptr) hint_lidar = mount_inv.compose(*hint);
  // The hint is refined before the scan's returns are counted: when it verifies, at least min_inliers beams are
  // valid, so tracking never reads the beams away from the dock. Otherwise it is accounted for below, after the
  // same no-points test a hint-less scan gets.
  Refined hinted{};
  if (hint != nullptr) {
    hinted = refine(hint_lidar, false);
    decide(hinted, &hint_lidar);
  }
  const bool hint_holds = hint != nullptr && hinted.ok &&
                          dist2(hinted.pose, hint_lidar) <= params_.hint_gate_m * params_.hint_gate_m;
  // The global search's points are its count of valid returns.
  if (!hint_holds) {
    build_points();
    if (points_.size() < min_inliers()) {
      est.status = EstimateStatus::kNoPoints;
      return est;
    }
  }

  Refined best{};
  best.ok = false;
  Refined best_refused{};
  bool have_refused = false;
  bool best_from_hint = false;
  Real best_key = 0;
  // Accounts for a decided candidate and keeps the best.
  auto consider = [&](const Refined& r, bool from_hint) {
    ++counters_.candidates;
    ++est.candidates;
    if (!r.ok) {
      ++counters_.rejected;
      ++counters_.rejected_by[static_cast<std::size_t>(r.reject)];
      if (r.reject != RejectReason::kNoConvergence &&
          (!have_refused || r.evidence.total_nats > best_refused.evidence.total_nats)) {
        best_refused = r;
        have_refused = true;
      }
      return;
    }
    ++est.verified;
    const bool by_hint = params_.select == DockSelect::kHint && hint != nullptr;
    const Real key = by_hint ? dist2(r.pose, hint_lidar) : r.pose.x_m * r.pose.x_m + r.pose.y_m * r.pose.y_m;
    // Two verified poses within the dock's own size explain the same object: keep the one that explains it better
    // (a face placed on a wing can verify on the beams it predicts, with a worse fit). Two objects: one whose
    // evidence is far stronger wins (a look-alike box nearer than the dock must not take turns with it from scan to
    // scan); otherwise select by key (nearest, or nearest the hint).
    const bool same_object = best.ok && dist2(r.pose, best.pose) < profile_radius_m_ * profile_radius_m_;
    const Real margin = r.evidence.total_nats - best.evidence.total_nats;
    const bool better = !best.ok || (same_object                    ? margin > 0
                                     : margin > kSelectMarginNats   ? true
                                     : margin < -kSelectMarginNats  ? false
                                                                    : key < best_key);
    if (better) {
      best = r;
      best_key = key;
      best_from_hint = from_hint;
    }
  };

  if (hint != nullptr) consider(hinted, true);
  // Tracking: a hint that verifies and stays near the hint ends the search; a global search runs otherwise.
  if (!hint_holds) {
    const std::size_t n = generate_candidates();
    std::size_t done = 0;
    Pose2 verified_poses[8];
    for (std::size_t k = 0; k < n; ++k) {
      // Hypotheses from the face and the wings of one dock converge to the same pose: refine each dock once.
      bool duplicate = false;
      for (std::size_t q = 0; q < done; ++q) {
        duplicate = duplicate || near_pose(hyps_[k].pose, verified_poses[q], R(0.03), R(0.1));
      }
      if (duplicate) continue;
      Refined r = refine(hyps_[k].pose, true, verified_poses, done);
      if (r.duplicate) continue;
      decide(r, hint != nullptr ? &hint_lidar : nullptr);
      consider(r, false);
      if (r.ok && done < 8) verified_poses[done++] = r.pose;
    }
    if (n == 0 && !best.ok && !have_refused) {
      est.status = EstimateStatus::kNoCandidates;
      return est;
    }
  }
  if (!best.ok) {
    est.status = EstimateStatus::kNotVerified;
    if (have_refused) {
      report(best_refused, &est);
      est.reject = best_refused.reject;
      est.refused_pose = lidar_mount.compose(best_refused.pose);
    }
    return est;
  }
  // Covariance in the lidar frame: residual variance times the inverse normal matrix.
  const Real sigma = best.rms_m > params_.range_sigma_m ? best.rms_m : params_.range_sigma_m;
  Mat3 h_inv = Mat3::Constant(std::numeric_limits<Real>::infinity());
  invert_sym3(best.h, &h_inv);
  const Mat3 cov_lidar = sigma * sigma * h_inv;
  const Mat3 rot = axis_rotation(2, lidar_mount.yaw_rad);
  est.covariance = rot * cov_lidar * rot.transpose();
  if (!est.covariance.allFinite() || std::sqrt(est.covariance(0, 0) + est.covariance(1, 1)) > params_.max_sigma_m) {
    ++counters_.rejected;
    ++counters_.rejected_by[static_cast<std::size_t>(RejectReason::kUncertain)];
    est.status = EstimateStatus::kNotVerified;
    est.evidence = best.evidence;
    est.reject = RejectReason::kUncertain;
    return est;
  }
  est.found = true;
  est.status = EstimateStatus::kOk;
  est.pose = lidar_mount.compose(best.pose);
  est.rms_m = best.rms_m;
  est.shape_rms_m = best.shape_rms_m;
  report(best, &est);
  est.iterations = best.iterations;
  est.from_hint = best_from_hint;
  ++counters_.found;
  return est;
}

}  // namespace dockcore
