#pragma once
/// @file The session record: every CAN frame sent and received in candump log format
/// ("(sec.usec) iface ID#DATA", what `candump -L` writes and `canplayer` / dock-decode read), and a JSON-lines event
/// log. Each line is written with one write(2) (it survives a SIGKILL of dockd once written) and files rotate by
/// size: "<name>" → "<name>.1" → ... → "<name>.<max_files-1>", the oldest dropped. Fixed buffers after open.

#include <cstddef>
#include <cstdint>
#include <string>

#include "dockcore/hal/can_bus.hpp"
#include "dockcore/hal/log_sink.hpp"

namespace dockd {

/// One append-only log file with size rotation.
class RotatingLog final : public dockcore::hal::LogSink {
 public:
  RotatingLog() = default;
  ~RotatingLog();
  RotatingLog(const RotatingLog&) = delete;
  RotatingLog& operator=(const RotatingLog&) = delete;

  /// Opens (appends to) dir/name. False + reason when the directory or file cannot be opened.
  bool open(const std::string& dir, const std::string& name, std::uint64_t max_bytes, std::uint32_t max_files,
            std::string& error);
  bool is_open() const { return fd_ >= 0; }
  /// Appends one line (must end in '\n'); rotates first when it would exceed max_bytes. False on a write error
  /// (counted). O(len) plus a rotation's renames.
  bool write_line(const char* line, std::size_t len) override;
  std::uint32_t write_errors() const { return write_errors_; }
  std::uint32_t rotations() const { return rotations_; }
  const std::string& path() const { return path_; }

 private:
  void rotate();
  int fd_ = -1;
  std::string path_;
  std::uint64_t size_ = 0, max_bytes_ = 0;
  std::uint32_t max_files_ = 1;
  std::uint32_t write_errors_ = 0, rotations_ = 0;
};

/// Formats one frame as a candump log line "(1700000000.123456) can0 123#0102030405060708\n" (extended ids with 8
/// hex digits). Returns the length (0 if it does not fit). O(1).
std::size_t format_candump_line(char* buf, std::size_t size, std::uint64_t unix_us, const char* iface,
                                const dockcore::CanFrame& f);

/// CLOCK_REALTIME in µs (the candump log's time base).
std::uint64_t realtime_us();

/// hal::CanBus decorator: forwards to `inner` and logs every frame sent (when queued) and received. Received frames
/// are gathered and written together once the bus is drained (receive() finds no frame), before a send, or when the
/// buffer is full: one write(2) per drain instead of one per frame, so a burst of incoming frames costs the loop one
/// system call. Sent frames are written at once, so the record survives a SIGKILL up to the last frame sent.
class RecordingCanBus final : public dockcore::hal::CanBus {
 public:
  /// `inner` and `log` must outlive this object; `log` may be closed (then nothing is written).
  RecordingCanBus(dockcore::hal::CanBus& inner, RotatingLog& log, const std::string& iface);
  ~RecordingCanBus() { flush(); }
  RecordingCanBus(const RecordingCanBus&) = delete;
  RecordingCanBus& operator=(const RecordingCanBus&) = delete;
  /// Writes the gathered lines (nothing when there are none).
  void flush();
  bool send(const dockcore::CanFrame& frame) override;
  bool receive(dockcore::CanFrame& frame, std::uint64_t& stamp_us) override;
  int fd() const override { return inner_.fd(); }
  const dockcore::hal::CanBusCounters& counters() const override { return inner_.counters(); }

 private:
  void record(const dockcore::CanFrame& f);
  dockcore::hal::CanBus& inner_;
  RotatingLog& log_;
  char iface_[24];
  char pending_[8192];  ///< Received frames' lines not yet written (about 90 frames).
  std::size_t pending_len_ = 0;
};

}  // namespace dockd
