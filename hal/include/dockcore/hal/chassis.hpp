#pragma once
/// @file HAL: the link to the robot's base (SocketCAN profiles: dockcore CAN v1, AgileX V2; an in-memory fake in
/// tests). Commands go out as wheel speeds; feedback, power and status come back.

#include <cstdint>

#include "dockcore/geometry.hpp"

namespace dockcore::hal {

/// Per-wheel angular speed commands, rad/s, positive drives the robot forward. Order: left, right (differential)
/// or front-left, front-right, rear-left, rear-right (mecanum).
struct WheelCommand {
  Real radps[4] = {0, 0, 0, 0};
  std::uint8_t count = 2;
};

/// What the base reports. Each group carries the host time it was received so staleness can be judged.
struct ChassisFeedback {
  Real wheel_radps[4] = {0, 0, 0, 0};       ///< Measured wheel speeds.
  std::int32_t encoder_counts[4] = {0, 0, 0, 0};  ///< Wrapping encoder counters.
  std::uint64_t wheels_stamp_us = 0;
  Real battery_voltage_v = 0;
  Real battery_current_a = 0;  ///< Positive while charging.
  Real soc = 0;                ///< State of charge 0..1.
  bool charging_contact = false;
  std::uint64_t power_stamp_us = 0;
  bool estop = false;
  std::uint16_t fault_bits = 0;
  std::uint64_t status_stamp_us = 0;
};

struct ChassisCounters {
  std::uint32_t frames_sent = 0;
  std::uint32_t frames_received = 0;
  std::uint32_t bad_frames = 0;        ///< Wrong length, checksum or rolling counter.
  std::uint32_t send_failures = 0;     ///< ENOBUFS and friends.
  std::uint32_t bus_errors = 0;        ///< Error frames (bus-off, controller problems).
  std::uint32_t bus_off = 0;           ///< Bus-off events among bus_errors.
  std::uint32_t rx_overflows = 0;      ///< Frames the kernel dropped (SO_RXQ_OVFL).
};

class ChassisLink {
 public:
  /// Sends one wheel command (the link adds counters/checksums). Returns false when the frame could not be queued.
  virtual bool send_wheels(const WheelCommand& cmd) = 0;
  /// Requests the charger relay on/off where the base supports it.
  virtual bool request_charging(bool on) = 0;
  /// Reads everything pending, non-blocking; returns the latest feedback.
  virtual const ChassisFeedback& poll() = 0;
  virtual int fd() const = 0;
  virtual const ChassisCounters& counters() const = 0;

 protected:
  ~ChassisLink() = default;
};

}  // namespace dockcore::hal
