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
/// As read_scans from a file; "cannot open <path>" when it cannot be opened.
bool read_scan_file(const std::string& path, std::vector<RecordedScan>* out, std::string* error);
/// Writes one line per scan, each terminated by '\n'. Returns false on a stream error.
bool write_scans(std::ostream& out, const std::vector<RecordedScan>& scans);
bool write_scan_file(const std::string& path, const std::vector<RecordedScan>& scans, std::string* error);

}  // namespace docksim
