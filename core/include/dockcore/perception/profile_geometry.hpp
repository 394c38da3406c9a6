#pragma once
/// @file Geometry of a dock profile placed in a sensor frame: transformed vertices, visibility, ray casting and the
/// angular span the dock covers. Shared by the pose estimator (association, verification) and the benchmarks (CRLB).

#include <cstddef>

#include "dockcore/geometry.hpp"
#include "dockcore/perception/dock_profile.hpp"

namespace dockcore {

/// A profile placed at a pose in a sensor frame, with per-segment data precomputed for cheap queries.
struct PlacedProfile {
  Vec2 v_m[kMaxProfileVertices];       ///< Vertices in the sensor frame.
  Vec2 n[kMaxProfileVertices];         ///< Outward unit normal of segment i (i < segments).
  Real c_m[kMaxProfileVertices] = {};     ///< Line offset: n[i]·x = c_m[i] on segment i.
  bool visible[kMaxProfileVertices] = {}; ///< Segment faces the sensor origin (its outward side contains the origin).
  Vec2 d_m[kMaxProfileVertices];       ///< Segment i as a vector: v_m[i + 1] - v_m[i].
  Vec2 u[kMaxProfileVertices];         ///< Unit direction of segment i.
  Real len_m[kMaxProfileVertices] = {};   ///< Length of segment i.
  Real inv_len_sq[kMaxProfileVertices] = {};///< 1 / len_m[i]² (the per-query divisions become products).
  std::size_t segments = 0;
  Vec2 x_axis{1, 0};  ///< The dock's x axis in the sensor frame: (cos yaw, sin yaw) of the pose it was placed at.

  /// Places `profile` at `dock_in_sensor`. Cost O(vertices): one sin/cos pair.
  void place(const DockProfile& profile, const Pose2& dock_in_sensor);

  /// First visible segment hit by the ray from the sensor origin along unit `dir`. Returns false when none is hit;
  /// otherwise writes the range and the segment index. Cost O(segments): a side test per vertex, one division per
  /// segment the ray crosses.
  bool raycast(const Vec2& dir, Real* range_m, std::size_t* segment) const;

  /// Nearest visible segment to point p (clamped to the segment's ends). Returns false when no segment is visible;
  /// otherwise writes the index, the Euclidean distance, the signed distance to the segment's line (positive on
  /// the outward side) and the overhang: how far p's projection lies beyond the segment's nearer end (0 inside).
  /// Cost O(segments), no division or square root per segment.
  bool nearest(const Vec2& p, std::size_t* segment, Real* distance_m, Real* signed_line_distance_m,
               Real* overhang_m) const;

  /// Distance along segment i from its first vertex to p's projection onto its line, metres (negative before the
  /// first vertex, beyond len_m[i] past the second). Precondition: i < segments. O(1).
  Real along_m(std::size_t i, const Vec2& p) const { return (p - v_m[i]).dot(u[i]); }

  /// Bounding box of the vertices: a point further than d outside [lo_m, hi_m] is further than d from every
  /// segment. Cost O(vertices).
  void bounding_box(Vec2* lo_m, Vec2* hi_m) const;

  /// Angular interval [lo, hi] (lo may be < -pi, hi may exceed pi; hi - lo < 2pi) in which the profile's vertices lie
  /// as seen from the sensor origin, relative to no wrap: centre + half widths. Cost O(vertices) atan2 calls.
  void angular_span(Real* lo_rad, Real* hi_rad) const;

  /// True when p lies within max_line_m of segment i's line and projects inside the segment at least twice its
  /// line distance away from either end. Then a segment joining segment i with a turn of at most 120° cannot be
  /// nearer to p, and neither can any other segment whose distance from segment i is at least 2·max_line_m.
  /// Writes p's signed distance to the line (positive on the outward side) either way. Precondition: i < segments.
  /// O(1), no division or square root.
  bool projects_well_inside(const Vec2& p, std::size_t i, Real max_line_m, Real* signed_line_distance_m) const {
    const Vec2 w = p - v_m[i];
    const Real along_m = w.dot(u[i]);
    const Real e = n[i].dot(p) - c_m[i];
    *signed_line_distance_m = e;
    const Real abs_e = std::fabs(e);
    const Real clear_m = 2 * abs_e;
    return abs_e < max_line_m && along_m >= clear_m && len_m[i] - along_m >= clear_m;
  }
};

}  // namespace dockcore
