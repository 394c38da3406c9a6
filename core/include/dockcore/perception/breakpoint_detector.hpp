#pragma once
/// @file Breakpoint ("突变点") dock detector, faithful to seed 000: a dock whose face carries range steps of a known
/// height is found as a pattern of range jumps between neighbouring beams inside an angular window.
///
/// Pipeline per scan (seed 000, steps 1-4 of its text and of its ROS callback):
///  1. window: copy the beams whose angle lies in [window_min_rad, window_max_rad] into a working buffer
///     (contiguously across index count-1 -> 0 when the scan is a full turn);
///  2. filter: a range that is not a return (0, NaN, inf, < 0) or exceeds max_range_m becomes 0;
///  3. gap completion: one or two 0 samples between two valid neighbours that agree within gap_fill_max_diff_m
///     take the neighbours' mean;
///  4. mutation marking and pattern search, in one of two variants:
///     - kSeedCode (default), the author's C++: mark i when min_jump_m < |r[i] - r[i+1]| < max_jump_m, then slide a
///       window of four consecutive marks m0 < m1 < m2 < m3 until they satisfy the seed's four rules;
///     - kPaperSigned, the paper's equations (5-6)..(5-9): rd_i = +1 / -1 for a rise / fall of r[i] - r[i-1] within
///       [signed_min_jump_m, signed_max_jump_m], then a cluster of 3..5 non-zero marks gives the interval [m, n].
///
/// Everything is sized at compile time: the working buffers (kMaxScanPoints entries each, about 37 KB with double)
/// live inside the detector, so keep the detector static or a member, not on a small stack.

#include <cstddef>
#include <cstdint>

#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"

namespace dockcore {

/// Which marking / pattern rule the detector applies after filtering and gap completion.
enum class BreakpointVariant : std::uint8_t {
  kSeedCode = 0,  ///< The seed author's C++ (unsigned jump band, four-point rules). The default.
  kPaperSigned,   ///< The paper's signed marks rd in {-1, 0, +1} and the 3..5-marks interval (equations 5-6..5-9).
};

/// Thresholds of the detector. Defaults are the seed's values; the origin of each is given. Index-valued thresholds
/// count beams and were tuned by the seed for a 1° lidar (360 beams per turn); scale them for other resolutions.
struct BreakpointParams {
  /// Window start, radians in the scan frame (inclusive). Seed: MIN_RANGES_INDEX (value not published); default -90°,
  /// i.e. the half-plane in front of the lidar.
  Real window_min_rad = -kPi / 2;
  /// Window end, radians in the scan frame (inclusive; the seed's upper bound MAX_RANGES_INDEX is exclusive as an
  /// index, this bound is an angle). Must be >= window_min_rad and at most a full turn wider. Default +90°.
  Real window_max_rad = kPi / 2;
  /// Step 1 (text eq. 5-2 and code MAX_RANGES_FROM_CHANGE): ranges beyond this are set to 0. Seed: 2.1 m, the
  /// "near docking" radius.
  Real max_range_m = static_cast<Real>(2.1);
  /// Step 2: gap completion needs the valid neighbours to differ by less than this (strict). Seed code: 0.02 m; the
  /// seed text (eq. 5-3) says 0.01 m. <= 0 disables gap completion.
  Real gap_fill_max_diff_m = static_cast<Real>(0.02);

  /// Which rule set runs after step 2.
  BreakpointVariant variant = BreakpointVariant::kSeedCode;

  // --- kSeedCode (the seed's C++) ---
  /// Step 3: a jump |r[i] - r[i+1]| marks i when strictly greater than this. Seed code: 0.025 m.
  Real min_jump_m = static_cast<Real>(0.025);
  /// Step 3: ... and strictly less than this. Seed code: 0.065 m (the dock's steps are 0.06 m).
  Real max_jump_m = static_cast<Real>(0.065);
  /// Step 4 "neighbour" rule: r[m0] < r[m0 - k] and r[m3] < r[m3 + k] with k = this. Seed code: 5 beams.
  /// A candidate whose neighbour index falls outside the window is rejected (the seed reads out of bounds there).
  std::uint16_t neighbour_offset_idx = 5;
  /// Step 4 "spacing" rule: m1 - m0 < this and m3 - m2 < this (strict). Seed code: 7 beams.
  std::uint16_t max_pair_spacing_idx = 7;
  /// Step 4 "pair range" rule: |r[m0] - r[m1]| < this and |r[m2] - r[m3]| < this (strict). Seed code: 0.08 m.
  Real max_pair_range_diff_m = static_cast<Real>(0.08);
  /// Added to r[m0] to give the right range: m0 lies on the dock's raised end block, m3 in the slot, and the seed
  /// adds the slot depth so both sides refer to the slot plane. Seed code: 0.06 m ("突变点的厚度0.06m").
  Real right_range_compensation_m = static_cast<Real>(0.06);

  // --- kPaperSigned (the paper's text) ---
  /// Eq. 5-6: rd_i = +1 when signed_min_jump_m <= r[i] - r[i-1] <= signed_max_jump_m, -1 for the mirrored band.
  /// Seed text: 0.01 m.
  Real signed_min_jump_m = static_cast<Real>(0.01);
  /// Eq. 5-6 upper bound of the band. Seed text: 0.02 m (the paper's marker steps are 0.012 m high).
  Real signed_max_jump_m = static_cast<Real>(0.02);
  /// Eq. 5-7: fewest non-zero marks in the interval. Seed text: 3 (the marker has 5 steps, the middle 3 are reliable).
  std::uint16_t signed_min_count = 3;
  /// Eq. 5-7: most non-zero marks in the interval. Seed text: 5.
  std::uint16_t signed_max_count = 5;
  /// Not in the seed: the text does not bound the interval, so non-zero marks are grouped into clusters whose
  /// consecutive marks are at most this many beams apart; a cluster with count in [min, max] is the interval.
  /// Our default: 10 beams.
  std::uint16_t signed_max_gap_idx = 10;
};

/// Why detect() did or did not find the dock.
enum class BreakpointStatus : std::uint8_t {
  kFound = 0,
  kBadScan,           ///< Null ranges, count 0, non-finite geometry or angle_increment_rad <= 0.
  kBadWindow,         ///< Window bounds non-finite or min > max.
  kEmptyWindow,       ///< The window holds fewer than 2 beams of this scan.
  kTooFewMutations,   ///< Fewer than 4 mutation marks (kSeedCode) / fewer than signed_min_count (kPaperSigned).
  kNoPattern,         ///< Marks exist but no group satisfies the pattern rules.
};

/// Human-readable name of a BreakpointStatus. Never null.
const char* to_string(BreakpointStatus s);

/// One detection. Angles are in the scan (lidar) frame, wrapped to (-pi, pi]; indices are indices of the input scan.
/// "Left" is the higher beam angle (counter-clockwise side), as in the seed. All fields are 0 when !found, except
/// status and mutation_count.
struct BreakpointDetection {
  bool found = false;
  BreakpointStatus status = BreakpointStatus::kNoPattern;
  Real left_angle_rad = 0;    ///< Beam of m3 (kSeedCode) / n (kPaperSigned).
  Real left_range_m = 0;      ///< Filtered, gap-completed range at the left beam.
  Real right_angle_rad = 0;   ///< Beam of m0 (kSeedCode) / m (kPaperSigned).
  Real right_range_m = 0;     ///< Range at the right beam (+ right_range_compensation_m in kSeedCode).
  Real centre_angle_rad = 0;  ///< kSeedCode: beam at round((m0 + m3) / 2). kPaperSigned: (m + n) / 2, unrounded.
  /// Raw scan range at centre_index (not filtered, not gap-completed, as the seed reads msg.ranges). May be 0 / NaN /
  /// inf if that beam had no return: check is_valid_range() before use.
  Real centre_range_m = 0;
  std::uint32_t left_index = 0;    ///< Scan index of the left beam.
  std::uint32_t right_index = 0;   ///< Scan index of the right beam.
  std::uint32_t centre_index = 0;  ///< Scan index of round((right + left) / 2), counted along the window.
  /// kSeedCode: scan indices of m0..m3. kPaperSigned: [0] = m, [1] = the second mark, [2] = the second-to-last
  /// mark, [3] = n.
  std::uint32_t mutation_index[4] = {0, 0, 0, 0};
  std::uint16_t mutation_count = 0;  ///< Non-zero marks in the window this scan (seed: mutation_point_num).

  /// The dock's position in the lidar frame: centre_range_m * (cos, sin)(centre_angle_rad). The seed estimates no
  /// yaw, so none is given. Returns false (out untouched) when !found or centre_range_m is not a valid return. O(1).
  bool dock_position_lidar(Vec2& out_m) const;
};

/// Running totals since construction or reset_counters().
struct BreakpointCounters {
  std::uint32_t scans_processed = 0;   ///< detect() calls that got past scan/window validation.
  std::uint32_t gap_filled_points = 0; ///< Samples set by gap completion.
  std::uint32_t mutations_found = 0;   ///< Sum of mutation_count over processed scans.
  std::uint32_t detections = 0;        ///< Scans with found == true.
};

/// The detector. Holds fixed working buffers (kMaxScanPoints ranges + marks); not copyable cheaply, so keep one as a
/// static or a member. Not thread-safe; one detect() at a time.
class BreakpointDetector {
 public:
  /// Uses default parameters (the seed's values).
  BreakpointDetector() = default;
  /// Uses `params` (no validation here; detect() reports kBadWindow for unusable windows).
  explicit BreakpointDetector(const BreakpointParams& params) : params_(params) {}

  /// Replaces the parameters; takes effect on the next detect(). O(1).
  void set_params(const BreakpointParams& params) { params_ = params; }
  const BreakpointParams& params() const { return params_; }

  /// Runs the pipeline on one scan. Preconditions: scan.ranges_m has scan.count entries; angle_increment_rad > 0
  /// (counter-clockwise scans). The window is clipped to the scan unless the scan wraps (ScanView::wraps()), in which
  /// case it is taken modulo the turn; at most kMaxScanPoints beams are used (the window is truncated at its end).
  /// Cost O(W), W = beams in the window (each stage is one or two linear passes; the four-mark search only moves
  /// forward), no iteration caps needed.
  BreakpointDetection detect(const ScanView& scan);

  const BreakpointCounters& counters() const { return counters_; }
  void reset_counters() { counters_ = BreakpointCounters{}; }

  /// Diagnostics of the last detect(): the filtered, gap-completed working ranges (window order, right to left) and
  /// their count. Valid until the next detect(). O(1).
  const Real* working_ranges_m() const { return work_m_; }
  std::size_t working_count() const { return work_count_; }
  /// Scan index of working position j (precondition j < working_count()). O(1).
  std::uint32_t scan_index_of(std::size_t j) const;

 private:
  BreakpointDetection detect_seed_code(const ScanView& scan);
  BreakpointDetection detect_paper_signed(const ScanView& scan);
  /// Fills `d`'s angles/indices from working positions (right, left, centre) and reads the raw centre range.
  void fill_geometry(const ScanView& scan, std::size_t right_pos, std::size_t left_pos, BreakpointDetection& d) const;
  Real angle_of(std::size_t pos) const;

  BreakpointParams params_{};
  BreakpointCounters counters_{};
  Real work_m_[kMaxScanPoints] = {};
  std::int8_t marks_[kMaxScanPoints] = {};
  std::size_t work_count_ = 0;
  // Working position j is scan index (first_k_ + j), taken modulo index_modulus_ (beams per turn) when the scan wraps
  // (index_modulus_ == 0 otherwise); its angle is scan_angle_min_rad_ + (first_k_ + j) * scan_increment_rad_.
  std::int32_t first_k_ = 0;
  std::size_t index_modulus_ = 0;
  Real scan_angle_min_rad_ = 0;
  Real scan_increment_rad_ = 0;
};

}  // namespace dockcore
