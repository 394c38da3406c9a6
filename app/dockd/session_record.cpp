#include "session_record.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace dockd {

RotatingLog::~RotatingLog() {
  if (fd_ >= 0) ::close(fd_);
}

bool RotatingLog::open(const std::string& dir, const std::string& name, std::uint64_t max_bytes,
                       std::uint32_t max_files, std::string& error) {
  if (::mkdir(dir.c_str(), 0755) != 0 && errno != EEXIST) {
    error = "cannot create record directory " + dir + ": " + std::strerror(errno);
    return false;
  }
  path_ = dir + "/" + name;
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    error = "cannot open " + path_ + ": " + std::strerror(errno);
    return false;
  }
  struct stat st {};
  size_ = ::fstat(fd_, &st) == 0 ? static_cast<std::uint64_t>(st.st_size) : 0;
  max_bytes_ = max_bytes;
  max_files_ = max_files < 1 ? 1 : max_files;
  return true;
}

void RotatingLog::rotate() {
  ::close(fd_);
  fd_ = -1;
  char from[512], to[512];
  if (max_files_ > 1) {
    for (std::uint32_t i = max_files_ - 1; i >= 1; --i) {
      if (i == 1) {
        std::snprintf(from, sizeof from, "%s", path_.c_str());
      } else {
        std::snprintf(from, sizeof from, "%s.%u", path_.c_str(), i - 1);
      }
      std::snprintf(to, sizeof to, "%s.%u", path_.c_str(), i);
      ::rename(from, to);
    }
  }
  // With max_files == 1 the single file is truncated: the record never exceeds max_bytes.
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND | O_CLOEXEC, 0644);
  size_ = 0;
  ++rotations_;
}

bool RotatingLog::write_line(const char* line, std::size_t len) {
  if (fd_ < 0) return false;
  if (size_ > 0 && size_ + len > max_bytes_) rotate();
  if (fd_ < 0) {
    ++write_errors_;
    return false;
  }
  const ssize_t n = ::write(fd_, line, len);
  if (n != static_cast<ssize_t>(len)) {
    ++write_errors_;
    if (n > 0) size_ += static_cast<std::uint64_t>(n);
    return false;
  }
  size_ += len;
  return true;
}

std::uint64_t realtime_us() {
  timespec ts{};
  ::clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000u + static_cast<std::uint64_t>(ts.tv_nsec) / 1000u;
}

std::size_t format_candump_line(char* buf, std::size_t size, std::uint64_t unix_us, const char* iface,
                                const dockcore::CanFrame& f) {
  static const char kHex[] = "0123456789ABCDEF";
  int n = f.extended ? std::snprintf(buf, size, "(%llu.%06llu) %s %08X#", static_cast<unsigned long long>(unix_us / 1000000u),
                                     static_cast<unsigned long long>(unix_us % 1000000u), iface, f.id & 0x1FFFFFFFu)
                     : std::snprintf(buf, size, "(%llu.%06llu) %s %03X#", static_cast<unsigned long long>(unix_us / 1000000u),
                                     static_cast<unsigned long long>(unix_us % 1000000u), iface, f.id & 0x7FFu);
  if (n < 0) return 0;
  std::size_t len = static_cast<std::size_t>(n);
  const std::size_t dlc = f.dlc > 8 ? 8u : f.dlc;
  if (len + 2 * dlc + 2 > size) return 0;
  for (std::size_t i = 0; i < dlc; ++i) {
    buf[len++] = kHex[f.data[i] >> 4];
    buf[len++] = kHex[f.data[i] & 0xF];
  }
  buf[len++] = '\n';
  buf[len] = '\0';
  return len;
}

RecordingCanBus::RecordingCanBus(dockcore::hal::CanBus& inner, RotatingLog& log, const std::string& iface)
    : inner_(inner), log_(log) {
  std::snprintf(iface_, sizeof iface_, "%s", iface.c_str());
}

void RecordingCanBus::record(const dockcore::CanFrame& f) {
  if (!log_.is_open()) return;
  char line[96];
  const std::size_t n = format_candump_line(line, sizeof line, realtime_us(), iface_, f);
  if (n == 0) return;
  if (pending_len_ + n > sizeof pending_) flush();
  std::memcpy(pending_ + pending_len_, line, n);
  pending_len_ += n;
}

void RecordingCanBus::flush() {
  if (pending_len_ == 0) return;
  log_.write_line(pending_, pending_len_);
  pending_len_ = 0;
}

bool RecordingCanBus::send(const dockcore::CanFrame& frame) {
  flush();  // the received frames before it, in order
  const bool ok = inner_.send(frame);
  if (ok) {
    record(frame);
    flush();
  }
  return ok;
}

bool RecordingCanBus::receive(dockcore::CanFrame& frame, std::uint64_t& stamp_us) {
  const bool ok = inner_.receive(frame, stamp_us);
  if (ok) {
    record(frame);
  } else {
    flush();
  }
  return ok;
}

}  // namespace dockd
