#pragma once
/// @file Geometry of a dock profile placed in a sensor frame: transformed vertices, visibility, ray casting and the
/// angular span the dock covers. Shared by the pose estimator (association, verification) and the benchmarks (CRLB).

#include <cstddef>

#include "dockcore/dock_profile.hpp"
#include "dockcore/geometry.hpp"

namespace dockcore {

/// A profile placed at a pose in a sensor frame, with per-segment data precomputed for cheap queries.
struct PlacedProfile {
  Vec2 v_m[kMaxProfileVertices];       ///< Vertices in the sensor frame.
  Vec2 n[kMaxProfileVertices];         ///< Outward unit normal of segment i (i < segments).
  Real c_m[kMaxProfileVertices];       ///< Line offset: n[i]·x = c_m[i] on segment i.
  bool visible[kMaxProfileVertices];   ///< Segment faces the sensor origin (its outward side contains the origin).
  std::size_t segments = 0;

  /// Places `profile` at `dock_in_sensor`. Cost O(vertices): one sin/cos pair.
  void place(const DockProfile& profile, const Pose2& dock_in_sensor);

  /// First visible segment hit by the ray from the sensor origin along unit `dir`. Returns false when none is hit;
  /// otherwise writes the range and the segment index. Cost O(segments).
  bool raycast(const Vec2& dir, Real* range_m, std::size_t* segment) const;

  /// Nearest visible segment to point p (clamped to the segment's ends). Returns false when no segment is visible;
  /// otherwise writes the index, the Euclidean distance, the signed distance to the segment's line (positive on
  /// the outward side) and the overhang: how far p's projection lies beyond the segment's nearer end (0 inside).
  /// Cost O(segments).
  bool nearest(const Vec2& p, std::size_t* segment, Real* distance_m, Real* signed_line_distance_m,
               Real* overhang_m) const;

  /// Angular interval [lo, hi] (lo may be < -pi, hi may exceed pi; hi - lo < 2pi) in which the profile's vertices lie
  /// as seen from the sensor origin, relative to no wrap: centre + half widths. Cost O(vertices) atan2 calls.
  void angular_span(Real* lo_rad, Real* hi_rad) const;
};

}  // namespace dockcore
