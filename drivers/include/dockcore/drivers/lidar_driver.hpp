#pragma once
/// @file Linux lidar drivers behind hal::LidarSource: serial (termios, poll-based, reconnect with backoff) and UDP
/// (bound socket). The byte decoding is core's (byte-at-a-time parsers); drivers only move bytes and stamp scans.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "dockcore/hal/lidar.hpp"
#include "dockcore/protocols/lidar/lidar_lakibeam.hpp"
#include "dockcore/protocols/lidar/lidar_ld06.hpp"
#include "dockcore/protocols/lidar/lidar_rplidar.hpp"
#include "dockcore/protocols/lidar/lidar_scan_assembler.hpp"

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
  /// UDP transport: accept datagrams only from this IPv4 address ("" = from any source). Others are dropped unread
  /// and counted (hal::LidarCounters::foreign_datagrams): another host on the sensor's network cannot inject scans.
  std::string udp_source_address;
  std::uint32_t reconnect_min_ms = 100;       ///< First reopen delay after the device vanished; doubles per failure.
  std::uint32_t reconnect_max_ms = 2000;      ///< Cap on the reopen delay.
  /// Grid of the published scans (bins per full turn); 0 = the protocol's default (LD06 450, RPLIDAR 360,
  /// Lakibeam 1440). At most kMaxScanPoints.
  std::uint32_t bins_per_turn = 0;
  /// Called with every chunk of raw bytes (serial) or every datagram (UDP) before decoding; empty = none.
  /// lidar-dump --record uses it. Called from service()/poll_scan() on the caller's thread.
  std::function<void(const std::uint8_t* data, std::size_t n)> raw_tap;
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
  /// The parser's full counters (superset of counters(): bad span, health packets, bin collisions ...).
  virtual LidarParserCounters parser_counters() const { return LidarParserCounters{}; }
  /// UDP transport: the kernel stamps each datagram's arrival (SO_TIMESTAMPNS or SO_TIMESTAMP), so a backlog in the
  /// socket keeps its arrival times; false (stamped when read) for serial or where the kernel refused both.
  virtual bool receive_stamps() const { return false; }
  /// UDP transport: the local port actually bound (useful with udp_port 0); 0 for serial.
  virtual std::uint16_t bound_port() const { return 0; }
};

/// The protocol's core parser behind one interface (used by the drivers and by lidar-dump). Owns ~130 KiB on the
/// heap, allocated once here.
class LidarDecoder {
 public:
  explicit LidarDecoder(LidarProtocol protocol);
  ~LidarDecoder();
  LidarDecoder(const LidarDecoder&) = delete;
  LidarDecoder& operator=(const LidarDecoder&) = delete;
  /// Sets bins per turn (keeps the protocol's other defaults); false when out of [1, kMaxScanPoints].
  bool configure_grid(std::uint32_t bins_per_turn);
  /// RPLIDAR only: whether nodes need a scan descriptor first (default true; false to read captures that start
  /// mid-stream).
  void set_require_descriptor(bool require);
  /// Byte-stream protocols (LD06, RPLIDAR): n bytes whose last arrived at last_byte_us; byte i is stamped
  /// last_byte_us - (n-1-i) * byte_period_us (the wire time of the bytes behind it). Returns scans completed.
  /// Lakibeam ignores this call (use feed_datagram).
  std::size_t feed_bytes(const std::uint8_t* data, std::size_t n, std::uint64_t last_byte_us,
                         std::uint32_t byte_period_us);
  /// One UDP datagram: Lakibeam parses it whole, LD06 takes its bytes. Returns scans completed.
  std::size_t feed_datagram(const std::uint8_t* data, std::size_t n, std::uint64_t stamp_us);
  /// Newest complete scan in the parser's buffer (valid until the decoder is fed again); nullptr when none is
  /// waiting.
  const LaserScan* take_scan();
  /// Forget partial packets and the turn in progress (after a reconnect); counters are kept.
  void reset();
  const LidarParserCounters& counters() const;
  LidarProtocol protocol() const { return protocol_; }

 private:
  LidarProtocol protocol_;
  std::unique_ptr<Ld06Parser> ld06_;
  std::unique_ptr<RplidarParser> rplidar_;
  std::unique_ptr<LakibeamParser> lakibeam_;
};

/// CLOCK_MONOTONIC in microseconds.
std::uint64_t monotonic_us();

/// Creates a driver and tries to open it at once. A serial device that does not exist yet is not an error (it is
/// retried by service()); bad options (unsupported baud, bad address, Lakibeam over serial) return nullptr with a
/// message in `error`.
std::unique_ptr<LidarDriver> make_lidar_driver(const LidarDriverOptions& options, std::string& error);

}  // namespace dockcore::drivers
