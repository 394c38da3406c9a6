#pragma once
/// @file HAL: time. Core takes time as an argument; the application reads it here (CLOCK_MONOTONIC on Linux, a
/// hardware timer on an MCU, a scripted clock in simulation).

#include <cstdint>

namespace dockcore::hal {

class Clock {
 public:
  /// Monotonic microseconds since an arbitrary epoch; never goes backwards.
  virtual std::uint64_t now_us() const = 0;

 protected:
  ~Clock() = default;
};

}  // namespace dockcore::hal
