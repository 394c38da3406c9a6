#pragma once
/// @file dockd's event lines (the session record's events.jsonl, docs/dockd.md "Session record"): the line being
/// written and the rate limit on refusal events.

#include <cstdint>

#include "json_writer.hpp"

namespace dockd {

/// At most kPerWindow events of one kind per kWindowUs reach the record and stderr; the rest are held back and
/// counted. A host flooding refused requests would otherwise make every request a write(2) or two (on flash, wear
/// too) and starve the control loop; the request counters still count every one. Cost: O(1), no allocation.
class EventRateLimit {
 public:
  static constexpr std::uint32_t kPerWindow = 20;
  static constexpr std::uint64_t kWindowUs = 1000000;
  /// True when an event at now_us (monotonic, µs) may be logged; false: it is held back and counted.
  bool admit(std::uint64_t now_us) {
    roll(now_us);
    if (logged_ < kPerWindow) {
      ++logged_;
      return true;
    }
    ++held_;
    return false;
  }
  /// Events held back in windows that have ended by now_us, each reported once (0 while the window runs).
  std::uint32_t take_held(std::uint64_t now_us) {
    roll(now_us);
    const std::uint32_t n = ready_;
    ready_ = 0;
    return n;
  }

 private:
  void roll(std::uint64_t now_us) {
    if (now_us - window_start_us_ < kWindowUs) return;  // windows start at 0 or at the first event after one ended
    window_start_us_ = now_us;
    logged_ = 0;
    ready_ += held_;
    held_ = 0;
  }
  std::uint64_t window_start_us_ = 0;
  std::uint32_t logged_ = 0;
  std::uint32_t held_ = 0;   ///< In the running window.
  std::uint32_t ready_ = 0;  ///< From ended windows, not yet reported.
};

/// One event line being written: {"t_us":…,"event":"name", then the fields added to `w`}; Daemon::log_event
/// finishes and writes it. 1.5 KiB on the stack.
struct EventLine {
  EventLine(std::uint64_t t_us, const char* name) : w(buf, sizeof buf) { w.uint("t_us", t_us).str("event", name); }
  EventLine(const EventLine&) = delete;
  EventLine& operator=(const EventLine&) = delete;
  char buf[1536];
  JsonWriter w;
};

}  // namespace dockd
