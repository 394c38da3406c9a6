#include "dockcore/drivers/loop_record.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <type_traits>

namespace dockcore::drivers {

namespace {

constexpr char kMagic[8] = {'D', 'C', 'L', 'O', 'O', 'P', '1', '\n'};
constexpr std::size_t kBufferBytes = 256 * 1024;
constexpr std::size_t kRecordHeader = 5;  // kind + u32 length

// The structs are recorded as bytes: core's are plain data without pointers or owners (the fixed-size Eigen members
// are plain arrays, though std::is_trivially_copyable does not say so for them).
static_assert(std::is_trivially_copyable<WheelSpeeds>::value, "WheelSpeeds is recorded as bytes");
static_assert(std::is_trivially_copyable<QueuedCommand>::value, "QueuedCommand is recorded as bytes");
static_assert(std::is_trivially_copyable<TickDigest>::value, "TickDigest is recorded as bytes");

/// The layout line: a record is replayed only by a build whose structs have these sizes.
std::string layout_line() {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "layout real=%zu profile=%zu config=%zu controller=%zu tickin=%zu digest=%zu tag=%zu queued=%zu "
                "learned=%zu\n",
                sizeof(Real), sizeof(DockProfile), sizeof(DockcoreConfig), sizeof(LoopController), sizeof(TickInput),
                sizeof(TickDigest), sizeof(TagObservation), sizeof(QueuedCommand), sizeof(DockcoreBase::Learned));
  return buf;
}

/// The scan geometry a kScan record carries before its arrays.
struct ScanHeader {
  std::uint64_t stamp_us = 0;
  std::uint64_t now_us = 0;
  std::uint64_t view_stamp_us = 0;
  std::uint64_t count = 0;
  Real angle_min_rad = 0;
  Real angle_increment_rad = 0;
};

// The largest record, a full scan, fits the buffer allocated at open(): nothing is allocated while recording.
static_assert(kRecordHeader + sizeof(ScanHeader) + 2 * kMaxScanPoints * sizeof(Real) <= kBufferBytes,
              "a kMaxScanPoints scan must fit the loop record's buffer");

struct StampedWheels {
  WheelSpeeds wheels{};
  std::uint64_t stamp_us = 0;
};

struct StampedOdometry {
  Pose2 pose{};
  Twist2 twist{};
  std::uint64_t stamp_us = 0;
};

bool same_reals(const Real* a, const Real* b, std::size_t n) {
  return std::memcmp(a, b, n * sizeof(Real)) == 0;  // bit for bit: -0 and NaN payloads count
}

}  // namespace

TickDigest TickDigest::of(const TickOutput& o) {
  TickDigest d;
  for (std::size_t i = 0; i < kMaxDriveWheels; ++i) d.wheels[i] = o.wheels.radps[i];
  d.wheel_count = static_cast<std::uint32_t>(o.wheels.count);
  d.drive_cmd[0] = o.drive_cmd.vx_mps;
  d.drive_cmd[1] = o.drive_cmd.vy_mps;
  d.drive_cmd[2] = o.drive_cmd.wz_radps;
  d.cmd[0] = o.cmd.vx_mps;
  d.cmd[1] = o.cmd.vy_mps;
  d.cmd[2] = o.cmd.wz_radps;
  d.dock_pose[0] = o.status.dock_pose.x_m;
  d.dock_pose[1] = o.status.dock_pose.y_m;
  d.dock_pose[2] = o.status.dock_pose.yaw_rad;
  d.state = static_cast<std::uint8_t>(o.status.state);
  d.phase = o.status.phase;
  d.command_result = static_cast<std::uint8_t>(o.command_result);
  d.command_taken = o.command_taken ? 1 : 0;
  d.resume = static_cast<std::uint8_t>(o.resume);
  d.charge_enable = o.status.charge_enable ? 1 : 0;
  d.fault = static_cast<std::uint16_t>(o.status.fault);
  d.token = o.command.token;
  return d;
}

const char* TickDigest::first_difference(const TickDigest& a, const TickDigest& b) {
  if (a.state != b.state) return "state";
  if (a.fault != b.fault) return "fault";
  if (a.phase != b.phase) return "phase";
  if (a.command_taken != b.command_taken || a.token != b.token) return "command taken";
  if (a.command_result != b.command_result) return "command result";
  if (a.resume != b.resume) return "resume";
  if (a.charge_enable != b.charge_enable) return "charge request";
  if (a.wheel_count != b.wheel_count || !same_reals(a.wheels, b.wheels, kMaxDriveWheels)) return "wheel speeds";
  if (!same_reals(a.drive_cmd, b.drive_cmd, 3)) return "drive command";
  if (!same_reals(a.cmd, b.cmd, 3)) return "task manager twist";
  if (!same_reals(a.dock_pose, b.dock_pose, 3)) return "dock pose";
  return "";
}

LoopRecordWriter::~LoopRecordWriter() {
  flush();
  if (fd_ >= 0) ::close(fd_);
}

bool LoopRecordWriter::open(const std::string& path, std::uint64_t max_bytes, std::string& error) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    error = path + ": " + std::strerror(errno);
    return false;
  }
  if (fd_ >= 0) ::close(fd_);
  fd_ = fd;
  buf_.assign(kBufferBytes, 0);
  len_ = 0;
  written_ = 0;
  max_bytes_ = max_bytes;
  full_ = false;
  const std::string layout = layout_line();
  std::memcpy(buf_.data(), kMagic, sizeof kMagic);
  std::memcpy(buf_.data() + sizeof kMagic, layout.data(), layout.size());
  len_ = sizeof kMagic + layout.size();
  flush();
  return true;
}

void LoopRecordWriter::put(LoopRecordKind kind, const void* a, std::size_t na, const void* b, std::size_t nb,
                           const void* c, std::size_t nc) {
  if (fd_ < 0 || full_) return;
  const std::size_t n = na + nb + nc;
  if (written_ + len_ + kRecordHeader + n > max_bytes_) {
    full_ = true;
    return;
  }
  if (len_ + kRecordHeader + n > buf_.size()) flush();
  if (kRecordHeader + n > buf_.size()) {  // cannot happen for scans up to kMaxScanPoints (static_assert above)
    ++write_errors_;
    return;
  }
  unsigned char* p = buf_.data() + len_;
  p[0] = static_cast<unsigned char>(kind);
  const std::uint32_t len = static_cast<std::uint32_t>(n);
  for (int i = 0; i < 4; ++i) p[1 + i] = static_cast<unsigned char>(len >> (8 * i));
  p += kRecordHeader;
  if (na > 0) std::memcpy(p, a, na);
  if (nb > 0) std::memcpy(p + na, b, nb);
  if (nc > 0) std::memcpy(p + na + nb, c, nc);
  len_ += kRecordHeader + n;
}

void LoopRecordWriter::flush() {
  std::size_t off = 0;
  while (fd_ >= 0 && off < len_) {
    const ssize_t w = ::write(fd_, buf_.data() + off, len_ - off);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      ++write_errors_;
      break;
    }
    off += static_cast<std::size_t>(w);
  }
  written_ += off;
  len_ = 0;
}

void LoopRecordWriter::configure(const LoopController& ctl, const DockProfile& profile, const DockcoreConfig& config) {
  put(LoopRecordKind::kConfigure, &ctl, sizeof ctl, &profile, sizeof profile, &config, sizeof config);
}

void LoopRecordWriter::wheels(const WheelSpeeds& w, std::uint64_t stamp_us) {
  StampedWheels s;
  s.wheels = w;
  s.stamp_us = stamp_us;
  put(LoopRecordKind::kWheels, &s, sizeof s);
}

void LoopRecordWriter::odometry(const Pose2& pose, const Twist2& twist, std::uint64_t stamp_us) {
  StampedOdometry s;
  s.pose = pose;
  s.twist = twist;
  s.stamp_us = stamp_us;
  put(LoopRecordKind::kOdometry, &s, sizeof s);
}

void LoopRecordWriter::scan(const ScanView& scan, std::uint64_t stamp_us, std::uint64_t now_us) {
  ScanHeader h;
  h.stamp_us = stamp_us;
  h.now_us = now_us;
  h.view_stamp_us = scan.stamp_us;
  h.count = scan.ranges_m != nullptr ? scan.count : 0;
  h.angle_min_rad = scan.angle_min_rad;
  h.angle_increment_rad = scan.angle_increment_rad;
  const std::size_t n = static_cast<std::size_t>(h.count) * sizeof(Real);
  // Missing intensities are recorded as none (count 0 would lose the ranges): the core reads them as zeros.
  if (scan.intensities != nullptr) {
    put(LoopRecordKind::kScan, &h, sizeof h, scan.ranges_m, n, scan.intensities, n);
  } else {
    put(LoopRecordKind::kScan, &h, sizeof h, scan.ranges_m, n);
  }
}

void LoopRecordWriter::tag(const TagObservation& obs) {
  put(LoopRecordKind::kTag, &obs, sizeof obs);
}

void LoopRecordWriter::submit(const QueuedCommand& c) {
  put(LoopRecordKind::kSubmit, &c, sizeof c);
}

void LoopRecordWriter::check_inputs(std::uint64_t now_us) {
  put(LoopRecordKind::kCheckInputs, &now_us, sizeof now_us);
}

void LoopRecordWriter::tick(const TickInput& in, const TickOutput& out) {
  const TickDigest d = TickDigest::of(out);
  put(LoopRecordKind::kTick, &in, sizeof in, &d, sizeof d);
}

void LoopRecordWriter::rescan() {
  put(LoopRecordKind::kRescan, nullptr, 0);
}

void LoopRecordWriter::take_inputs() {
  put(LoopRecordKind::kTakeInputs, nullptr, 0);
}

void LoopRecordWriter::restore_learned(const DockcoreBase::Learned& learned) {
  put(LoopRecordKind::kRestoreLearned, &learned, sizeof learned);
}

// --- replay --------------------------------------------------------------------------------------------------------

namespace {

/// A core and its controllers, built from a configure record's parameters.
struct ReplayCore {
  explicit ReplayCore(const LoopController& c) : controllers(c.seed000, c.seed004, c.seed003, c.smooth) {}
  ControllerSet controllers;
  std::unique_ptr<BreakpointDetector> breakpoint;  ///< For docks configured with DockDetector::kBreakpoint.
  std::unique_ptr<Dockcore> core;
};

template <typename T>
bool read_as(const std::vector<unsigned char>& p, std::size_t off, T* out) {
  if (off + sizeof(T) > p.size()) return false;
  std::memcpy(static_cast<void*>(out), p.data() + off, sizeof(T));
  return true;
}

}  // namespace

ReplayResult replay_loop_record(const std::string& path) {
  ReplayResult r;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) {
    r.error = path + ": " + std::strerror(errno);
    return r;
  }
  std::uint64_t offset = 0;
  auto fail = [&](const std::string& why) {
    r.error = path + ": offset " + std::to_string(offset) + ": " + why;
    return r;
  };
  char magic[sizeof kMagic];
  if (std::fread(magic, 1, sizeof magic, f.get()) != sizeof magic || std::memcmp(magic, kMagic, sizeof magic) != 0) {
    return fail("not a dockcore loop record (magic DCLOOP1 missing)");
  }
  offset = sizeof kMagic;
  std::string layout;
  for (int ch; (ch = std::fgetc(f.get())) != EOF;) {
    layout.push_back(static_cast<char>(ch));
    if (ch == '\n' || layout.size() > 512) break;
  }
  if (layout != layout_line()) {
    return fail("recorded by a build with another layout: the record has \"" +
                layout.substr(0, layout.size() - (layout.empty() ? 0 : 1)) + "\", this build \"" +
                layout_line().substr(0, layout_line().size() - 1) +
                "\" (replay with the same dockcore version, Real "
                "type and ABI)");
  }
  offset += layout.size();

  std::unique_ptr<ReplayCore> rc;
  bool rebuild = false;
  std::vector<unsigned char> p;
  std::vector<Real> ranges, intensities;
  for (;;) {
    unsigned char h[kRecordHeader];
    const std::size_t got = std::fread(h, 1, sizeof h, f.get());
    if (got == 0) break;
    if (got != sizeof h) {
      r.truncated = true;
      break;
    }
    std::uint32_t len = 0;
    for (int i = 0; i < 4; ++i) len |= static_cast<std::uint32_t>(h[1 + i]) << (8 * i);
    if (len > (64u << 20)) return fail("record length " + std::to_string(len) + " is not plausible");
    p.resize(len);
    if (len > 0 && std::fread(p.data(), 1, len, f.get()) != len) {
      r.truncated = true;
      break;
    }
    const LoopRecordKind kind = static_cast<LoopRecordKind>(h[0]);
    if (kind != LoopRecordKind::kConfigure && kind != LoopRecordKind::kTakeInputs && !rc) {
      return fail("a call before the first configure");
    }
    switch (kind) {
      case LoopRecordKind::kConfigure: {
        LoopController ctl;
        DockProfile profile;
        DockcoreConfig config;
        if (len != sizeof ctl + sizeof profile + sizeof config) return fail("configure record of the wrong size");
        read_as(p, 0, &ctl);
        read_as(p, sizeof ctl, &profile);
        read_as(p, sizeof ctl + sizeof profile, &config);
        if (!rc || rebuild) {
          auto next = std::make_unique<ReplayCore>(ctl);
          const std::string name(ctl.name, strnlen(ctl.name, sizeof ctl.name));
          DockingController* const driven = next->controllers.by_name(name.c_str());
          if (driven == nullptr) return fail("unknown controller '" + name + "'");
          next->core = std::make_unique<Dockcore>(*driven);
          if (rc) next->core->take_inputs(*rc->core);
          rc = std::move(next);
          rebuild = false;
        }
        if (config.detector == DockDetector::kBreakpoint && !rc->breakpoint) {
          rc->breakpoint = std::make_unique<BreakpointDetector>();
          rc->core->attach_breakpoint(rc->breakpoint.get());
        }
        rc->core->configure(profile, config);
        break;
      }
      case LoopRecordKind::kTakeInputs:
        rebuild = true;
        break;
      case LoopRecordKind::kWheels: {
        StampedWheels s;
        if (len != sizeof s) return fail("wheels record of the wrong size");
        read_as(p, 0, &s);
        rc->core->on_wheels(s.wheels, s.stamp_us);
        break;
      }
      case LoopRecordKind::kOdometry: {
        StampedOdometry s;
        if (len != sizeof s) return fail("odometry record of the wrong size");
        read_as(p, 0, &s);
        rc->core->on_odometry(s.pose, s.twist, s.stamp_us);
        break;
      }
      case LoopRecordKind::kScan: {
        ScanHeader sh;
        if (!read_as(p, 0, &sh)) return fail("scan record too short");
        if (sh.count > len / sizeof(Real)) return fail("scan record with more beams than bytes");
        const std::size_t count = static_cast<std::size_t>(sh.count);
        const std::size_t n = count * sizeof(Real);
        const bool with_intensities = len == sizeof sh + 2 * n;
        if (len != sizeof sh + n && !with_intensities) return fail("scan record of the wrong size");
        ranges.resize(count);
        intensities.assign(count, 0);
        if (n > 0) std::memcpy(ranges.data(), p.data() + sizeof sh, n);
        if (with_intensities && n > 0) std::memcpy(intensities.data(), p.data() + sizeof sh + n, n);
        ScanView v{ranges.data(),
                   with_intensities ? intensities.data() : nullptr,
                   count,
                   sh.angle_min_rad,
                   sh.angle_increment_rad,
                   sh.view_stamp_us};
        rc->core->on_scan(v, sh.stamp_us, sh.now_us);
        ++r.scans;
        break;
      }
      case LoopRecordKind::kTag: {
        TagObservation o;
        if (len != sizeof o) return fail("tag record of the wrong size");
        read_as(p, 0, &o);
        rc->core->on_tag(o);
        break;
      }
      case LoopRecordKind::kSubmit: {
        QueuedCommand c;
        if (len != sizeof c) return fail("submit record of the wrong size");
        read_as(p, 0, &c);
        rc->core->submit(c);
        ++r.commands;
        break;
      }
      case LoopRecordKind::kCheckInputs: {
        std::uint64_t now = 0;
        if (len != sizeof now) return fail("check_inputs record of the wrong size");
        read_as(p, 0, &now);
        rc->core->check_inputs(now);
        break;
      }
      case LoopRecordKind::kTick: {
        TickInput in;
        TickDigest want;
        if (len != sizeof in + sizeof want) return fail("tick record of the wrong size");
        read_as(p, 0, &in);
        read_as(p, sizeof in, &want);
        const TickDigest got_d = TickDigest::of(rc->core->tick(in));
        const char* diff = TickDigest::first_difference(want, got_d);
        if (diff[0] != '\0') {
          r.diverged = true;
          r.diverged_tick = r.ticks;
          r.diverged_now_us = in.now_us;
          r.diverged_field = diff;
          r.recorded = want;
          r.replayed = got_d;
          return r;
        }
        ++r.ticks;
        break;
      }
      case LoopRecordKind::kRescan:
        rc->core->rescan();
        break;
      case LoopRecordKind::kRestoreLearned: {
        DockcoreBase::Learned learned;
        if (len != sizeof learned) return fail("restore-learned record of the wrong size");
        read_as(p, 0, &learned);
        rc->core->restore_learned(learned);
        break;
      }
      default:
        return fail("unknown record kind " + std::to_string(static_cast<unsigned>(h[0])));
    }
    offset += sizeof h + len;
    ++r.records;
  }
  r.ok = true;
  return r;
}

}  // namespace dockcore::drivers
