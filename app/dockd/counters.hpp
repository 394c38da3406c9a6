#pragma once
/// @file The counters dockd keeps itself (the drivers keep theirs): the daemon's and the host protocol's.

#include <cstdint>

#include "dockcore/perception/tag_measurement.hpp"

namespace dockd {

/// Counters the daemon itself keeps (the drivers keep theirs).
struct DaemonCounters {
  std::uint32_t commands = 0;  ///< Task commands handed to the task manager.
  /// By the task manager or dockd (unknown dock id, queue full), from CAN or UDP; the status field adds the UDP
  /// link's own refusals (HostProtocol::commands_rejected_total()).
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
  std::uint32_t events_too_long = 0;          ///< Event lines that did not fit EventLine and were not written.
  /// Tag poses handed to the core, by what became of them (index: dockcore::TagStatus; kFused = fused).
  std::uint32_t tags[dockcore::kTagStatusCount] = {};
};

}  // namespace dockd
