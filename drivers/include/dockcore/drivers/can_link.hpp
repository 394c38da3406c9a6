#pragma once
/// @file SocketCAN bus (hal::CanBus) and the chassis + host-frame link built on any hal::CanBus. One bus carries the
/// chassis profile's frames (dockcore CAN v1 or AgileX V2) and dockcore's host command / status frames
/// (docs/can.md, docs/can/dockcore.dbc). Frame encoding and checks are core's codecs.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "dockcore/control/kinematics.hpp"
#include "dockcore/hal/can_bus.hpp"
#include "dockcore/hal/chassis.hpp"
#include "dockcore/hal/host_link.hpp"

namespace dockcore::drivers {

enum class ChassisProtocol : std::uint8_t {
  kDockcoreV1 = 0,  ///< dockcore CAN protocol v1: per-wheel mm/s, rolling counter + checksum.
  kAgilexV2 = 1,    ///< AgileX protocol V2: body linear/angular, 0x421 enable, 0x111 motion.
};

/// "dockcore-v1" | "agilex-v2" → protocol; nullopt otherwise.
std::optional<ChassisProtocol> parse_chassis_protocol(std::string_view name);
const char* to_string(ChassisProtocol p);
/// Whether the chassis profile lets the host switch the charging current: dockcore v1 has the ChargeRequest relay
/// frame; AgileX has none (the dock's charger is live whenever the contacts touch). TaskParams::charger_switched.
bool switches_charger(ChassisProtocol p);

/// SocketCAN raw socket bound to one interface: filters for the given ids, error frames counted, SO_RXQ_OVFL,
/// receive timestamps, non-blocking writes (ENOBUFS counted), reopened when the interface goes down and up.
class SocketCanBus : public hal::CanBus {
 public:
  virtual ~SocketCanBus() = default;
  /// Reopens after the interface vanished or went down, with backoff. Call on every control tick.
  virtual void service(std::uint64_t now_us) = 0;
  virtual bool is_up() const = 0;
  virtual const char* last_error() const = 0;
};

/// What one SocketCAN error frame says (linux/can/error.h): the error classes in its id, the controller state in
/// data[1].
struct CanErrorReport {
  bool error_frame = false;  ///< The id has CAN_ERR_FLAG. False: a data or remote frame; nothing else is set.
  bool bus_off = false;      ///< CAN_ERR_BUSOFF: the controller has gone bus-off (counted in bus_off).
  bool restarted = false;    ///< CAN_ERR_RESTARTED: the controller is back on the bus after bus-off.
  const char* message = "";  ///< One line for last_error(), "socketcan: ..."; static storage, never null.
};

/// Decodes one received frame's raw `can_id` (flags included) and its 8 data bytes (`data` may be null: no
/// controller detail). The driver counts every error frame in bus_errors and a bus-off also in bus_off. Pure, O(1).
CanErrorReport decode_can_error_frame(std::uint32_t can_id, const std::uint8_t* data);

/// Opens `interface` (e.g. "can0", "vcan0"). Receive filter: exactly `rx_ids` (standard 11-bit ids; empty = all).
/// nullptr + message in `error` when the socket cannot be created (EAFNOSUPPORT: kernel without CAN) or the
/// interface does not exist.
std::unique_ptr<SocketCanBus> open_socketcan(const std::string& interface, const std::uint32_t* rx_ids,
                                             std::size_t rx_id_count, std::string& error);

struct CanLinkOptions {
  ChassisProtocol protocol = ChassisProtocol::kDockcoreV1;
  std::uint32_t chassis_base_id = 0x100;  ///< dockcore v1 chassis frames: base + documented offsets.
  std::uint32_t host_base_id = 0x180;     ///< Host command / dockcore status frames: base + documented offsets.
  DriveGeometry drive{};                  ///< Wheel radius / track for wheel rad/s <-> mm/s and body twist.
};

/// Chassis link and host link over one bus. poll() drains the bus: chassis frames update the feedback, host command
/// frames go to a bounded queue (overflow counted) that poll_command() empties; bad frames (length, checksum,
/// counter, unknown id in a filtered range) are counted in counters().bad_frames and change nothing else. Host command
/// frames dropped (queue full, replayed or out-of-order sequence) are counted in host_commands_rejected().
class CanLink : public hal::ChassisLink, public hal::HostLink {
 public:
  virtual ~CanLink() = default;
  /// Protocol housekeeping on every control tick (AgileX: re-send the 0x421 CAN-mode enable until feedback flows).
  virtual void service(std::uint64_t now_us) = 0;
  /// Standard ids this link wants to receive (for the SocketCAN filter). Pointer valid for the link's lifetime.
  virtual const std::uint32_t* rx_ids(std::size_t& count) const = 0;
};

/// The ids a link with `options` receives, without constructing one (the bus is opened first, then the link).
std::size_t can_link_rx_ids(const CanLinkOptions& options, std::uint32_t* out, std::size_t capacity);

/// `bus` must outlive the link.
std::unique_ptr<CanLink> make_can_link(hal::CanBus& bus, const CanLinkOptions& options);

}  // namespace dockcore::drivers
