#pragma once
/// @file Reading a dock's reflector stripes at a known pose: which stretches of its outline return bright beams. Used
/// to record a dock's code (dockd's teach, docs/docks.md "Reflectors"), where the dock's pose is known from the
/// geometry and its stripes are not.
///
/// The profile is placed at the dock's pose in the lidar frame (PlacedProfile) and every beam of the dock's angular
/// span is ray-cast against it, as the estimator's verification does. A beam whose range lies within the inlier gate
/// of the expected one is an inlier on the segment it hits, at the distance along that segment where the expected
/// hit lies (the pose, not the beam's noisy range, fixes it). Per segment, in scan order, the inlier beams form a
/// sequence (beams off the gate, such as mixed pixels or dropouts, are skipped; a beam that misses the dock or hits
/// another segment ends it), and each run of two or more consecutive bright beams (intensity >= min_intensity) in it
/// is a stripe. Its edges lie half-way between the last dark and the first bright beam; a run that reaches the end of
/// its sequence is extended by half the beam spacing there, and to the segment's end when that lies within one beam
/// spacing. Stripes are clamped to their segment; those shorter than kMinStripeM are dropped.
///
/// No heap, no exceptions, deterministic. Cost O(W · S) for the W beams of the dock's span and S profile segments,
/// plus one sin/cos pair per beam of the span.

#include <cstddef>
#include <cstdint>

#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/dock_profile.hpp"

namespace dockcore {

/// Shortest stripe reported, metres (add_reflector's floor too).
constexpr Real kMinStripeM = static_cast<Real>(0.01);

/// Why a read gave no stripes (or kOk: the stripes found, possibly none).
enum class StripeReadStatus : std::uint8_t {
  kOk = 0,
  kNoIntensity,     ///< The scan carries no intensities, or every inlier beam on the dock reads the same value.
  kTooFewBeams,     ///< Fewer than min_inlier_beams inlier beams on the dock (or a malformed scan or profile).
  kTooManyStripes,  ///< More than kMaxReflectors bright runs: not a stripe pattern (no stripes reported).
};

/// "ok", "no_intensity", "too_few_beams", "too_many_stripes". Never null.
const char* to_string(StripeReadStatus s);

/// The read's thresholds.
struct StripeReadParams {
  Real inlier_gate_m = static_cast<Real>(0.03);  ///< |measured - expected range| at most this: an inlier. > 0.
  /// A beam at least this bright (the lidar's own units, LD06 0-255) is on tape (the estimator's
  /// reflector_min_intensity).
  Real min_intensity = static_cast<Real>(235);
  Real min_range_m = static_cast<Real>(0.05);  ///< Closer returns are ignored (the lidar's blind zone).
  std::uint16_t min_inlier_beams = 10;         ///< Fewer inlier beams on the dock: kTooFewBeams.
};

/// The stripes read, in order along the outline (segment, then from_m), each as add_reflector takes it.
struct StripeRead {
  StripeReadStatus status = StripeReadStatus::kTooFewBeams;
  ReflectorStripe stripes[kMaxReflectors] = {};
  std::size_t count = 0;           ///< Stripes in `stripes`; 0 unless status is kOk.
  std::uint16_t inlier_beams = 0;  ///< Beams within the inlier gate of the dock.
  std::uint16_t bright_beams = 0;  ///< Of those, at least min_intensity.
};

/// Reads the stripes of `profile` (its geometry; its own reflectors are ignored) placed at `dock_in_robot` in
/// `scan`, taken by a lidar at `lidar_mount` (both in the robot frame). Cost: see the file comment.
StripeRead read_reflector_stripes(const ScanView& scan, const Pose2& lidar_mount, const DockProfile& profile,
                                  const Pose2& dock_in_robot, const StripeReadParams& params);

/// Whether two stripe patterns are the same code: as many stripes, each on the same segment with both ends within
/// `tolerance_m` of the other's (both lists in outline order, as read_reflector_stripes and add_reflector keep
/// them). O(count).
bool same_stripes(const ReflectorStripe* a, std::size_t a_count, const ReflectorStripe* b, std::size_t b_count,
                  Real tolerance_m);

}  // namespace dockcore
