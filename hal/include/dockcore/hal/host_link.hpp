#pragma once
/// @file HAL: the host computer's command channel and dockcore's status stream (CAN host frames, UDP JSON lines).

#include <cstdint>

#include "dockcore/geometry.hpp"

namespace dockcore::hal {

/// A command from the host. Unknown commands are reported back with a rejection code, never silently dropped.
struct HostCommandMessage {
  std::uint8_t command = 0;    ///< 1 dock, 2 cancel, 3 undock, 4 test_mode (recognition only).
  std::uint16_t dock_id = 0;
  std::uint16_t sequence = 0;  ///< Replays and out-of-order sequences are rejected.
  std::uint64_t stamp_us = 0;
};

/// What dockcore reports on every status tick.
struct StatusMessage {
  std::uint8_t task_state = 0;
  std::uint8_t align_phase = 0;
  std::uint16_t fault_code = 0;
  std::uint8_t retries = 0;
  std::uint8_t last_result = 0;  ///< CommandResult of the last host command (CAN DockStatus.LastResult).
  bool dock_valid = false;
  Pose2 dock_in_robot{};
  std::uint64_t stamp_us = 0;
};

class HostLink {
 public:
  /// Next pending command, non-blocking; false when none.
  virtual bool poll_command(HostCommandMessage& out) = 0;
  virtual bool send_status(const StatusMessage& status) = 0;
  virtual int fd() const = 0;

 protected:
  ~HostLink() = default;
};

}  // namespace dockcore::hal
