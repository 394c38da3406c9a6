// Real recordings: location, per-recording table, CARMEN logs and pose matching (see docksim/realdata.hpp).
#include "docksim/realdata.hpp"

#include <zlib.h>

#include <cmath>
#include <cstdlib>
#include <fstream>

#ifndef DOCKCORE_SOURCE_DIR
#error "DOCKCORE_SOURCE_DIR must name the repository root (set by tools/CMakeLists.txt)"
#endif

namespace docksim {
namespace {

using dockcore::Pose2;
using dockcore::Real;

bool has_readme(const std::string& dir) {
  std::ifstream f(dir + "/README.md");
  return static_cast<bool>(f);
}

bool parse_double(const std::string& s, double* out) {
  if (s.empty()) return false;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end == s.c_str() || *end != '\0' || !std::isfinite(v)) return false;
  *out = v;
  return true;
}

bool parse_count(const std::string& s, std::size_t* out) {
  double v = 0;
  if (!parse_double(s, &v) || v < 0 || v > 100000 || std::floor(v) != v) return false;
  *out = static_cast<std::size_t>(v);
  return true;
}

Pose2 pose_of(double x, double y, double yaw) {
  return Pose2{static_cast<Real>(x), static_cast<Real>(y), dockcore::wrap_angle(static_cast<Real>(yaw))};
}

}  // namespace

std::string RealDataLocation::describe() const {
  if (found()) return "real data: " + dir + " (from " + source + ")";
  std::string s = "real data: not found (looked in ";
  for (std::size_t i = 0; i < looked.size(); ++i) s += (i ? ", " : "") + looked[i];
  return s + "); skipped";
}

RealDataLocation locate_realdata(const std::string& override_dir) {
  RealDataLocation loc;
  auto try_dir = [&loc](const std::string& dir, const char* source) {
    loc.looked.push_back(dir);
    if (has_readme(dir)) {
      loc.dir = dir;
      loc.source = source;
    }
  };
  if (!override_dir.empty()) {
    try_dir(override_dir, "--realdata");
    return loc;
  }
  const char* env = std::getenv("DOCKCORE_REALDATA");
  if (env != nullptr && *env != '\0') {
    try_dir(env, "$DOCKCORE_REALDATA");
    return loc;
  }
  try_dir(std::string(DOCKCORE_SOURCE_DIR) + "/../shared/realdata", "<repo>/../shared/realdata");
  return loc;
}

const char* to_string(PoseSource p) {
  switch (p) {
    case PoseSource::kNone:
      return "none";
    case PoseSource::kCarmenFlaser:
      return "carmen-flaser";
    case PoseSource::kCarmenRobotLaser:
      return "carmen-robotlaser";
    case PoseSource::kStatic:
      return "static";
  }
  return "?";
}

namespace {
// σ: README "noise 1-2 m" p25 (mm). Resolutions and no-return codes: README "How each source was converted".
const RealRecording kTable[] = {
    {"intel-lab", "intel-lab.jsonl", 0.0029, 0.01, PoseSource::kCarmenFlaser,
     "orig/acschaefer+ple/data/carmen/intel-corrected.log.gz", 1, 81.0, "Intel lab, offices, cluttered"},
    {"fr079", "fr079.jsonl", 0.0037, 0.01, PoseSource::kCarmenFlaser,
     "orig/acschaefer+ple/data/carmen/freiburg-079-corrected.log.gz", 2, 81.0, "Freiburg 079, offices, corridor"},
    {"fr101", "fr101.jsonl", 0.0032, 0.01, PoseSource::kCarmenFlaser,
     "orig/acschaefer+ple/data/carmen/freiburg-101-corrected.log.gz", 1, 81.0, "Freiburg 101"},
    {"fr-campus", "fr-campus.jsonl", 0.0042, 0.01, PoseSource::kCarmenFlaser,
     "orig/acschaefer+ple/data/carmen/freiburg-campus-corrected.log.gz", 1, 81.0, "Freiburg campus, outdoor"},
    {"aces", "aces.jsonl", 0.0127, 0.01, PoseSource::kCarmenFlaser,
     "orig/acschaefer+ple/data/carmen/aces-corrected.log.gz", 1, 50.0, "UT Austin ACES building"},
    {"mit-csail", "mit-csail.jsonl", 0.0029, 0.01, PoseSource::kCarmenFlaser,
     "orig/acschaefer+ple/data/carmen/csail-corrected.log.gz", 1, 81.0, "MIT CSAIL building"},
    {"mit-csail-robotlaser", "mit-csail-robotlaser.jsonl", 0.0028, 0.01, PoseSource::kCarmenRobotLaser,
     "orig/kiran-mohan+SLAM-Algorithms-Octave/4_Gridmapping/data/csail.log.gz", 1, 80.0, "MIT CSAIL (course excerpt)"},
    {"mit-infinite-corridor", "mit-infinite-corridor.jsonl", 0.0130, 0.01, PoseSource::kCarmenFlaser,
     "orig/acschaefer+ple/data/carmen/infinite-corridor-corrected.log.gz", 1, 51.0, "MIT Infinite Corridor"},
    {"seattle-uw", "seattle-uw.jsonl", 0.0021, 0.01, PoseSource::kCarmenFlaser,
     "orig/acschaefer+ple/data/carmen/seattle-corrected.log.gz", 1, 81.0, "Univ. of Washington"},
    {"orebro", "orebro.jsonl", 0.0024, 0.001, PoseSource::kCarmenFlaser,
     "orig/acschaefer+ple/data/carmen/orebro-corrected.log.gz", 1, 32.7, "Orebro University"},
    {"belgioioso", "belgioioso.jsonl", 0.0032, 0.01, PoseSource::kCarmenFlaser,
     "orig/acschaefer+ple/data/carmen/belgioioso-corrected.log.gz", 1, 81.0, "Belgioioso castle"},
    {"fhw-museum", "fhw-museum.jsonl", 0.0129, 0.05, PoseSource::kCarmenFlaser,
     "orig/acschaefer+ple/data/carmen/fhw-corrected.log.gz", 1, 51.0, "FHW museum, 5 cm steps"},
    {"edmonton", "edmonton.jsonl", 0.0152, 0.05, PoseSource::kCarmenFlaser,
     "orig/acschaefer+ple/data/carmen/edmonton-corrected.log.gz", 1, 51.0, "Edmonton hall, 5 cm steps"},
    {"acapulco", "acapulco.jsonl", 0.0135, 0.05, PoseSource::kCarmenFlaser,
     "orig/acschaefer+ple/data/carmen/acapulco-corrected.log.gz", 1, 50.0, "Acapulco hall, 5 cm steps"},
    {"mrpt-malaga-sena-telecom", "mrpt-malaga-sena-telecom.jsonl", 0.0057, 0.01, PoseSource::kNone, nullptr, 1, 0,
     "Malaga Telecom faculty loop"},
    {"mrpt-localization-demo", "mrpt-localization-demo.jsonl", 0.0025, 0.01, PoseSource::kNone, nullptr, 1, 0,
     "Malaga building"},
    {"breezyslam-mines-exp1", "breezyslam-mines-exp1.jsonl", 0.0036, 0.001, PoseSource::kNone, nullptr, 1, 0,
     "Hokuyo URG-04LX, indoor"},
    {"breezyslam-mines-exp2", "breezyslam-mines-exp2.jsonl", 0.0032, 0.001, PoseSource::kNone, nullptr, 1, 0,
     "Hokuyo URG-04LX, indoor"},
    {"ydlidar-x4-broombot", "ydlidar-x4-broombot.jsonl", 0.0021, 0.001, PoseSource::kNone, nullptr, 1, 0,
     "YDLIDAR X4, sparse"},
    {"rplidar-a1-room-flat", "rplidar-a1-room-flat.jsonl", 0.0027, 0, PoseSource::kStatic, nullptr, 1, 0,
     "RPLIDAR A1, living room, standing"},
    {"rplidar-a1-room-turret", "rplidar-a1-room-turret.jsonl", 0.0033, 0, PoseSource::kNone, nullptr, 1, 0,
     "RPLIDAR A1, vertical slices"},
};
}  // namespace

RealRecordingTable real_recordings() {
  return RealRecordingTable{kTable, sizeof(kTable) / sizeof(kTable[0])};
}

const RealRecording* find_real_recording(const std::string& name) {
  for (const RealRecording& r : real_recordings()) {
    if (name == r.name) return &r;
  }
  return nullptr;
}

// ---------------------------------------------------------------- CARMEN log parser

CarmenLogParser::Event CarmenLogParser::feed(char c) {
  const bool space = c == ' ' || c == '\t' || c == '\r';
  if (c == '\n') return end_line();
  switch (state_) {
    case State::kLineStart:
      if (space) break;
      type_.assign(1, c);
      state_ = State::kType;
      break;
    case State::kType:
      if (space) {
        if (type_ == "FLASER" || type_ == "ROBOTLASER1") {
          fields_.clear();
          state_ = State::kBetween;
        } else {
          state_ = State::kSkipLine;
        }
      } else if (type_.size() < kMaxFieldBytes) {
        type_.push_back(c);
      }
      break;
    case State::kBetween:
      if (space) break;
      field_.assign(1, c);
      state_ = State::kField;
      break;
    case State::kField:
      if (space) {
        if (fields_.size() >= kMaxFields) {
          overflow_what_ = "more than " + std::to_string(kMaxFields) + " fields";
          state_ = State::kOverflow;
          break;
        }
        fields_.push_back(field_);
        state_ = State::kBetween;
      } else if (field_.size() < kMaxFieldBytes) {
        field_.push_back(c);
      } else {
        overflow_what_ = "a field longer than " + std::to_string(kMaxFieldBytes) + " bytes";
        state_ = State::kOverflow;
      }
      break;
    case State::kSkipLine:
    case State::kOverflow:
      break;
  }
  return Event::kNone;
}

CarmenLogParser::Event CarmenLogParser::finish() {
  if (state_ == State::kLineStart) return Event::kNone;
  return end_line();
}

CarmenLogParser::Event CarmenLogParser::end_line() {
  ++line_;
  const State st = state_;
  state_ = State::kLineStart;
  switch (st) {
    case State::kLineStart:
      return Event::kNone;
    case State::kSkipLine:
      ++other_;
      return Event::kNone;
    case State::kType:
      if (type_ == "FLASER" || type_ == "ROBOTLASER1") {
        error_ = "line " + std::to_string(line_) + ": " + type_ + " without fields";
        return Event::kError;
      }
      ++other_;
      return Event::kNone;
    case State::kOverflow:
      error_ = "line " + std::to_string(line_) + ": " + type_ + " with " + overflow_what_;
      return Event::kError;
    case State::kField:
      if (fields_.size() >= kMaxFields) {
        error_ = "line " + std::to_string(line_) + ": " + type_ + " with more than " + std::to_string(kMaxFields) +
                 " fields";
        return Event::kError;
      }
      fields_.push_back(field_);
      return interpret();
    case State::kBetween:
      return interpret();
  }
  return Event::kNone;
}

CarmenLogParser::Event CarmenLogParser::interpret() {
  const std::string where = "line " + std::to_string(line_) + ": " + type_;
  auto fail = [&](const std::string& what) {
    error_ = where + ": " + what;
    return Event::kError;
  };
  const std::vector<std::string>& f = fields_;
  // Position of the beam count and of the first field after the ranges (and remissions).
  std::size_t count_at = 0;
  if (type_ == "ROBOTLASER1") count_at = 7;
  std::size_t n = 0;
  if (f.size() <= count_at || !parse_count(f[count_at], &n)) return fail("bad beam count");
  std::size_t after = count_at + 1 + n;
  if (type_ == "ROBOTLASER1") {
    std::size_t k = 0;
    if (f.size() <= after || !parse_count(f[after], &k)) return fail("bad remission count");
    after += 1 + k;
  }
  // FLASER: 6 pose values then ipc_timestamp; ROBOTLASER1: 6 pose values, 5 velocities/safety, then ipc_timestamp.
  const std::size_t ts_at = after + (type_ == "ROBOTLASER1" ? 11 : 6);
  if (f.size() <= ts_at) {
    return fail(std::to_string(f.size()) + " fields; " + std::to_string(n) + " ranges need " +
                std::to_string(ts_at + 1));
  }
  laser_ = CarmenLaser{};
  laser_.line = line_;
  laser_.ranges_m.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!parse_double(f[count_at + 1 + i], &laser_.ranges_m[i]))
      return fail("range " + std::to_string(i) + " is not a number");
  }
  double p[6];
  for (int i = 0; i < 6; ++i) {
    if (!parse_double(f[after + static_cast<std::size_t>(i)], &p[i]))
      return fail("pose field " + std::to_string(i) + " is not a number");
  }
  laser_.laser_in_world = pose_of(p[0], p[1], p[2]);
  laser_.robot_in_world = pose_of(p[3], p[4], p[5]);
  if (!parse_double(f[ts_at], &laser_.timestamp_s)) return fail("ipc_timestamp is not a number");
  return Event::kLaser;
}

bool read_carmen_log(const std::string& path, std::size_t max_messages, std::vector<CarmenLaser>* out,
                     std::size_t* errors, std::string* first_error) {
  *errors = 0;
  gzFile gz = gzopen(path.c_str(), "rb");
  if (gz == nullptr) {
    *first_error = "cannot open " + path;
    return false;
  }
  CarmenLogParser parser;
  char buf[1 << 16];
  bool done = false;
  auto handle = [&](CarmenLogParser::Event ev) {
    if (ev == CarmenLogParser::Event::kLaser) {
      out->push_back(parser.laser());
      if (max_messages != 0 && out->size() >= max_messages) done = true;
    } else if (ev == CarmenLogParser::Event::kError) {
      if (*errors == 0) *first_error = path + ":" + parser.error();
      ++*errors;
    }
  };
  while (!done) {
    const int got = gzread(gz, buf, sizeof buf);
    if (got < 0) {
      *first_error = "read error on " + path;
      gzclose(gz);
      return false;
    }
    if (got == 0) {
      handle(parser.finish());
      break;
    }
    for (int i = 0; i < got && !done; ++i) handle(parser.feed(buf[i]));
  }
  gzclose(gz);
  return true;
}

// ---------------------------------------------------------------- loading

bool load_real_recording(const std::string& dir, const RealRecording& rec, std::size_t max_scans, LoadedRecording* out,
                         std::string* error) {
  *out = LoadedRecording{};
  out->info = &rec;
  if (!read_scan_file_skipping_bad(dir + "/" + rec.file, &out->scans, &out->read, error, max_scans)) return false;
  if (rec.poses == PoseSource::kStatic) {
    out->sensor_in_world.assign(out->scans.size(), Pose2{});
    return true;
  }
  if (rec.poses != PoseSource::kCarmenFlaser && rec.poses != PoseSource::kCarmenRobotLaser) return true;

  PoseMatch& m = out->match;
  std::vector<CarmenLaser> log;
  const std::size_t every = rec.pose_every > 0 ? rec.pose_every : 1;
  const std::size_t need = out->scans.empty() ? 1 : (out->scans.size() - 1) * every + 1;
  std::string problem;
  if (!read_carmen_log(dir + "/" + rec.pose_log, max_scans != 0 ? need : 0, &log, &m.log_errors, &problem)) {
    m.first_problem = problem;
    m.mismatched = out->scans.size();
    return true;  // the scans are still usable single-scan
  }
  if (m.log_errors != 0) m.first_problem = problem;
  m.log_messages = log.size();
  std::vector<Pose2> poses;
  poses.reserve(out->scans.size());
  for (std::size_t j = 0; j < out->scans.size(); ++j) {
    const std::size_t k = j * every;
    const RecordedScan& s = out->scans[j];
    std::string why;
    if (k >= log.size()) {
      why = "scan " + std::to_string(j) + ": no log message " + std::to_string(k);
    } else if (log[k].ranges_m.size() != s.ranges_m.size()) {
      why = "scan " + std::to_string(j) + " has " + std::to_string(s.ranges_m.size()) + " ranges, log line " +
            std::to_string(log[k].line) + " " + std::to_string(log[k].ranges_m.size());
    } else {
      for (std::size_t i = 0; i < s.ranges_m.size() && why.empty(); ++i) {
        const double r = log[k].ranges_m[i];
        const double expect = (r >= rec.noreturn_m || r <= 0) ? 0.0 : r;
        if (std::fabs(expect - s.ranges_m[i]) > 1e-4) {
          why = "scan " + std::to_string(j) + " range " + std::to_string(i) + " differs from log line " +
                std::to_string(log[k].line);
        }
      }
    }
    if (why.empty()) {
      ++m.matched;
      poses.push_back(log[k].laser_in_world);
    } else {
      ++m.mismatched;
      if (m.first_problem.empty()) m.first_problem = why;
    }
  }
  if (m.ok()) out->sensor_in_world = std::move(poses);
  return true;
}

}  // namespace docksim
