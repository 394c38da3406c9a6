#pragma once
/// @file Line segments from a 2D scan: range-gap clustering, split-and-merge, total-least-squares refinement.
///
/// Pipeline (all in one call, bounded cost, no heap):
///  1. Clusters: consecutive points (scan order) are split where their distance exceeds max(cluster_abs_gap_m,
///     cluster_gap_k * range * angular step + cluster_noise_margin_m) or more than cluster_max_missing_beams samples are
///     missing between them. On a full-turn scan the last and first points are neighbours; the processing start is
///     rotated to a gap so a cluster that straddles index 0 comes out whole.
///  2. Split (iterative end-point fit) inside each cluster, driven by an explicit fixed-capacity stack (no recursion):
///     a range is split at the point farthest from its end-to-end chord while that distance exceeds split_threshold_m.
///  3. Each resulting range is refit by total least squares (orthogonal regression, closed-form 2x2 eigen solution).
///  4. Adjacent pieces of the same cluster that one line fits within noise (combined-fit RMS) are merged.
///
/// Used by the V-marker detector and as generic features by the dock pose estimator; nothing here is dock-specific.

#include <cstddef>
#include <cstdint>

#include "dockcore/fixed_vector.hpp"
#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"

namespace dockcore {

/// Most segments one call returns. A room seen by a 0.8° lidar gives 20-60; 256 leaves room for 0.1° lidars.
constexpr std::size_t kMaxLineSegments = 256;

/// Depth of the split stack. With the left-first order used here the stack holds one pending right-hand range per
/// nesting level; real contours nest < 20 deep, 64 leaves a wide margin (512 bytes). A full stack leaves the range
/// unsplit and is counted (SegmentStats::unsplit_ranges).
constexpr std::size_t kSegmentSplitStackDepth = 64;

/// One straight piece of a scan contour, fitted by total least squares to points[first..last] (scan order).
struct LineSegment {
  Vec2 start_m = Vec2::Zero();   ///< Projection of the first point onto the fitted line (frame of the points).
  Vec2 end_m = Vec2::Zero();     ///< Projection of the last point onto the fitted line.
  Vec2 normal = Vec2::Zero();    ///< Unit normal facing the side the points were seen from (towards the sensor),
                                 ///< derived from scan order, so it matches DockProfile's "outward" convention.
  Real offset_m = 0;             ///< Line: normal · p = offset_m. Negative when the sensor sits at the frame origin.
  Real rms_m = 0;                ///< RMS orthogonal distance of the points to the fitted line.
  std::uint32_t first = 0;       ///< Index into the point set of the first point. When the segment straddles index 0
                                 ///< of a wrapping scan, first > last and the points are first..n-1, 0..last.
  std::uint32_t last = 0;        ///< Index into the point set of the last point (inclusive).
  std::uint32_t point_count = 0; ///< Points used in the fit (skipped spikes between merged pieces excluded).
                                 ///< Neighbours are disjoint (corner refinement puts the boundary where the fits
                                 ///< are best) except when a side would have fewer than min_points: then they share
                                 ///< the corner sample.
  std::uint32_t cluster = 0;     ///< Cluster ordinal (0, 1, ... in output order); segments of one cluster are
                                 ///< contiguous in the scan with no range gap between them.

  /// Length start -> end in metres. O(1).
  Real length_m() const { return (end_m - start_m).norm(); }
  /// Unit direction start -> end (scan order); zero for a zero-length segment. O(1).
  Vec2 direction() const {
    const Vec2 d = end_m - start_m;
    const Real n = d.norm();
    return n > 0 ? Vec2(d / n) : Vec2(Vec2::Zero());
  }
  /// Signed orthogonal distance of p from the line, positive on the normal's (sensor's) side. O(1).
  Real signed_distance_m(const Vec2& p) const { return normal.dot(p) - offset_m; }
  /// Midpoint of start and end. O(1).
  Vec2 midpoint_m() const { return (start_m + end_m) * static_cast<Real>(0.5); }
};

/// Segments of a scan, any capacity (what the algorithms take).
using LineSegmentBuffer = FixedVectorBase<LineSegment>;
using LineSegments = FixedVector<LineSegment, kMaxLineSegments>;

/// Thresholds for extract_line_segments. Defaults suit an LD06-class lidar (0.8° steps, range noise σ ≈ 10 mm)
/// looking at objects 0.1-6 m away.
struct SegmentParams {
  /// Floor of the cluster-break distance. 0.05 m = 5σ: noise alone never breaks a cluster, a 5 cm depth step does.
  Real cluster_abs_gap_m = static_cast<Real>(0.05);
  /// Range-proportional term: neighbours on one surface are range·Δθ/cos(incidence) apart, so k = 5 keeps a surface
  /// whole up to ~78° incidence (an 0.212 m V arm at 75° incidence, 1.5 m away, still clusters with its apex).
  Real cluster_gap_k = 5;
  /// Added to the range-proportional term: range noise changes the distance between neighbours by up to ~3σ·√2, so
  /// a surface sampled exactly at the k·r·Δθ limit would otherwise break on noise. 0.03 m ≈ 2σ·√2 for LD06 (σ 10 mm).
  /// The break distance is max(cluster_abs_gap_m, cluster_gap_k · r · Δθ + cluster_noise_margin_m).
  Real cluster_noise_margin_m = static_cast<Real>(0.03);
  /// Missing (invalid / filtered) samples tolerated inside a cluster. A real surface loses the odd return (dark
  /// spots, dropouts); more than 2 in a row usually means an edge.
  std::uint32_t cluster_max_missing_beams = 2;
  /// Split a range while some point is farther than this from its chord. 0.03 m = 3σ of LD06 noise: a straight
  /// wall of ~100 points is rarely split by noise, and corners whose sides are longer than ~6 cm are found.
  Real split_threshold_m = static_cast<Real>(0.03);
  /// After a split, the boundary between the two sides may move this many samples either way to where the two line
  /// fits leave the least squared residual (the split sample is only the one farthest from a chord; with noise it is
  /// often the true corner's neighbour, and one foreign sample tilts a 0.2 m side by degrees). O(1) per step.
  std::uint32_t corner_refine_points = 2;
  /// Fewest points a segment may have. 3: at 0.8° a 0.2 m surface at 1.5 m and 75° incidence only gets 3 returns;
  /// consumers that need more weight should filter on point_count / rms_m.
  std::uint32_t min_points = 3;
  /// Shortest segment kept (after merging). Shorter pieces are usually noise around corners or mixed pixels.
  Real min_length_m = static_cast<Real>(0.04);
  /// Merge two adjacent pieces of a cluster when one line fits both with an RMS of at most this (1.5σ). This is the
  /// collinearity test: a corner between two 0.2 m pieces bent by more than ~17° (1 m pieces: ~3.5°) exceeds it.
  /// There is deliberately no angle test: the short pieces that noise spikes cut out of a wall point anywhere.
  Real merge_max_rms_m = static_cast<Real>(0.015);
  /// Pieces may merge across this many skipped points (pieces too small to keep): a single noise spike or a mixed
  /// pixel splits a wall into two pieces and two 2-point crumbs; the merged fit leaves the skipped points out.
  std::uint32_t merge_max_skipped_points = 2;
  /// Clusters processed per call; later clusters are dropped and counted. Bounds nothing the point count does not,
  /// but lets a caller cap work on cluttered scans.
  std::uint32_t max_clusters = 1024;
  /// Total range evaluations (stack pops) of the split step per call; once spent, remaining ranges are fitted
  /// unsplit and counted. Bounds the split cost to max_split_iterations · (longest cluster).
  std::uint32_t max_split_iterations = 2048;
};

/// What extract_line_segments did, and where a cap truncated its output.
struct SegmentStats {
  std::uint32_t clusters = 0;            ///< Clusters formed (including ones too small to give a segment).
  std::uint32_t clusters_dropped = 0;    ///< Clusters beyond params.max_clusters, not processed.
  std::uint32_t split_iterations = 0;    ///< Ranges evaluated by the split step.
  std::uint32_t unsplit_ranges = 0;      ///< Ranges left unsplit because the iteration cap or the stack was full.
  std::uint32_t segments_dropped = 0;    ///< Segments lost because the output was full (kMaxLineSegments).
  std::uint32_t rejected_short = 0;      ///< Pieces dropped by min_points / min_length_m (not an error).
  bool wrapped = false;                  ///< The first and last points were joined across index 0.
  /// True when a cap cut work or output short (the result is still valid but may be incomplete). O(1).
  bool truncated() const { return clusters_dropped != 0 || unsplit_ranges != 0 || segments_dropped != 0; }
};

/// Extracts line segments from `points` (scan order, as written by scan_to_points; range_m and angle_rad must be
/// filled, p_m may be in any frame). `angle_increment_rad` is the scan's step (either sign); `wraps` says whether the
/// scan covers a full turn (ScanView::wraps()), so the last and first points may be neighbours.
/// Output: `out` is cleared, then filled in circular scan order — consecutive segments are consecutive in the scan;
/// on a wrapping scan the list starts at the first cluster after a gap. Never fails; caps are reported in the result.
/// A contour with no gap at all (a full turn inside a closed room) is first cut at its widest step, then processed
/// again cut at the first corner found, so no wall is split by the cut; that case costs two passes.
/// Cost: O(n) clustering + O(n · d) splitting (d = split nesting depth, ~log(segments) for real contours, at most
/// max_split_iterations pops in all) + O(n) fitting and merging; ×2 for a closed contour. Stack use ~1 KB besides
/// `out`.
SegmentStats extract_line_segments(const ScanPointBuffer& points, Real angle_increment_rad, bool wraps,
                                   const SegmentParams& params, LineSegmentBuffer& out);

/// Convenience: takes the step and the wrap flag from the scan the points were made from. Same contract and cost.
inline SegmentStats extract_line_segments(const ScanPointBuffer& points, const ScanView& scan,
                                          const SegmentParams& params, LineSegmentBuffer& out) {
  return extract_line_segments(points, scan.angle_increment_rad, scan.wraps(), params, out);
}

/// Result of a total-least-squares line fit.
struct LineFit {
  Vec2 centroid_m = Vec2::Zero();  ///< Mean of the points.
  Vec2 direction = Vec2::Zero();   ///< Unit direction of the line (sign arbitrary).
  Real rms_m = 0;                  ///< RMS orthogonal distance of the points to the line.
  std::uint32_t count = 0;         ///< Points fitted.
};

/// Total-least-squares (orthogonal regression) fit to `count` points. Returns false (fit untouched) when count < 2 or
/// the points coincide. O(count), two passes (centred moments, so float Real stays accurate far from the origin).
bool fit_line_tls(const Vec2* points_m, std::size_t count, LineFit& fit);

}  // namespace dockcore
