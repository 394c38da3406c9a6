#pragma once
/// @file V-marker detector: finds a concave V (two straight arms meeting at a notch) among scan line segments.
///
/// Seed 004's "triangle label": the dock carries a V-shaped notch whose apex points away from an approaching robot.
/// Seen from the lidar the V is concave: the apex is farther than the arm ends, and each arm's visible face looks
/// towards the other arm. The detector pairs neighbouring segments (from extract_line_segments), intersects their
/// fitted lines to get the apex, checks notch angle, arm lengths (allowing for partial visibility) and how closely the
/// segments meet, and turns apex + bisector into the dock pose through the marker geometry.
///
/// V frame: origin at the apex, +x along the bisector out of the notch (towards the viewer). For a symmetric V this
/// is the dock's +x axis.

#include <cstddef>
#include <cstdint>

#include "dockcore/geometry.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "dockcore/perception/line_segments.hpp"

namespace dockcore {

/// Shape of the V to look for. Defaults are the built-in "v-marker" profile: 90° notch, 0.2121 m arms, dock origin on
/// the mouth line 0.15 m in front of the apex.
struct VMarkerGeometry {
  /// Interior angle between the arms at the apex, (0, pi).
  Real notch_angle_rad = kPi / 2;
  /// Expected arm lengths apex -> mouth. [0]: the arm to the right of the bisector (clockwise side, looking out of the
  /// notch; the dock's -y side for a profile whose vertices run -y -> +y); [1]: the arm to the left.
  Real arm_length_m[2] = {static_cast<Real>(0.21213203435596426), static_cast<Real>(0.21213203435596426)};
  /// The dock frame expressed in the V frame (apex origin, +x out of the notch along the bisector).
  Pose2 dock_in_v{static_cast<Real>(0.15), 0, 0};
};

/// Why a geometry could not be derived or is invalid.
enum class VMarkerError : std::uint8_t {
  kOk = 0,
  kNotThreeVertices,  ///< The profile does not have exactly 3 vertices (mouth end, apex, mouth end).
  kNotConcave,        ///< The outward normals do not face into the notch: the apex points towards the viewer.
  kBadAngle,          ///< Notch angle outside (5°, 175°) or not finite.
  kBadLength,         ///< An arm length is not finite or <= 1 mm.
  kBadParams,         ///< A tolerance is negative / not finite, or min_arm_fraction outside [0, 1].
};

/// Human-readable name of a VMarkerError. Never null.
const char* to_string(VMarkerError e);

/// Derives the V geometry from a 3-vertex dock profile (vertex 1 is the apex; vertices run from the dock's -y side to
/// its +y side, outward normals facing into the notch). On error `out` is untouched. O(1).
VMarkerError vmarker_geometry_from_profile(const DockProfile& profile, VMarkerGeometry& out);

/// A symmetric V: notch angle, equal arms, dock origin `apex_to_origin_m` in front of the apex along the bisector.
/// No validation (configure() validates). O(1).
VMarkerGeometry symmetric_vmarker_geometry(Real notch_angle_rad, Real arm_length_m, Real apex_to_origin_m);

/// Detector thresholds. Defaults suit an LD06-class lidar (0.8°, σ ≈ 10 mm) at 0.3-2 m from the marker.
struct VMarkerParams {
  VMarkerGeometry geometry;
  /// |measured notch angle - expected| must not exceed this. 15°: at 1.5 m an LD06 gives an arm 5-8 points, whose
  /// direction alone has σ ≈ 2-3° (σ 5-10 mm), so the notch angle has σ ≈ 3-4°; 15° keeps misses rare. Angle is a
  /// weak discriminator anyway: room corners are stopped by arm length, box corners by concavity.
  Real angle_tolerance_rad = deg_to_rad(static_cast<Real>(15));
  /// An arm may be at most this much longer than expected (mixed pixels at the mouth and fit noise add length).
  Real arm_length_tolerance_m = static_cast<Real>(0.05);
  /// An arm must show at least this fraction of its expected length (occlusion and grazing incidence shorten it).
  Real min_arm_fraction = static_cast<Real>(0.4);
  /// Each arm's nearest end must lie within max_apex_gap_m + apex_gap_spacing_factor · (that arm's mean sample
  /// spacing, length / (n-1)) of the fitted apex (the lines' intersection). The corner falls between samples, up to
  /// one spacing from an arm seen at grazing incidence, and range noise moves grazing samples along the arm by
  /// σ/cos(incidence) (2 cm at 75°), hence 1.5 spacings. 0.04 m (4σ of LD06 range noise) covers noise and a mixed
  /// pixel at the apex.
  Real max_apex_gap_m = static_cast<Real>(0.04);
  Real apex_gap_spacing_factor = static_cast<Real>(1.5);
  /// Each arm's fit RMS must not exceed this (2.5σ of LD06 noise).
  Real max_arm_rms_m = static_cast<Real>(0.025);
  /// Fewest points per arm.
  std::uint32_t min_arm_points = 3;
  /// Segments paired with each segment: the next `pair_span` segments in scan order (1 = immediate neighbours only;
  /// 2 also bridges one small spurious piece at the apex). Pairing cost is O(segments · pair_span).
  std::uint32_t pair_span = 2;
  /// Bisector estimate. true: each arm's fitted direction, turned by half the *expected* notch angle, is one estimate
  /// of the bisector; the two are averaged weighted by their information (points · length² / rms²), so a short,
  /// occluded or noisy arm counts less. false: the plain bisector of the two measured directions (unbiased if the
  /// real notch angle differs from the expected one, but an occluded arm drags it as much as a clean one).
  bool weight_arms_by_information = true;
  /// Floor on an arm's RMS in the weighting above: a 3-point arm can fit with ~0 RMS by chance, which would give it
  /// all the weight. 3 mm is below LD06 noise at any incidence that gives a usable arm.
  Real weight_rms_floor_m = static_cast<Real>(0.003);
  /// Candidates whose apex is farther than this from the frame origin are ignored. Seed 004 looks within 1.5 m; beyond
  /// ~2 m an LD06 puts 3-4 points on a 0.2 m arm, too few to tell the V from clutter.
  Real max_apex_distance_m = 2;
  /// Candidates scoring below this are ignored. 0.3 drops Vs made of two barely-half-visible, ragged arms (clutter
  /// such as table legs against a box) while a clean V with one half-occluded arm still scores ~0.6.
  Real min_score = static_cast<Real>(0.3);
  /// With a pose hint, candidates whose dock origin is farther than this from the hint are ignored.
  Real hint_gate_m = static_cast<Real>(0.5);
};

/// Outcome of a detection.
enum class VMarkerStatus : std::uint8_t {
  kFound = 0,
  kNoSegments,     ///< Fewer than 2 segments given.
  kNoCandidate,    ///< No segment pair passed the checks.
  kNoneNearHint,   ///< Candidates exist but none within hint_gate_m of the hint.
  kBadParams,      ///< The detector was configured with invalid parameters.
};

/// Human-readable name of a VMarkerStatus. Never null.
const char* to_string(VMarkerStatus s);

/// What a detection found. All positions are in the frame of the segments (lidar or robot frame).
struct VMarkerDetection {
  bool found = false;
  VMarkerStatus status = VMarkerStatus::kNoCandidate;
  Vec2 apex_m = Vec2::Zero();       ///< Intersection of the two fitted arm lines.
  Real bisector_yaw_rad = 0;        ///< Direction out of the notch (towards the viewer): the V frame's +x
                                    ///< (see VMarkerParams::weight_arms_by_information).
  Pose2 dock_pose;                  ///< Dock frame in the segments' frame: V pose ∘ geometry.dock_in_v.
  Real notch_angle_rad = 0;         ///< Measured interior angle.
  Real arm_length_m[2] = {0, 0};    ///< Visible arm lengths apex -> far end, [0] right arm, [1] left arm.
  Real arm_rms_m[2] = {0, 0};       ///< Fit RMS of the arms, same order.
  Real score = 0;                   ///< In (0, 1], higher is better; see VMarkerDetector::detect.
  std::uint32_t segment_index[2] = {0, 0};  ///< Indices into the segment list of the right and left arms.
  std::uint32_t candidates = 0;     ///< Pairs that passed every check (before the hint gate).
};

/// Finds the dock's V among line segments. Stateless between calls; holds only its parameters (~100 bytes).
class VMarkerDetector {
 public:
  /// Detector for the built-in "v-marker" with default tolerances.
  VMarkerDetector() = default;
  /// Detector with `params`; check error() for validity.
  explicit VMarkerDetector(const VMarkerParams& params) { configure(params); }

  /// Validates and adopts `params`. On error the previous parameters stay and detect() reports kBadParams. O(1).
  VMarkerError configure(const VMarkerParams& params);
  /// Result of the last configure() (kOk for the default constructor).
  VMarkerError error() const { return error_; }
  const VMarkerParams& params() const { return params_; }

  /// Searches `segments` (scan order, as from extract_line_segments) for the V. Every pair (i, i+1..i+pair_span)
  /// (circularly) is tested: lines not near-parallel; concave (each arm's normal faces the other arm); notch angle
  /// within tolerance; nearest ends within max_apex_gap_m (+ sample spacing) of the lines' intersection; each arm between
  /// min_arm_fraction·expected and expected + arm_length_tolerance_m long, with enough points and small RMS.
  /// Score of a candidate = visibility · (1 - (e_angle + e_gap + e_rms) / 3), where visibility is the mean visible
  /// fraction of the two arms (capped at 1) and each e is the error divided by its tolerance (in [0, 1]).
  /// Choice: without a hint, the highest score; with `hint` (expected dock pose in the same frame), the candidate whose
  /// dock origin is nearest the hint among those within hint_gate_m (ties by score). Deterministic: ties keep the
  /// earliest pair. Cost O(segments · pair_span), no allocation.
  VMarkerDetection detect(const LineSegmentBuffer& segments, const Pose2* hint = nullptr) const;
  /// Same, over a plain array of `count` segments.
  VMarkerDetection detect(const LineSegment* segments, std::size_t count, const Pose2* hint = nullptr) const;

 private:
  VMarkerParams params_;
  VMarkerError error_ = VMarkerError::kOk;
};

}  // namespace dockcore
