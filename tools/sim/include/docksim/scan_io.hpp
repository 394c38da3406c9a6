#pragma once
// Recorded scans as JSON lines, one scan per line:
//   {"stamp_us":123,"angle_min_rad":-3.14159,"angle_increment_rad":0.0139626,"ranges_m":[1.2,0,...],
//    "intensities":[200,0,...]}
// A range of 0 or null means "no return"; "intensities" is optional (absent, null or [] = none; otherwise one per
// range, null read as 0). Unknown keys are ignored so recorders may add fields. Blank lines are skipped.
// Host-side; reading never throws and never crashes on garbage: every problem is an error message with the line.
#include <cstddef>
#include <cstdint>
#include <istream>
#include <ostream>
#include <string>
#include <vector>

#include "dockcore/laser_scan.hpp"

namespace docksim {

/// One recorded scan, host-side (sized by its data, unlike dockcore::LaserScan).
struct RecordedScan {
  std::uint64_t stamp_us = 0;
  double angle_min_rad = 0;
  double angle_increment_rad = 0;
  std::vector<double> ranges_m;     ///< 0 = no return (null in the file reads as 0).
  std::vector<double> intensities;  ///< Empty, or one per range.

  /// Copies into a core scan (count <= kMaxScanPoints is guaranteed by the reader). Intensities are 0 when absent.
  /// Returns false (out untouched) if there are more than kMaxScanPoints ranges.
  bool to_laser_scan(dockcore::LaserScan* out) const;
  /// Copies a core scan view (intensities copied only if the view has them).
  static RecordedScan from_view(const dockcore::ScanView& v);
};

/// Longest line the reader accepts (bytes): 4096 points at ~25 characters each with room to spare.
constexpr std::size_t kMaxScanLineBytes = 1u << 20;

/// Parses one line. On failure returns false, leaves *out unspecified and puts a message (without line number) in
/// *error. Errors: not JSON, not an object, nesting deeper than 4, missing/ill-typed stamp_us (a non-negative
/// integer), angle_min_rad / angle_increment_rad (finite numbers; increment != 0 when there are >= 2 ranges),
/// ranges_m (array of numbers or null, each >= 0), more than dockcore::kMaxScanPoints ranges, intensities of a
/// different length or with non-numbers, line longer than kMaxScanLineBytes.
bool parse_scan_line(const std::string& line, RecordedScan* out, std::string* error);

/// Formats one scan as a compact JSON line (no trailing newline): angles with 17 significant digits (exact round
/// trip), ranges and intensities with 6 significant digits (%.6g: 0.1 mm at 10 m), non-finite or negative ranges
/// written as 0 (no return). Intensities are written only if non-empty.
std::string format_scan_line(const RecordedScan& scan);
/// Same from a core scan view; intensities written when the view has them.
std::string format_scan_line(const dockcore::ScanView& scan);

/// Streaming reader for large recordings.
class ScanReader {
 public:
  explicit ScanReader(std::istream& in) : in_(in) {}
  enum class Status { kScan, kEnd, kError };
  /// Next scan. kError: *error = "line N: <what>"; the reader can continue with the following line.
  Status next(RecordedScan* out, std::string* error);
  /// 1-based number of the last line read.
  std::size_t line_number() const { return line_; }

 private:
  std::istream& in_;
  std::size_t line_ = 0;
};

/// Reads every scan; stops at the first bad line with *error = "line N: <what>" (scans before it are in *out).
bool read_scans(std::istream& in, std::vector<RecordedScan>* out, std::string* error);

/// What read_scans_skipping_bad read and what it skipped.
struct ScanReadSummary {
  std::size_t lines = 0;    ///< Lines read, blank ones included.
  std::size_t scans = 0;    ///< Scans appended to the output.
  std::size_t skipped = 0;  ///< Malformed lines skipped (every one counted).
  /// "line N: <what>" of the first kMaxReportedScanErrors skipped lines, in file order.
  std::vector<std::string> errors;
};

/// Skipped lines whose message ScanReadSummary keeps (the count goes on beyond).
constexpr std::size_t kMaxReportedScanErrors = 20;

/// Reads the scans of a recording that may hold bad lines: a malformed line (every parse_scan_line error: wrong
/// number of intensities, non-finite or missing angles, zero increment, ...) is skipped, counted and reported with
/// its line number; every other line is read exactly as read_scans would. Stops after `max_scans` scans (0: all).
/// Returns false only when the stream itself fails (*summary then holds what was read so far). O(bytes).
bool read_scans_skipping_bad(std::istream& in, std::vector<RecordedScan>* out, ScanReadSummary* summary,
                             std::size_t max_scans = 0);
/// As read_scans_skipping_bad from a file; false with *error = "cannot open <path>" or "read error on <path>".
bool read_scan_file_skipping_bad(const std::string& path, std::vector<RecordedScan>* out, ScanReadSummary* summary,
                                 std::string* error, std::size_t max_scans = 0);
/// As read_scans from a file; "cannot open <path>" when it cannot be opened.
bool read_scan_file(const std::string& path, std::vector<RecordedScan>* out, std::string* error);
/// Writes one line per scan, each terminated by '\n'. Returns false on a stream error.
bool write_scans(std::ostream& out, const std::vector<RecordedScan>& scans);
bool write_scan_file(const std::string& path, const std::vector<RecordedScan>& scans, std::string* error);

}  // namespace docksim
