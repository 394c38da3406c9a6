#pragma once
/// @file HAL: an append-only record of text lines (dockd's event log, docs/dockd.md "Session record").

#include <cstddef>

namespace dockcore::hal {

class LogSink {
 public:
  /// Appends one whole line (`len` bytes, ending in '\n'). False when it could not be written (the sink counts it).
  /// Never blocks for long: a local file write at most.
  virtual bool write_line(const char* line, std::size_t len) = 0;

 protected:
  ~LogSink() = default;
};

}  // namespace dockcore::hal
