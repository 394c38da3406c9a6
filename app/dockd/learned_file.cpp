#include "learned_file.hpp"

#include <cinttypes>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <initializer_list>
#include <sstream>

#include "state_file.hpp"  // crc32_ieee, checked_body, read_bounded, write_synced, replace_synced

namespace dockd {

bool LearnedState::learned_on(const dockcore::Pose2& mount, const dockcore::DriveGeometry& d) const {
  auto near = [](dockcore::Real a, dockcore::Real b) { return std::fabs(static_cast<double>(a - b)) <= 1e-6; };
  return near(lidar_mount.x_m, mount.x_m) && near(lidar_mount.y_m, mount.y_m) &&
         near(lidar_mount.yaw_rad, mount.yaw_rad) && drive.kind == d.kind &&
         near(drive.wheel_radius_m, d.wheel_radius_m) && near(drive.wheel_base_m, d.wheel_base_m) &&
         near(drive.lx_m, d.lx_m) && near(drive.ly_m, d.ly_m);
}

bool same_learned(const dockcore::DockcoreBase::Learned& a, const dockcore::DockcoreBase::Learned& b) {
  for (std::size_t i = 0; i < dockcore::kMaxDriveWheels; ++i) {
    for (std::size_t d = 0; d < 2; ++d) {
      if (a.deadband.radps[i][d] != b.deadband.radps[i][d]) return false;
    }
  }
  for (std::size_t i = 0; i < dockcore::kDockIds; ++i) {
    if (a.task.remembered_aim_m[i] != b.task.remembered_aim_m[i]) return false;
  }
  const dockcore::MountCalibrationResult& ca = a.task.last_calibration;
  const dockcore::MountCalibrationResult& cb = b.task.last_calibration;
  return a.deadband.raises == b.deadband.raises && a.task.mount_shift_m == b.task.mount_shift_m &&
         a.task.calibrations == b.task.calibrations && ca.status == cb.status &&
         ca.lateral_error_m == cb.lateral_error_m && ca.mount.x_m == cb.mount.x_m && ca.mount.y_m == cb.mount.y_m &&
         ca.mount.yaw_rad == cb.mount.yaw_rad && ca.rms_m == cb.rms_m && ca.sweep_rad == cb.sweep_rad &&
         ca.detections == cb.detections;
}

namespace {

/// Appends printf-formatted text at buf + *len; false when it does not fit (nothing more is written then).
#if defined(__GNUC__)
__attribute__((format(printf, 4, 5)))
#endif
bool append(char* buf, std::size_t size, std::size_t* len, const char* format, ...) {
  if (*len >= size) return false;
  std::va_list args;
  va_start(args, format);
  const int n = std::vsnprintf(buf + *len, size - *len, format, args);
  va_end(args);
  if (n < 0 || static_cast<std::size_t>(n) >= size - *len) {
    *len = size;
    return false;
  }
  *len += static_cast<std::size_t>(n);
  return true;
}

}  // namespace

std::size_t format_learned(const LearnedState& l, char* buf, std::size_t size) {
  if (buf == nullptr || size == 0) return 0;
  const dockcore::WheelDeadband::Floors& f = l.learned.deadband;
  const dockcore::TaskLearned& t = l.learned.task;
  const dockcore::MountCalibrationResult& c = t.last_calibration;
  std::size_t len = 0;
  bool ok = append(buf, size, &len, "dockd-learned 1\n") &&
            append(buf, size, &len, "learned %.9f %.9f %.9f %u %.9f %.9f %.9f %.9f %" PRIu64 "\n",
                   static_cast<double>(l.lidar_mount.x_m), static_cast<double>(l.lidar_mount.y_m),
                   static_cast<double>(l.lidar_mount.yaw_rad), static_cast<unsigned>(l.drive.kind),
                   static_cast<double>(l.drive.wheel_radius_m), static_cast<double>(l.drive.wheel_base_m),
                   static_cast<double>(l.drive.lx_m), static_cast<double>(l.drive.ly_m), l.saved_unix_s) &&
            append(buf, size, &len, "deadband %u", f.raises);
  for (std::size_t i = 0; ok && i < dockcore::kMaxDriveWheels; ++i) {
    ok = append(buf, size, &len, " %.9f %.9f", static_cast<double>(f.radps[i][0]), static_cast<double>(f.radps[i][1]));
  }
  ok = ok && append(buf, size, &len, "\n") &&
       append(buf, size, &len, "mount %u %u %.9f %.9f %.9f %u %.9f %.9f %.9f %.9f %.9f\n", t.calibrations,
              static_cast<unsigned>(c.status), static_cast<double>(c.lateral_error_m), static_cast<double>(c.rms_m),
              static_cast<double>(c.sweep_rad), static_cast<unsigned>(c.detections), static_cast<double>(c.mount.x_m),
              static_cast<double>(c.mount.y_m), static_cast<double>(c.mount.yaw_rad),
              static_cast<double>(t.mount_shift_m.x()), static_cast<double>(t.mount_shift_m.y()));
  for (std::size_t i = 0; ok && i < dockcore::kDockIds; ++i) {
    if (t.remembered_aim_m[i] == 0) continue;
    ok = append(buf, size, &len, "aim %u %.9f\n", static_cast<unsigned>(i), static_cast<double>(t.remembered_aim_m[i]));
  }
  const std::uint32_t crc = ok ? crc32_ieee(buf, len) : 0;
  ok = ok && append(buf, size, &len, "crc32 %08x\n", crc);
  return ok ? len : 0;
}

namespace {

/// Parses one line of the learned state (`learned`, `deadband`, `mount`, `aim`) into `l`; false + reason otherwise.
/// A `learned` line starts the state; the others must follow one. O(line).
bool parse_learned_line(const std::string& line, bool started, LearnedState& l, std::string& why) {
  const char* p = line.c_str();
  int used = 0;
  auto whole = [&] { return static_cast<std::size_t>(used) == line.size(); };
  auto finite = [](std::initializer_list<double> v) {
    for (double x : v) {
      if (!std::isfinite(x)) return false;
    }
    return true;
  };
  if (line.compare(0, 8, "learned ") == 0) {
    double mx = 0, my = 0, myaw = 0, r = 0, b = 0, lx = 0, ly = 0;
    unsigned kind = 0;
    std::uint64_t when = 0;
    if (std::sscanf(p, "learned %lf %lf %lf %u %lf %lf %lf %lf %" SCNu64 "%n", &mx, &my, &myaw, &kind, &r, &b, &lx, &ly,
                    &when, &used) != 9 ||
        !whole() || kind > 1 || !finite({mx, my, myaw, r, b, lx, ly})) {
      why = "expected 'learned <mount x y yaw> <drive 0|1> <wheel_radius_m> <wheel_base_m> <lx_m> <ly_m> <unix_s>'";
      return false;
    }
    l = LearnedState{};
    l.lidar_mount = dockcore::Pose2{static_cast<dockcore::Real>(mx), static_cast<dockcore::Real>(my),
                                    static_cast<dockcore::Real>(myaw)};
    l.drive.kind = static_cast<dockcore::DriveKind>(kind);
    l.drive.wheel_radius_m = static_cast<dockcore::Real>(r);
    l.drive.wheel_base_m = static_cast<dockcore::Real>(b);
    l.drive.lx_m = static_cast<dockcore::Real>(lx);
    l.drive.ly_m = static_cast<dockcore::Real>(ly);
    l.saved_unix_s = when;
    return true;
  }
  if (!started) {
    why = "no 'learned' line before it";
    return false;
  }
  if (line.compare(0, 9, "deadband ") == 0) {
    unsigned raises = 0;
    double v[2 * dockcore::kMaxDriveWheels] = {};
    static_assert(dockcore::kMaxDriveWheels == 4, "the deadband line holds four wheels");
    if (std::sscanf(p, "deadband %u %lf %lf %lf %lf %lf %lf %lf %lf%n", &raises, &v[0], &v[1], &v[2], &v[3], &v[4],
                    &v[5], &v[6], &v[7], &used) != 9 ||
        !whole()) {
      why = "expected 'deadband <raises> <forward reverse rad/s> x 4 wheels'";
      return false;
    }
    for (std::size_t i = 0; i < 2 * dockcore::kMaxDriveWheels; ++i) {
      if (!std::isfinite(v[i]) || v[i] < 0 || v[i] > 1000) {
        why = "a floor not in 0-1000 rad/s";
        return false;
      }
      l.learned.deadband.radps[i / 2][i % 2] = static_cast<dockcore::Real>(v[i]);
    }
    l.learned.deadband.raises = raises;
    return true;
  }
  if (line.compare(0, 6, "mount ") == 0) {
    unsigned swings = 0, status = 0, detections = 0;
    double lat = 0, rms = 0, sweep = 0, mx = 0, my = 0, myaw = 0, sx = 0, sy = 0;
    if (std::sscanf(p, "mount %u %u %lf %lf %lf %u %lf %lf %lf %lf %lf%n", &swings, &status, &lat, &rms, &sweep,
                    &detections, &mx, &my, &myaw, &sx, &sy, &used) != 11 ||
        !whole() || status > static_cast<unsigned>(dockcore::MountCalibrationStatus::kInterrupted) ||
        detections > 65535 || !finite({lat, rms, sweep, mx, my, myaw, sx, sy}) || std::fabs(sx) > 1 ||
        std::fabs(sy) > 1) {
      why =
          "expected 'mount <swings> <status 0-6> <lateral_error_m> <rms_m> <sweep_rad> <detections> <mount x y yaw> "
          "<shift x y, |.| <= 1 m>'";
      return false;
    }
    dockcore::TaskLearned& t = l.learned.task;
    t.calibrations = swings;
    t.last_calibration.status = static_cast<dockcore::MountCalibrationStatus>(status);
    t.last_calibration.lateral_error_m = static_cast<dockcore::Real>(lat);
    t.last_calibration.rms_m = static_cast<dockcore::Real>(rms);
    t.last_calibration.sweep_rad = static_cast<dockcore::Real>(sweep);
    t.last_calibration.detections = static_cast<std::uint16_t>(detections);
    t.last_calibration.mount = dockcore::Pose2{static_cast<dockcore::Real>(mx), static_cast<dockcore::Real>(my),
                                               static_cast<dockcore::Real>(myaw)};
    t.mount_shift_m = dockcore::Vec2(static_cast<dockcore::Real>(sx), static_cast<dockcore::Real>(sy));
    return true;
  }
  if (line.compare(0, 4, "aim ") == 0) {
    unsigned id = 0;
    double aim = 0;
    if (std::sscanf(p, "aim %u %lf%n", &id, &aim, &used) != 2 || !whole() || id >= dockcore::kDockIds ||
        !std::isfinite(aim) || std::fabs(aim) > 1) {
      why = "expected 'aim <dock_id 0-" + std::to_string(dockcore::kDockIds - 1) + "> <lateral_m, |.| <= 1>'";
      return false;
    }
    l.learned.task.remembered_aim_m[id] = static_cast<dockcore::Real>(aim);
    return true;
  }
  why = "unknown line";
  return false;
}

}  // namespace

bool parse_learned(const std::string& text, LearnedState& out, std::string& error) {
  std::size_t pos = 0;
  if (!checked_body(text, &pos, error)) return false;
  std::istringstream in(text.substr(0, pos));
  std::string line;
  if (!std::getline(in, line) || line != "dockd-learned 1") {
    error = "line 1: unknown header '" + line.substr(0, 80) + "'";
    return false;
  }
  LearnedState l;
  bool started = false;
  std::size_t line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    std::string why;
    if (line.compare(0, 8, "learned ") == 0 && started) {
      why = "a second 'learned' line";
    } else if (parse_learned_line(line, started, l, why)) {
      started = true;
      continue;
    }
    error = "line " + std::to_string(line_no) + ": '" + line.substr(0, 120) + "': " + why;
    return false;
  }
  if (!started) {
    error = "no 'learned' line";
    return false;
  }
  out = l;
  return true;
}

LearnedLoadStatus load_learned(const std::string& path, LearnedState& out, std::string& message) {
  std::string text, why;
  const FileRead r = read_bounded(path, kMaxLearnedFileBytes, text, why);
  if (r == FileRead::kMissing) return LearnedLoadStatus::kMissing;
  if (r == FileRead::kOk && parse_learned(text, out, why)) return LearnedLoadStatus::kOk;
  if (r == FileRead::kUnreadable) {  // nothing to move aside
    message = path + ": " + why;
    return LearnedLoadStatus::kCorrupt;
  }
  std::rename(path.c_str(), (path + ".corrupt").c_str());
  message = path + ": " + why + "; moved to " + path + ".corrupt, learned again";
  return LearnedLoadStatus::kCorrupt;
}

LearnedPaths LearnedPaths::beside(const std::string& state_file) {
  LearnedPaths p;
  p.file = state_file + ".learned";
  p.tmp = p.file + ".tmp";
  p.dir = directory_of(p.file);
  return p;
}

bool save_learned(const LearnedPaths& paths, const LearnedState& l, char* buf, std::size_t size, char* error,
                  std::size_t error_size) {
  const std::size_t len = format_learned(l, buf, size);
  if (len == 0) {
    if (error != nullptr && error_size > 0) {
      std::snprintf(error, error_size, "cannot format %s: more than %zu bytes", paths.file.c_str(), size);
    }
    return false;
  }
  return write_synced(paths.tmp.c_str(), buf, len, error, error_size) &&
         replace_synced(paths.tmp.c_str(), paths.file.c_str(), paths.dir.c_str(), error, error_size);
}

}  // namespace dockd
