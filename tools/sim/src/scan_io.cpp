// JSON-lines scan recordings (see docksim/scan_io.hpp).
#include "docksim/scan_io.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>

#include <nlohmann/json.hpp>

namespace docksim {
namespace {

using dockcore::Real;
using nlohmann::json;

constexpr int kMaxDepth = 4;

// nlohmann's parser is iterative but its value tree is not free, so bound the depth before building one.
bool depth_ok(const std::string& s) {
  int depth = 0;
  bool in_string = false, escaped = false;
  for (const char ch : s) {
    if (in_string) {
      if (escaped) escaped = false;
      else if (ch == '\\') escaped = true;
      else if (ch == '"') in_string = false;
      continue;
    }
    if (ch == '"') in_string = true;
    else if (ch == '[' || ch == '{') {
      if (++depth > kMaxDepth) return false;
    } else if (ch == ']' || ch == '}') {
      --depth;
    }
  }
  return true;
}

// JSON has no NaN or infinity, so a recorder that writes one (NaN, Infinity, 1e999) makes the line invalid JSON.
// After a failed parse this names the culprit: "non-finite number <token> in \"<key>\"". Byte-at-a-time scan
// with explicit state (inside a string or not, the last string seen = the key the value belongs to).
bool find_nonfinite(const std::string& s, std::string* what) {
  enum class State { kOutside, kString, kEscape, kToken };
  State st = State::kOutside;
  std::string last_string, current, token;
  auto finish_token = [&]() {
    if (token.empty()) return false;
    char* end = nullptr;
    const double v = std::strtod(token.c_str(), &end);
    const bool consumed = end != nullptr && *end == '\0';
    const bool bad_literal = token == "NaN" || token == "nan" || token == "Infinity" || token == "-Infinity" ||
                             token == "inf" || token == "-inf" || token == "-NaN" || token == "-nan";
    if (bad_literal || (consumed && !std::isfinite(v))) {
      *what = "non-finite number " + token + " in \"" + last_string + "\"";
      return true;
    }
    token.clear();
    return false;
  };
  for (const char ch : s) {
    switch (st) {
      case State::kString:
        if (ch == '\\')
          st = State::kEscape;
        else if (ch == '"') {
          last_string = current;
          st = State::kOutside;
        } else {
          current.push_back(ch);
        }
        break;
      case State::kEscape:
        current.push_back(ch);
        st = State::kString;
        break;
      case State::kToken:
        if (std::isalnum(static_cast<unsigned char>(ch)) || ch == '.' || ch == '+' || ch == '-') {
          if (token.size() < 64) token.push_back(ch);
          break;
        }
        if (finish_token()) return true;
        st = State::kOutside;
        [[fallthrough]];
      case State::kOutside:
        if (ch == '"') {
          current.clear();
          st = State::kString;
        } else if (std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '.') {
          token.assign(1, ch);
          st = State::kToken;
        }
        break;
    }
  }
  return st == State::kToken && finish_token();
}

bool get_finite(const json& obj, const char* key, double* out, std::string* error) {
  const auto it = obj.find(key);
  if (it == obj.end()) {
    *error = std::string("missing \"") + key + "\"";
    return false;
  }
  if (!it->is_number()) {
    *error = std::string("\"") + key + "\" is not a number";
    return false;
  }
  const double v = it->get<double>();
  if (!std::isfinite(v)) {
    *error = std::string("\"") + key + "\" is not finite";
    return false;
  }
  *out = v;
  return true;
}

void append_g(std::string* s, double v, int digits) {
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.*g", digits, v);
  *s += buf;
}

std::string format(std::uint64_t stamp, double amin, double ainc, const double* r, const double* inten, std::size_t n) {
  std::string s;
  s.reserve(96 + n * (inten ? 16 : 9));
  s += "{\"stamp_us\":";
  s += std::to_string(stamp);
  s += ",\"angle_min_rad\":";
  append_g(&s, std::isfinite(amin) ? amin : 0.0, 17);
  s += ",\"angle_increment_rad\":";
  append_g(&s, std::isfinite(ainc) ? ainc : 0.0, 17);
  s += ",\"ranges_m\":[";
  for (std::size_t i = 0; i < n; ++i) {
    if (i) s += ',';
    if (r[i] > 0 && std::isfinite(r[i])) append_g(&s, r[i], 6);
    else s += '0';
  }
  s += ']';
  if (inten) {
    s += ",\"intensities\":[";
    for (std::size_t i = 0; i < n; ++i) {
      if (i) s += ',';
      append_g(&s, std::isfinite(inten[i]) ? inten[i] : 0.0, 6);
    }
    s += ']';
  }
  s += '}';
  return s;
}

// Reads one line of at most kMaxScanLineBytes; a longer line is consumed to its end and reported as too long.
// Returns false at end of input with nothing read.
bool read_line(std::istream& in, std::string* line, bool* too_long) {
  line->clear();
  *too_long = false;
  std::streambuf* sb = in.rdbuf();
  if (!sb) return false;
  bool any = false;
  for (;;) {
    const int c = sb->sbumpc();
    if (c == std::char_traits<char>::eof()) {
      in.setstate(std::ios::eofbit);
      return any;
    }
    any = true;
    if (c == '\n') break;
    if (line->size() < kMaxScanLineBytes) line->push_back(static_cast<char>(c));
    else *too_long = true;
  }
  if (!line->empty() && line->back() == '\r') line->pop_back();
  return true;
}

bool blank(const std::string& s) {
  for (const char c : s)
    if (c != ' ' && c != '\t' && c != '\r' && c != '\n') return false;
  return true;
}

}  // namespace

bool RecordedScan::to_laser_scan(dockcore::LaserScan* out) const {
  if (ranges_m.size() > dockcore::kMaxScanPoints) return false;
  out->reset(ranges_m.size(), static_cast<Real>(angle_min_rad), static_cast<Real>(angle_increment_rad), stamp_us);
  for (std::size_t i = 0; i < ranges_m.size(); ++i) {
    out->ranges_m[i] = static_cast<Real>(ranges_m[i]);
    out->intensities[i] = intensities.size() == ranges_m.size() ? static_cast<Real>(intensities[i]) : 0;
  }
  return true;
}

RecordedScan RecordedScan::from_view(const dockcore::ScanView& v) {
  RecordedScan s;
  s.stamp_us = v.stamp_us;
  s.angle_min_rad = static_cast<double>(v.angle_min_rad);
  s.angle_increment_rad = static_cast<double>(v.angle_increment_rad);
  s.ranges_m.resize(v.count);
  for (std::size_t i = 0; i < v.count; ++i) s.ranges_m[i] = v.ranges_m ? static_cast<double>(v.ranges_m[i]) : 0.0;
  if (v.intensities) {
    s.intensities.resize(v.count);
    for (std::size_t i = 0; i < v.count; ++i) s.intensities[i] = static_cast<double>(v.intensities[i]);
  }
  return s;
}

bool parse_scan_line(const std::string& line, RecordedScan* out, std::string* error) {
  std::string dummy;
  if (!error) error = &dummy;
  if (line.size() > kMaxScanLineBytes) {
    *error = "line longer than " + std::to_string(kMaxScanLineBytes) + " bytes";
    return false;
  }
  if (!depth_ok(line)) {
    *error = "JSON nested deeper than " + std::to_string(kMaxDepth);
    return false;
  }
  const json j = json::parse(line, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) {
    if (!find_nonfinite(line, error)) *error = "not valid JSON";
    return false;
  }
  if (!j.is_object()) {
    *error = "not a JSON object";
    return false;
  }
  RecordedScan s;
  const auto st = j.find("stamp_us");
  if (st == j.end()) {
    *error = "missing \"stamp_us\"";
    return false;
  }
  if (st->is_number_unsigned()) {
    s.stamp_us = st->get<std::uint64_t>();
  } else if (st->is_number_float()) {
    const double d = st->get<double>();
    if (!(d >= 0 && d < 18446744073709551616.0 && std::floor(d) == d)) {
      *error = "\"stamp_us\" is not a non-negative integer";
      return false;
    }
    s.stamp_us = static_cast<std::uint64_t>(d);
  } else {
    *error = "\"stamp_us\" is not a non-negative integer";
    return false;
  }
  if (!get_finite(j, "angle_min_rad", &s.angle_min_rad, error)) return false;
  if (!get_finite(j, "angle_increment_rad", &s.angle_increment_rad, error)) return false;

  const auto rg = j.find("ranges_m");
  if (rg == j.end()) {
    *error = "missing \"ranges_m\"";
    return false;
  }
  if (!rg->is_array()) {
    *error = "\"ranges_m\" is not an array";
    return false;
  }
  if (rg->size() > dockcore::kMaxScanPoints) {
    *error = "too many points: " + std::to_string(rg->size()) + " > " + std::to_string(dockcore::kMaxScanPoints);
    return false;
  }
  if (rg->size() >= 2 && s.angle_increment_rad == 0) {
    *error = "\"angle_increment_rad\" is 0";
    return false;
  }
  s.ranges_m.reserve(rg->size());
  for (std::size_t i = 0; i < rg->size(); ++i) {
    const json& v = (*rg)[i];
    if (v.is_null()) {
      s.ranges_m.push_back(0.0);
    } else if (v.is_number()) {
      const double r = v.get<double>();
      if (r < 0) {
        *error = "\"ranges_m\"[" + std::to_string(i) + "] is negative";
        return false;
      }
      s.ranges_m.push_back(r);  // inf (from an overflowing literal) stays: it already means "no return".
    } else {
      *error = "\"ranges_m\"[" + std::to_string(i) + "] is not a number or null";
      return false;
    }
  }
  const auto in = j.find("intensities");
  if (in != j.end() && !in->is_null()) {
    if (!in->is_array()) {
      *error = "\"intensities\" is not an array";
      return false;
    }
    if (!in->empty()) {
      if (in->size() != rg->size()) {
        *error = "\"intensities\" has " + std::to_string(in->size()) + " values for " + std::to_string(rg->size()) +
                 " ranges";
        return false;
      }
      s.intensities.reserve(in->size());
      for (std::size_t i = 0; i < in->size(); ++i) {
        const json& v = (*in)[i];
        if (v.is_null()) {
          s.intensities.push_back(0.0);
        } else if (v.is_number()) {
          s.intensities.push_back(v.get<double>());
        } else {
          *error = "\"intensities\"[" + std::to_string(i) + "] is not a number or null";
          return false;
        }
      }
    }
  }
  *out = std::move(s);
  return true;
}

std::string format_scan_line(const RecordedScan& scan) {
  const bool has_i = !scan.intensities.empty() && scan.intensities.size() == scan.ranges_m.size();
  return format(scan.stamp_us, scan.angle_min_rad, scan.angle_increment_rad, scan.ranges_m.data(),
                has_i ? scan.intensities.data() : nullptr, scan.ranges_m.size());
}

std::string format_scan_line(const dockcore::ScanView& scan) { return format_scan_line(RecordedScan::from_view(scan)); }

ScanReader::Status ScanReader::next(RecordedScan* out, std::string* error) {
  std::string line;
  bool too_long = false;
  for (;;) {
    if (!read_line(in_, &line, &too_long)) return Status::kEnd;
    ++line_;
    if (too_long) {
      if (error) *error = "line " + std::to_string(line_) + ": longer than " + std::to_string(kMaxScanLineBytes) + " bytes";
      return Status::kError;
    }
    if (blank(line)) continue;
    std::string what;
    if (parse_scan_line(line, out, &what)) return Status::kScan;
    if (error) *error = "line " + std::to_string(line_) + ": " + what;
    return Status::kError;
  }
}

bool read_scans(std::istream& in, std::vector<RecordedScan>* out, std::string* error) {
  ScanReader reader(in);
  for (;;) {
    RecordedScan s;
    switch (reader.next(&s, error)) {
      case ScanReader::Status::kScan: out->push_back(std::move(s)); break;
      case ScanReader::Status::kEnd: return true;
      case ScanReader::Status::kError: return false;
    }
  }
}

bool read_scans_skipping_bad(std::istream& in, std::vector<RecordedScan>* out, ScanReadSummary* summary,
                             std::size_t max_scans) {
  ScanReader reader(in);
  *summary = ScanReadSummary{};
  for (;;) {
    if (max_scans != 0 && summary->scans >= max_scans) break;
    RecordedScan s;
    std::string error;
    const ScanReader::Status st = reader.next(&s, &error);
    summary->lines = reader.line_number();
    if (st == ScanReader::Status::kEnd) break;
    if (st == ScanReader::Status::kError) {
      ++summary->skipped;
      if (summary->errors.size() < kMaxReportedScanErrors) summary->errors.push_back(error);
      continue;
    }
    out->push_back(std::move(s));
    ++summary->scans;
  }
  return !in.bad();
}

bool read_scan_file_skipping_bad(const std::string& path, std::vector<RecordedScan>* out, ScanReadSummary* summary,
                                 std::string* error, std::size_t max_scans) {
  std::ifstream f(path, std::ios::binary);
  if (!f) {
    if (error) *error = "cannot open " + path;
    *summary = ScanReadSummary{};
    return false;
  }
  if (!read_scans_skipping_bad(f, out, summary, max_scans)) {
    if (error) *error = "read error on " + path;
    return false;
  }
  return true;
}

bool read_scan_file(const std::string& path, std::vector<RecordedScan>* out, std::string* error) {
  std::ifstream f(path, std::ios::binary);
  if (!f) {
    if (error) *error = "cannot open " + path;
    return false;
  }
  return read_scans(f, out, error);
}

bool write_scans(std::ostream& out, const std::vector<RecordedScan>& scans) {
  for (const RecordedScan& s : scans) {
    out << format_scan_line(s) << '\n';
    if (!out) return false;
  }
  return static_cast<bool>(out);
}

bool write_scan_file(const std::string& path, const std::vector<RecordedScan>& scans, std::string* error) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f) {
    if (error) *error = "cannot open " + path + " for writing";
    return false;
  }
  if (!write_scans(f, scans) || !f.flush()) {
    if (error) *error = "write error on " + path;
    return false;
  }
  return true;
}

}  // namespace docksim
