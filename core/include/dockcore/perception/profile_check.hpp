#pragma once
/// @file Checks that a dock profile can be detected and can fix the dock's full pose with a given lidar: its outline
/// does not cross itself, it is wide enough to be sampled by the lidar's beams at the farthest range it is sought
/// at, and its surfaces seen from the front fix x, y and yaw.
///
/// The ambiguity test uses the Fisher information of the pose (x, y, yaw) — rotation about the dock frame's origin,
/// the contacts — from point-to-segment residuals: each beam that hits the profile contributes J·Jᵀ with
/// J = (n_x, n_y, p_x·n_y − p_y·n_x), p the hit point and n the hit segment's outward normal in the dock frame (unit
/// weight per beam, as the estimator's registration weights them). Yaw is scaled by L, the RMS distance of the hit
/// points from the dock origin, so all three components are in metres (a rotation of 1/L rad moves the hits by about
/// 1 m, like a 1 m translation). The beams are cast at the lidar's beam spacing from kProfileCheckViews viewpoints,
/// each kProfileCheckViewRangeM from the dock origin, at bearings 0 and ±kProfileCheckViewBearingRad off the dock's x
/// axis, looking at the origin; the first surface a beam meets is the one it hits (self-occlusion is modelled). The
/// profile is ambiguous when the smallest eigenvalue of the summed, scaled information is below
/// kProfileCheckMinEigenRatio times the largest: along that eigenvector the pose is at least 1/sqrt(ratio) = 10 times
/// less certain than along the best one. The reported component is the eigenvector's largest (scaled) entry: a flat
/// plate cannot fix y, a circular arc about the contacts cannot fix yaw.

#include <cstddef>
#include <cstdint>

#include "dockcore/geometry.hpp"
#include "dockcore/perception/dock_profile.hpp"

namespace dockcore {

/// Why check_profile refused a profile (or kOk).
enum class ProfileCheckReason : std::uint8_t {
  kOk = 0,
  kSelfIntersecting,  ///< Two non-adjacent segments share a point, or two adjacent ones fold back onto each other.
  kTooSmall,          ///< The dock, or every surface fixing one pose component, holds fewer than 3 beams at range.
  kAmbiguous,         ///< The visible surfaces cannot fix one pose component (see the file comment).
  kNotVisible,        ///< No beam from the viewpoints hits the profile (no surface faces the front).
  kBadArguments,      ///< Beam spacing or range not finite and > 0, or the profile has no segment.
};

/// A component of the dock pose.
enum class PoseComponent : std::uint8_t { kNone = 0, kX, kY, kYaw };

/// Human-readable names ("ok", "self-intersecting", ...; "none", "x", "y", "yaw"), for messages. Never null.
const char* to_string(ProfileCheckReason r);
const char* to_string(PoseComponent c);

/// Viewpoints of the ambiguity test (file comment): straight ahead and at ±kProfileCheckViewBearingRad.
constexpr std::size_t kProfileCheckViews = 3;
constexpr Real kProfileCheckViewRangeM = 1;                                           ///< Their distance, metres.
constexpr Real kProfileCheckViewBearingRad = static_cast<Real>(0.52359877559829887);  ///< 30°.
/// Smallest eigenvalue / largest of the scaled Fisher information below which a profile is ambiguous.
constexpr Real kProfileCheckMinEigenRatio = static_cast<Real>(0.01);
/// A width "holds" floor(width / (range · beam spacing)) + 1 beams when seen face-on (the best case: the first beam
/// on its edge); a dock or surface holding fewer than this many beams at max range is too small. Equivalently,
/// too small means narrower than (kProfileCheckMinBeams − 1) beam gaps at max range.
constexpr std::size_t kProfileCheckMinBeams = 3;
/// Consecutive segments meeting at a joint that bends by less than this are one surface (a face drawn as several
/// segments, or a curve drawn as facets, is sampled as a whole); sharper corners separate surfaces. 30°.
constexpr Real kProfileCheckSurfaceJointRad = static_cast<Real>(0.52359877559829887);
/// Most beams cast per viewpoint: with a finer lidar the beams are spread evenly over the dock instead (the
/// eigenvalue ratio does not depend on the beam density, only on where the beams land).
constexpr std::size_t kProfileCheckMaxBeamsPerView = 1024;

/// The verdict, with what was measured. Trivially copyable.
struct ProfileCheck {
  ProfileCheckReason reason = ProfileCheckReason::kOk;
  /// kAmbiguous / kTooSmall of features: the component that is not fixed; kNone otherwise (also for a dock that is
  /// too small as a whole).
  PoseComponent component = PoseComponent::kNone;
  /// kSelfIntersecting: the two segments (indices, first < second).
  std::size_t segment_a = 0;
  std::size_t segment_b = 0;
  /// kTooSmall: the width that was too small (the dock's width across y, or the longest surface that fixes
  /// `component`), and the least width that holds kProfileCheckMinBeams beams at max range, metres.
  Real width_m = 0;
  Real min_width_m = 0;
  /// Smallest / largest eigenvalue of the scaled information of all visible surfaces (kTooSmall of features: of the
  /// surfaces wide enough), and its weakest eigenvector (unit, (x, y, L·yaw)). Filled whenever the test ran.
  Real eigen_ratio = 0;
  Vec3 weak_direction = Vec3::Zero();
  Real lever_m = 0;       ///< L, the yaw scale (file comment).
  std::size_t beams = 0;  ///< Beams that hit the profile over all viewpoints.
};

/// Checks `profile` for a lidar with `beam_spacing_rad` between beams, sought out to `max_range_m`. The checks run
/// in this order and the first failure is returned:
///  1. self-intersection (kSelfIntersecting with the two segments);
///  2. the dock's width across y (DockProfile::width_m) holds fewer than kProfileCheckMinBeams beams at max_range_m
///     (kTooSmall, component kNone);
///  3. no beam from the viewpoints hits the profile (kNotVisible);
///  4. the information of all visible surfaces is ambiguous (kAmbiguous with the component);
///  5. the information of the surfaces wide enough — surfaces (runs of consecutive segments, see
///     kProfileCheckSurfaceJointRad) whose length holds
///     kProfileCheckMinBeams beams at max_range_m — is ambiguous: every surface that fixes `component` is too small
///     to be sampled there (kTooSmall with the component).
/// Cost: O(S²) for 1, then O(kProfileCheckViews · beams · S) with beams ≤ kProfileCheckMaxBeamsPerView, S segments;
/// no heap, deterministic.
ProfileCheck check_profile(const DockProfile& profile, Real beam_spacing_rad, Real max_range_m);

/// Beam spacing of LD06-class lidars (0.8°) and the estimator's default max range (2.5 m): what profile files are
/// checked against.
constexpr Real kProfileCheckDefaultBeamSpacingRad = static_cast<Real>(0.013962634015954637);
constexpr Real kProfileCheckDefaultRangeM = static_cast<Real>(2.5);

}  // namespace dockcore
