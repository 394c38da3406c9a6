#pragma once
/// @file The counters dockd keeps itself (the drivers keep theirs): the daemon's and the host protocol's.

#include <cstdint>

#include "dockcore/perception/tag_measurement.hpp"

namespace dockd {

/// What the host protocol counts of the UDP request datagrams (the link counts the datagrams, replies and
/// subscribers).
struct UdpRequestCounters {
  std::uint32_t requests = 0;  ///< Parsed and answered or handed on (subscriptions included).
  std::uint32_t malformed = 0;
  std::uint32_t unknown_command = 0;
  std::uint32_t bad_field = 0;
  std::uint32_t too_long = 0;
  /// Parsed, then refused with an error reply: unknown dock id, queue full, the task manager, teach.
  std::uint32_t rejected_later = 0;

  /// Datagrams refused because they did not parse (malformed, unknown command, bad field, too long). O(1).
  std::uint32_t refused() const { return malformed + unknown_command + bad_field + too_long; }
};

/// Counters the daemon itself keeps (the drivers keep theirs).
struct DaemonCounters {
  std::uint32_t commands = 0;  ///< Task commands handed to the task manager.
  /// By the task manager or dockd (unknown dock id, queue full), from CAN or UDP; the status field adds the UDP
  /// datagrams that did not parse (HostProtocol::commands_rejected_total()).
  std::uint32_t commands_rejected = 0;
  std::uint32_t queue_overflows = 0;
  std::uint32_t scans = 0;
  std::uint32_t detections = 0;
  std::uint32_t camera_stalls = 0;  ///< Times the own camera went [camera.device] stall_ms without a frame.
  std::uint32_t resumes = 0;
  std::uint32_t wheel_send_failures = 0;
  std::uint32_t status_sent = 0;
  std::uint32_t config_reloads = 0;           ///< Reloads applied.
  std::uint32_t config_reloads_rejected = 0;  ///< Reloads refused (invalid file, restart-only key changed).
  std::uint32_t learned_saves = 0;            ///< Learned files written (a task's end changed what was learned).
  std::uint32_t learned_save_failures = 0;    ///< ... and writes that failed (reported; tried again at the next end).
  std::uint32_t events_too_long = 0;          ///< Event lines that did not fit EventLine and were not written.
  /// UDP replies and status stream objects that did not fit one datagram: a reply_too_long error went instead.
  std::uint32_t replies_too_long = 0;
  /// Tag poses handed to the core, by what became of them (index: dockcore::TagStatus; kFused = fused).
  std::uint32_t tags[dockcore::kTagStatusCount] = {};
  UdpRequestCounters udp{};  ///< The UDP request datagrams, by what became of them.
};

}  // namespace dockd
