#pragma once
/// @file Linux lidar drivers behind hal::LidarSource: serial (termios, poll-based, reconnect with backoff) and UDP
/// (bound socket). The byte decoding is core's (byte-at-a-time parsers); drivers only move bytes and stamp scans.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "dockcore/hal/lidar.hpp"

namespace dockcore::drivers {

/// Wire protocols a driver can decode.
enum class LidarProtocol : std::uint8_t {
  kLd06 = 0,      ///< LDROBOT LD06/LD19 47-byte packets (serial 230400, or carried over UDP).
  kRplidar = 1,   ///< Slamtec RPLIDAR A1/A2 legacy standard scan (serial 115200/256000).
  kLakibeam = 2,  ///< Richbeam Lakibeam1 1206-byte UDP datagrams.
};

enum class LidarTransport : std::uint8_t { kSerial = 0, kUdp = 1 };

/// "ld06" | "rplidar" | "lakibeam" → protocol; nullopt for anything else.
std::optional<LidarProtocol> parse_lidar_protocol(std::string_view name);
const char* to_string(LidarProtocol p);

struct LidarDriverOptions {
  LidarProtocol protocol = LidarProtocol::kLd06;
  LidarTransport transport = LidarTransport::kSerial;
  std::string device = "/dev/ttyUSB0";        ///< Serial device path (serial transport).
  std::uint32_t baud = 230400;                ///< Serial baud rate; must be a rate termios supports.
  std::string udp_bind_address = "0.0.0.0";   ///< UDP transport: local address to bind.
  std::uint16_t udp_port = 2368;              ///< UDP transport: local port to bind.
  std::uint32_t reconnect_min_ms = 100;       ///< First reopen delay after the device vanished; doubles per failure.
  std::uint32_t reconnect_max_ms = 2000;      ///< Cap on the reopen delay.
};

/// A lidar source with the Linux-side lifecycle dockd needs on top of hal::LidarSource.
class LidarDriver : public hal::LidarSource {
 public:
  virtual ~LidarDriver() = default;
  /// Reads whatever is pending without blocking (poll_scan also does), reopens a vanished device once its backoff
  /// expires, and sends protocol start requests (RPLIDAR SCAN) after a (re)open. Call on every control tick.
  /// `now_us`: CLOCK_MONOTONIC microseconds. fd() may change after a reopen (-1 while closed).
  virtual void service(std::uint64_t now_us) = 0;
  virtual bool connected() const = 0;
  /// Human-readable reason of the last open/read failure ("" when none). Never null.
  virtual const char* last_error() const = 0;
};

/// Creates a driver and tries to open it at once. A serial device that does not exist yet is not an error (it is
/// retried by service()); bad options (unsupported baud, bad address, Lakibeam over serial) return nullptr with a
/// message in `error`.
std::unique_ptr<LidarDriver> make_lidar_driver(const LidarDriverOptions& options, std::string& error);

}  // namespace dockcore::drivers
