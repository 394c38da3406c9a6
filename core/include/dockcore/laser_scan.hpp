#pragma once
/// @file 2D laser scans: a capacity-free view every detector reads, and a sized owner that holds the samples.

#include <cstddef>
#include <cstdint>

#include "dockcore/fixed_vector.hpp"
#include "dockcore/geometry.hpp"

namespace dockcore {

/// Largest scan any owner in core holds: 0.1° lidars give 3600 points per turn.
constexpr std::size_t kMaxScanPoints = 4096;

/// True when a range sample is a real return: finite and > 0. 0, NaN and inf all mean "no return".
inline bool is_valid_range(Real range_m) { return range_m > 0 && std::isfinite(range_m); }

/// Index of the beam nearest `angle_rad` in a scan of `count` beams from `angle_min_rad` every `angle_increment_rad`
/// (> 0). The angle is taken within ±π of the scan's centre, so a partial scan gets the unambiguous index; it may lie
/// outside [0, count) for an angle outside a partial scan (a full turn's caller wraps it). O(1).
inline long nearest_beam_index(Real angle_min_rad, Real angle_increment_rad, std::size_t count, Real angle_rad) {
  const Real half_span = static_cast<Real>(count) * angle_increment_rad * static_cast<Real>(0.5);
  const Real rel = wrap_angle(angle_rad - angle_min_rad - half_span) + half_span;
  return static_cast<long>(std::floor(rel / angle_increment_rad + static_cast<Real>(0.5)));
}

/// Read-only view of one scan. Sample i was taken at angle_min_rad + i * angle_increment_rad in the lidar frame
/// (counter-clockwise, x forward). A range of 0 / NaN / inf is "no return". intensities may be null.
struct ScanView {
  const Real* ranges_m = nullptr;
  const Real* intensities = nullptr;
  std::size_t count = 0;
  Real angle_min_rad = 0;
  Real angle_increment_rad = 0;
  std::uint64_t stamp_us = 0;  ///< Time of the first sample, microseconds on the producer's monotonic clock.

  /// Beam angle of sample i in the lidar frame, not wrapped. O(1).
  Real angle_rad(std::size_t i) const { return angle_min_rad + static_cast<Real>(i) * angle_increment_rad; }
  /// True when the scan covers a full turn, so index 0 and count-1 are angular neighbours. O(1).
  bool wraps() const {
    return count > 1 && std::fabs(static_cast<Real>(count) * angle_increment_rad) >= kTwoPi - angle_increment_rad * static_cast<Real>(0.5);
  }
};

/// Owner of up to N samples. Trivially copyable; ~16 bytes per point of capacity with double.
template <std::size_t N>
struct LaserScanN {
  static constexpr std::size_t kCapacity = N;
  Real ranges_m[N] = {};
  Real intensities[N] = {};
  std::size_t count = 0;
  Real angle_min_rad = 0;
  Real angle_increment_rad = 0;
  std::uint64_t stamp_us = 0;

  ScanView view() const { return ScanView{ranges_m, intensities, count, angle_min_rad, angle_increment_rad, stamp_us}; }
  /// Clears the samples and sets the geometry; returns false (changing nothing) if count_in > N. O(1).
  bool reset(std::size_t count_in, Real angle_min, Real angle_increment, std::uint64_t stamp) {
    if (count_in > N) return false;
    count = count_in;
    angle_min_rad = angle_min;
    angle_increment_rad = angle_increment;
    stamp_us = stamp;
    for (std::size_t i = 0; i < count_in; ++i) ranges_m[i] = intensities[i] = 0;
    return true;
  }
};

using LaserScan = LaserScanN<kMaxScanPoints>;

/// One valid return converted to Cartesian coordinates.
struct ScanPoint {
  Vec2 p_m;                 ///< Position in the target frame (robot frame when a mount pose is given).
  Real range_m = 0;         ///< Raw range as measured.
  Real angle_rad = 0;       ///< Beam angle in the lidar frame.
  std::uint32_t index = 0;  ///< Sample index in the source scan.
};

/// Points of a scan, any capacity (what the algorithms take).
using ScanPointBuffer = FixedVectorBase<ScanPoint>;
/// Points of a scan of up to N beams.
template <std::size_t N>
using ScanPointsN = FixedVector<ScanPoint, N>;
using ScanPoints = ScanPointsN<kMaxScanPoints>;

/// Converts the valid returns with range in [min_range_m, max_range_m] to points in the frame in which
/// `lidar_mount` is expressed (identity mount = lidar frame). Invalid samples are skipped, so out's order is the scan
/// order. Returns the number of points written (<= out capacity; extra points are counted in `*truncated` if given).
/// Cost O(count).
std::size_t scan_to_points(const ScanView& scan, const Pose2& lidar_mount, Real min_range_m, Real max_range_m,
                           ScanPointBuffer& out, std::size_t* truncated = nullptr);

}  // namespace dockcore
