#pragma once
/// @file One classic CAN frame as core's codecs see it: no OS types, so the same codecs run on Linux (SocketCAN) and
/// on a microcontroller's CAN peripheral.

#include <cstdint>

namespace dockcore {

/// A classic CAN 2.0 data frame. `id` holds 11 bits (standard) or 29 bits (extended); flags are separate fields,
/// never packed into `id` as SocketCAN does.
struct CanFrame {
  std::uint32_t id = 0;
  bool extended = false;
  std::uint8_t dlc = 0;        ///< 0..8 data bytes.
  std::uint8_t data[8] = {0, 0, 0, 0, 0, 0, 0, 0};
};

}  // namespace dockcore
