#pragma once
/// @file IntensityCheck: whether the lidar's intensity can tell a bright target from a wall (docs/lidars.md,
/// "Intensity check").
///
/// Lidars differ in what their intensity carries: an LD06/LD19 reports 0–255 that follows surface reflectance, range
/// and incidence; an RPLIDAR A1's standard scan reports a 6-bit quality that a real A1 saturates at 15 for almost
/// every return; RPLIDAR express and dense modes report a constant 47; some drivers send none (0). A cue built on
/// intensity would read such a sensor as "no reflector anywhere" or "reflector everywhere", so the sensor is judged
/// at run time, from the scans themselves, and the verdict is reported, never acted on silently.
///
/// Per scan: up to kMaxSamples returns (range finite and > 0, beams taken at an even stride) are read; the scan is
/// *flat* when at least flat_share of them lie within ±flat_band of its most common value (found by a majority vote,
/// exact when that value holds over half the returns, which is all a flat verdict needs), *absent* when every one
/// reads 0 (absent scans are flat too). A scan with fewer than min_returns sampled returns is not judged.
/// Across scans: the last window_scans judged scans vote; the verdict turns kAbsent / kFlat / kUsable once a share of
/// at least decide_share of the window agrees (absent before flat), and otherwise keeps what it was, so a sensor
/// that is flat in some rooms and not in others does not flap. kUnknown until the window is full.
/// No heap; O(min(count, kMaxSamples)) per scan.

#include <cstddef>
#include <cstdint>

#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"

namespace dockcore {

/// What the lidar's intensity is good for.
enum class IntensityVerdict : std::uint8_t {
  kUnknown = 0,  ///< Fewer than window_scans judged scans so far, or no share of the window has agreed yet.
  kUsable,       ///< Intensities vary from return to return: a bright target can stand out.
  kFlat,         ///< Nearly every return reads the same value (saturated or constant): nothing can stand out.
  kAbsent,       ///< Every return reads 0: the sensor or its driver gives no intensity.
};

/// "unknown" / "usable" / "flat" / "absent", as in dockd's status. Never null.
const char* to_string(IntensityVerdict v);

/// The check's thresholds (dockd's and a scenario's [intensity] table).
struct IntensityCheckParams {
  /// A scan is flat when at least this share of its returns lie within ±flat_band of the most common value. (0.5, 1].
  Real flat_share = static_cast<Real>(0.7);
  /// Half-width of "the same value", in the sensor's intensity units (LD06: 0–255, RPLIDAR quality: 0–63). >= 0.
  Real flat_band = static_cast<Real>(1);
  /// Scans with fewer sampled returns than this are not judged. >= 1.
  std::uint16_t min_returns = 20;
  /// Judged scans the verdict looks back on. 1..32.
  std::uint8_t window_scans = 16;
  /// The verdict changes when at least this share of the window agrees. (0.5, 1].
  Real decide_share = static_cast<Real>(0.75);
};

/// One scan's reading.
struct IntensityScan {
  bool judged = false;        ///< Enough returns to judge.
  bool flat = false;          ///< flat_share or more within ±flat_band of `mode` (absent scans are flat).
  bool absent = false;        ///< Every sampled return reads 0.
  std::uint16_t returns = 0;  ///< Sampled returns (range finite and > 0).
  Real mode = 0;              ///< The majority vote's value (the most common one when it holds over half).
  Real share = 0;             ///< Share of the sampled returns within ±flat_band of `mode`, 0..1.
};

class IntensityCheck {
 public:
  /// Returns read per scan at most; longer scans are sampled at an even stride.
  static constexpr std::size_t kMaxSamples = 256;
  /// Longest window (bits of the vote history).
  static constexpr std::uint8_t kMaxWindow = 32;

  /// New thresholds. A different window_scans forgets the vote history (the verdict stays until the new window is
  /// full and agrees). Values out of their documented range are clamped into it (the config readers refuse them
  /// first). O(1).
  void configure(const IntensityCheckParams& p);
  /// Forgets every scan: kUnknown, counters kept. O(1).
  void reset();

  /// Judges one scan and updates the verdict. Returns the scan's reading. O(min(scan.count, kMaxSamples)).
  IntensityScan add(const ScanView& scan);

  IntensityVerdict verdict() const { return verdict_; }
  /// The verdict is kUsable. O(1).
  bool usable() const { return verdict_ == IntensityVerdict::kUsable; }
  /// The last add()'s reading. O(1).
  const IntensityScan& last() const { return last_; }
  const IntensityCheckParams& params() const { return p_; }
  /// Scans given to add(), and those judged, since construction (reset() keeps them). O(1).
  std::uint32_t scans() const { return scans_; }
  std::uint32_t scans_judged() const { return judged_; }
  /// Judged scans that were flat (absent ones included). O(1).
  std::uint32_t scans_flat() const { return flat_scans_; }
  /// Times the verdict changed. O(1).
  std::uint32_t verdict_changes() const { return changes_; }

 private:
  IntensityCheckParams p_{};
  std::uint32_t flat_bits_ = 0;    ///< One bit per judged scan in the window, newest in bit 0: flat.
  std::uint32_t absent_bits_ = 0;  ///< The same: absent.
  std::uint8_t filled_ = 0;        ///< Judged scans in the window.
  IntensityVerdict verdict_ = IntensityVerdict::kUnknown;
  IntensityScan last_{};
  std::uint32_t scans_ = 0;
  std::uint32_t judged_ = 0;
  std::uint32_t flat_scans_ = 0;
  std::uint32_t changes_ = 0;
};

}  // namespace dockcore
