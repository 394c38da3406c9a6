// Recorded-scan JSON lines: exact-enough round trips and clear, line-numbered errors on bad input.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "dockcore/laser_scan.hpp"
#include "docksim/scan_io.hpp"

#include <CppUTest/TestHarness.h>

using namespace docksim;

namespace {

RecordedScan sample_scan(std::size_t n, bool with_intensities) {
  RecordedScan s;
  s.stamp_us = (1ull << 53) + 1;  // Not representable as a double: must stay an integer on the way through.
  s.angle_min_rad = -3.14159265358979;
  s.angle_increment_rad = 2 * 3.14159265358979323846 / 450.0;
  for (std::size_t i = 0; i < n; ++i) {
    s.ranges_m.push_back(i % 7 == 0 ? 0.0 : 0.02 + 11.9 * std::fabs(std::sin(0.37 * static_cast<double>(i))));
    if (with_intensities) s.intensities.push_back(i % 7 == 0 ? 0.0 : 1.5 + static_cast<double>(i % 250));
  }
  return s;
}

bool contains(const std::string& s, const char* what) { return s.find(what) != std::string::npos; }

// Parses one line and returns the error ("" on success).
std::string error_of(const std::string& line) {
  RecordedScan s;
  std::string err;
  return parse_scan_line(line, &s, &err) ? std::string() : err;
}

}  // namespace

TEST_GROUP(ScanIo){};

TEST(ScanIo, RoundTripKeepsAnglesExactlyAndRangesToSixDigits) {
  const RecordedScan in = sample_scan(450, true);
  const std::string line = format_scan_line(in);
  CHECK_TRUE(line.find('\n') == std::string::npos);
  RecordedScan out;
  std::string err;
  CHECK_TRUE(parse_scan_line(line, &out, &err));
  CHECK_TRUE(out.stamp_us == in.stamp_us);
  CHECK_TRUE(out.angle_min_rad == in.angle_min_rad);
  CHECK_TRUE(out.angle_increment_rad == in.angle_increment_rad);
  LONGS_EQUAL(in.ranges_m.size(), out.ranges_m.size());
  LONGS_EQUAL(in.intensities.size(), out.intensities.size());
  for (std::size_t i = 0; i < in.ranges_m.size(); ++i) {
    if (in.ranges_m[i] == 0) {
      DOUBLES_EQUAL(0.0, out.ranges_m[i], 0);
    } else {
      DOUBLES_EQUAL(in.ranges_m[i], out.ranges_m[i], 5e-6 * in.ranges_m[i]);  // %.6g: half a unit in the 6th digit.
    }
    DOUBLES_EQUAL(in.intensities[i], out.intensities[i], 5e-6 * in.intensities[i]);
  }
  // Formatting what was read gives the same line: the format is a fixed point.
  STRCMP_EQUAL(line.c_str(), format_scan_line(out).c_str());
}

TEST(ScanIo, CoreScanViewRoundTrip) {
  static dockcore::LaserScan a, b;
  CHECK_TRUE(a.reset(360, static_cast<dockcore::Real>(-3.0), static_cast<dockcore::Real>(0.0174533), 99));
  for (std::size_t i = 0; i < 360; ++i) {
    a.ranges_m[i] = static_cast<dockcore::Real>(i % 5 == 0 ? 0.0 : 0.5 + 0.01 * static_cast<double>(i));
    a.intensities[i] = static_cast<dockcore::Real>(i);
  }
  std::stringstream ss;
  ss << format_scan_line(a.view()) << "\n";
  std::vector<RecordedScan> scans;
  std::string err;
  CHECK_TRUE(read_scans(ss, &scans, &err));
  LONGS_EQUAL(1, scans.size());
  CHECK_TRUE(scans[0].to_laser_scan(&b));
  LONGS_EQUAL(360, b.count);
  CHECK_EQUAL(99u, b.stamp_us);
  DOUBLES_EQUAL(a.angle_min_rad, b.angle_min_rad, 0);
  DOUBLES_EQUAL(a.angle_increment_rad, b.angle_increment_rad, 0);
  for (std::size_t i = 0; i < 360; ++i) {
    DOUBLES_EQUAL(a.ranges_m[i], b.ranges_m[i], 5e-6 * a.ranges_m[i]);
    DOUBLES_EQUAL(a.intensities[i], b.intensities[i], 5e-6 * a.intensities[i]);
  }
}

TEST(ScanIo, NullsOptionalIntensitiesAndUnknownKeys) {
  RecordedScan s;
  std::string err;
  CHECK_TRUE(parse_scan_line(R"({"stamp_us":5,"angle_min_rad":-1,"angle_increment_rad":0.5,"ranges_m":[1.5,null,0,2],"frame":"laser"})", &s, &err));
  LONGS_EQUAL(4, s.ranges_m.size());
  DOUBLES_EQUAL(1.5, s.ranges_m[0], 0);
  DOUBLES_EQUAL(0.0, s.ranges_m[1], 0);
  DOUBLES_EQUAL(0.0, s.ranges_m[2], 0);
  DOUBLES_EQUAL(2.0, s.ranges_m[3], 0);
  CHECK_TRUE(s.intensities.empty());
  CHECK_TRUE(parse_scan_line(R"({"stamp_us":5,"angle_min_rad":-1,"angle_increment_rad":0.5,"ranges_m":[1,2],"intensities":[null,7]})", &s, &err));
  LONGS_EQUAL(2, s.intensities.size());
  DOUBLES_EQUAL(0.0, s.intensities[0], 0);
  DOUBLES_EQUAL(7.0, s.intensities[1], 0);
  CHECK_TRUE(parse_scan_line(R"({"stamp_us":5,"angle_min_rad":-1,"angle_increment_rad":0.5,"ranges_m":[1,2],"intensities":null})", &s, &err));
  CHECK_TRUE(s.intensities.empty());
  // Writer: no intensities key when there are none; non-finite and negative ranges become 0.
  RecordedScan w;
  w.angle_increment_rad = 0.1;
  w.ranges_m = {std::nan(""), -1.0, 1.0};
  const std::string line = format_scan_line(w);
  CHECK_FALSE(contains(line, "intensities"));
  CHECK_TRUE(contains(line, "\"ranges_m\":[0,0,1]"));
}

TEST(ScanIo, MalformedLinesGiveSpecificErrors) {
  const std::string ok_head = R"({"stamp_us":1,"angle_min_rad":0,"angle_increment_rad":0.01,)";
  CHECK_TRUE(error_of(ok_head + R"("ranges_m":[1]})").empty());
  CHECK_TRUE(contains(error_of("{"), "not valid JSON"));
  CHECK_TRUE(contains(error_of("\x01\xff\xfe garbage"), "not valid JSON"));
  CHECK_TRUE(contains(error_of("[1,2,3]"), "not a JSON object"));
  CHECK_TRUE(contains(error_of("{}"), "missing \"stamp_us\""));
  CHECK_TRUE(contains(error_of(R"({"stamp_us":-4,"angle_min_rad":0,"angle_increment_rad":0.01,"ranges_m":[]})"), "stamp_us"));
  CHECK_TRUE(contains(error_of(R"({"stamp_us":"12","angle_min_rad":0,"angle_increment_rad":0.01,"ranges_m":[]})"), "stamp_us"));
  CHECK_TRUE(contains(error_of(R"({"stamp_us":1.5,"angle_min_rad":0,"angle_increment_rad":0.01,"ranges_m":[]})"), "stamp_us"));
  CHECK_TRUE(contains(error_of(R"({"stamp_us":1,"angle_increment_rad":0.01,"ranges_m":[]})"), "missing \"angle_min_rad\""));
  CHECK_TRUE(contains(error_of(R"({"stamp_us":1,"angle_min_rad":true,"angle_increment_rad":0.01,"ranges_m":[]})"), "\"angle_min_rad\" is not a number"));
  CHECK_TRUE(contains(error_of(R"({"stamp_us":1,"angle_min_rad":0,"angle_increment_rad":0,"ranges_m":[1,2]})"), "angle_increment_rad"));
  CHECK_TRUE(contains(error_of(R"({"stamp_us":1,"angle_min_rad":0,"angle_increment_rad":0.01})"), "missing \"ranges_m\""));
  CHECK_TRUE(contains(error_of(ok_head + R"("ranges_m":"1,2"})"), "\"ranges_m\" is not an array"));
  CHECK_TRUE(contains(error_of(ok_head + R"("ranges_m":[1,"x"]})"), "\"ranges_m\"[1] is not a number"));
  CHECK_TRUE(contains(error_of(ok_head + R"("ranges_m":[1,[2]]})"), "\"ranges_m\"[1] is not a number"));
  CHECK_TRUE(contains(error_of(ok_head + R"("ranges_m":[1,-2]})"), "\"ranges_m\"[1] is negative"));
  CHECK_TRUE(contains(error_of(ok_head + R"("ranges_m":[1,2],"intensities":[1]})"), "\"intensities\" has 1 values for 2"));
  CHECK_TRUE(contains(error_of(ok_head + R"("ranges_m":[1,2],"intensities":[1,false]})"), "\"intensities\"[1]"));
  CHECK_TRUE(contains(error_of(ok_head + R"("ranges_m":[1,2],"intensities":{}})"), "\"intensities\" is not an array"));
  // Too many points.
  std::string many = ok_head + "\"ranges_m\":[";
  for (std::size_t i = 0; i <= dockcore::kMaxScanPoints; ++i) many += i ? ",1" : "1";
  many += "]}";
  CHECK_TRUE(contains(error_of(many), "too many points: 4097 > 4096"));
  // Deep nesting is refused before any tree is built.
  CHECK_TRUE(contains(error_of(std::string(200000, '[')), "nested deeper"));
  CHECK_TRUE(contains(error_of(std::string(100, '{')), "nested deeper"));
  // Brackets inside strings do not count.
  CHECK_TRUE(error_of(ok_head + R"("note":"[[[[[[[[\"]]]","ranges_m":[1]})").empty());
}

TEST(ScanIo, ReaderReportsLineNumbersAndCanContinue) {
  const std::string good = format_scan_line(sample_scan(10, false));
  std::stringstream ss;
  ss << good << "\n\n   \r\n" << good << "\r\n" << "{\"stamp_us\":1}\n" << good;  // No final newline.
  std::vector<RecordedScan> scans;
  std::string err;
  CHECK_FALSE(read_scans(ss, &scans, &err));
  LONGS_EQUAL(2, scans.size());
  STRCMP_EQUAL("line 5: missing \"angle_min_rad\"", err.c_str());

  std::stringstream ss2(ss.str());
  ScanReader reader(ss2);
  RecordedScan s;
  CHECK_TRUE(reader.next(&s, &err) == ScanReader::Status::kScan);
  CHECK_TRUE(reader.next(&s, &err) == ScanReader::Status::kScan);
  LONGS_EQUAL(4, reader.line_number());
  CHECK_TRUE(reader.next(&s, &err) == ScanReader::Status::kError);
  CHECK_TRUE(reader.next(&s, &err) == ScanReader::Status::kScan);
  LONGS_EQUAL(6, reader.line_number());
  LONGS_EQUAL(10, s.ranges_m.size());
  CHECK_TRUE(reader.next(&s, &err) == ScanReader::Status::kEnd);
}

TEST(ScanIo, OverlongLineIsAnErrorAndTheNextLineStillReads) {
  std::stringstream ss;
  ss << std::string(kMaxScanLineBytes + 10, ' ') << "x\n" << format_scan_line(sample_scan(3, true)) << "\n";
  ScanReader reader(ss);
  RecordedScan s;
  std::string err;
  CHECK_TRUE(reader.next(&s, &err) == ScanReader::Status::kError);
  CHECK_TRUE(contains(err, "line 1: longer than"));
  CHECK_TRUE(reader.next(&s, &err) == ScanReader::Status::kScan);
  LONGS_EQUAL(3, s.intensities.size());
}

TEST(ScanIo, FileRoundTrip) {
  const std::string path = "h_sim_scan_io_test_" + std::to_string(reinterpret_cast<std::uintptr_t>(&path)) + ".jsonl";
  std::vector<RecordedScan> in = {sample_scan(450, true), sample_scan(1081, false), sample_scan(0, false)};
  in[1].stamp_us = 100000;
  std::string err;
  CHECK_TRUE(write_scan_file(path, in, &err));
  std::vector<RecordedScan> out;
  CHECK_TRUE(read_scan_file(path, &out, &err));
  std::remove(path.c_str());
  LONGS_EQUAL(3, out.size());
  CHECK_TRUE(out[1].stamp_us == 100000);
  LONGS_EQUAL(1081, out[1].ranges_m.size());
  CHECK_TRUE(out[1].intensities.empty());
  LONGS_EQUAL(0, out[2].ranges_m.size());
  CHECK_FALSE(read_scan_file("/nonexistent/dir/x.jsonl", &out, &err));
  CHECK_TRUE(contains(err, "cannot open"));
}

// A recording with bad lines among good ones: each bad line is reported with its number and skipped, counted; the
// good lines read exactly as they would alone.
TEST(ScanIo, BadLinesAreReportedSkippedAndCounted) {
  const std::string good = format_scan_line(sample_scan(10, true));
  const std::string head = R"({"stamp_us":7,"angle_min_rad":0,"angle_increment_rad":0.01,)";
  std::stringstream ss;
  ss << good << "\n"  // line 1
     << head << R"("ranges_m":[1,2,3],"intensities":[5,6]})"
     << "\n"  // 2: wrong intensity count
     << R"({"stamp_us":7,"angle_min_rad":NaN,"angle_increment_rad":0.01,"ranges_m":[1,2]})"
     << "\n"  // 3
     << R"({"stamp_us":7,"angle_min_rad":0,"angle_increment_rad":1e999,"ranges_m":[1,2]})"
     << "\n"  // 4
     << R"({"stamp_us":7,"angle_min_rad":0,"angle_increment_rad":0,"ranges_m":[1,2]})"
     << "\n"           // 5: zero step
     << "\n"           // 6: blank, not counted
     << good << "\n";  // 7
  std::vector<RecordedScan> scans;
  ScanReadSummary summary;
  CHECK_TRUE(read_scans_skipping_bad(ss, &scans, &summary));
  LONGS_EQUAL(2, scans.size());
  LONGS_EQUAL(2, summary.scans);
  LONGS_EQUAL(4, summary.skipped);
  LONGS_EQUAL(7, summary.lines);
  LONGS_EQUAL(4, summary.errors.size());
  STRCMP_EQUAL("line 2: \"intensities\" has 2 values for 3 ranges", summary.errors[0].c_str());
  STRCMP_EQUAL("line 3: non-finite number NaN in \"angle_min_rad\"", summary.errors[1].c_str());
  STRCMP_EQUAL("line 4: non-finite number 1e999 in \"angle_increment_rad\"", summary.errors[2].c_str());
  STRCMP_EQUAL("line 5: \"angle_increment_rad\" is 0", summary.errors[3].c_str());
  // The good lines are untouched by their bad neighbours.
  RecordedScan alone;
  std::string err;
  CHECK_TRUE(parse_scan_line(good, &alone, &err));
  for (const RecordedScan& s : scans) STRCMP_EQUAL(format_scan_line(alone).c_str(), format_scan_line(s).c_str());
}

TEST(ScanIo, SkippingReaderKeepsTheFirstErrorsAndCountsTheRest) {
  std::stringstream ss;
  for (std::size_t i = 0; i < kMaxReportedScanErrors + 5; ++i) ss << "{\"stamp_us\":1}\n";
  ss << format_scan_line(sample_scan(3, false)) << "\n";
  std::vector<RecordedScan> scans;
  ScanReadSummary summary;
  CHECK_TRUE(read_scans_skipping_bad(ss, &scans, &summary));
  LONGS_EQUAL(kMaxReportedScanErrors + 5, summary.skipped);
  LONGS_EQUAL(kMaxReportedScanErrors, summary.errors.size());
  LONGS_EQUAL(1, scans.size());
  STRCMP_EQUAL("line 1: missing \"angle_min_rad\"", summary.errors.front().c_str());
}

TEST(ScanIo, SkippingReaderStopsAfterMaxScans) {
  const std::string good = format_scan_line(sample_scan(3, false));
  std::stringstream ss;
  ss << good << "\n{}\n" << good << "\n" << good << "\n";
  std::vector<RecordedScan> scans;
  ScanReadSummary summary;
  CHECK_TRUE(read_scans_skipping_bad(ss, &scans, &summary, 2));
  LONGS_EQUAL(2, scans.size());
  LONGS_EQUAL(1, summary.skipped);
  LONGS_EQUAL(3, summary.lines);
  std::string err;
  CHECK_FALSE(read_scan_file_skipping_bad("/nonexistent/dir/x.jsonl", &scans, &summary, &err));
  CHECK_TRUE(contains(err, "cannot open"));
}

TEST(ScanIo, NonFiniteValuesAreNamed) {
  const std::string head = R"({"stamp_us":1,"angle_min_rad":0,"angle_increment_rad":0.01,)";
  CHECK_TRUE(contains(error_of(head + R"("ranges_m":[1,Infinity]})"), "non-finite number Infinity in \"ranges_m\""));
  CHECK_TRUE(contains(error_of(head + R"("ranges_m":[1,-1e400]})"), "non-finite number -1e400"));
  // A string that merely spells NaN is not a number; a plain syntax error stays "not valid JSON".
  CHECK_TRUE(error_of(head + R"("note":"NaN 1e999","ranges_m":[1]})").empty());
  CHECK_TRUE(contains(error_of(head + R"("ranges_m":[1,,2]})"), "not valid JSON"));
}
