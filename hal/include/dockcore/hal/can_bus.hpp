#pragma once
/// @file HAL: a raw CAN bus (SocketCAN on Linux, an in-memory fake in tests, a CAN peripheral on an MCU). Chassis and
/// host-frame links are built on top of it, so one bus carries both.

#include <cstdint>

#include "dockcore/protocols/can/can_frame.hpp"

namespace dockcore::hal {

/// Counters every bus keeps so nothing is lost silently.
struct CanBusCounters {
  std::uint32_t frames_sent = 0;
  std::uint32_t frames_received = 0;
  std::uint32_t send_failures = 0;  ///< Frames not queued (ENOBUFS, interface down, short write).
  std::uint32_t bus_errors = 0;     ///< Error frames: bus-off, controller/protocol/transceiver problems.
  std::uint32_t bus_off = 0;        ///< Bus-off events among bus_errors.
  std::uint32_t rx_overflows = 0;   ///< Frames the receive queue dropped (SO_RXQ_OVFL on SocketCAN).
  std::uint32_t reopens = 0;        ///< Times the bus was reopened after the interface went away.
};

class CanBus {
 public:
  /// Queues one frame, non-blocking. False (counted in send_failures) when it could not be queued.
  virtual bool send(const CanFrame& frame) = 0;
  /// Next received data frame, non-blocking; false when none pending. `stamp_us`: receive time on the host's
  /// monotonic clock. Error frames are consumed and counted here, never returned.
  virtual bool receive(CanFrame& frame, std::uint64_t& stamp_us) = 0;
  /// File descriptor to wait on (epoll), or -1.
  virtual int fd() const = 0;
  virtual const CanBusCounters& counters() const = 0;

 protected:
  ~CanBus() = default;
};

}  // namespace dockcore::hal
