#pragma once
/// @file LDROBOT LD06 / LD19 (and the same packets carried over UDP by network models): byte-at-a-time parser that
/// assembles turns into LaserScans, and a stream encoder (emulator, tests). Layout of a measurement packet (47 bytes,
/// little-endian): 0x54 | 0x2C | speed u16 deg/s | start angle u16 0.01 deg | 12 x {distance u16 mm, intensity u8} |
/// end angle u16 0.01 deg | timestamp u16 ms (wraps at 30000) | CRC8 over bytes 0..45. Health: 0x54 0xE0 error u8
/// CRC8 (4 bytes); device info: 0x54 0x0F + 20 bytes + CRC8 (23 bytes). docs/lidars.md has the details.

#include <cstddef>
#include <cstdint>

#include "dockcore/protocols/lidar/lidar_scan_assembler.hpp"

namespace dockcore {

constexpr std::uint8_t kLd06Header = 0x54;
constexpr std::uint8_t kLd06DataKind = 0x2C;    ///< Measurement packet (low 5 bits: 12 points).
constexpr std::uint8_t kLd06HealthKind = 0xE0;  ///< Health packet.
constexpr std::uint8_t kLd06InfoKind = 0x0F;    ///< Device (manufacture) information packet.
constexpr std::size_t kLd06PacketBytes = 47;
constexpr std::size_t kLd06HealthBytes = 4;
constexpr std::size_t kLd06InfoBytes = 23;
constexpr std::size_t kLd06PointsPerPacket = 12;
constexpr std::uint32_t kLd06TimestampWrapMs = 30000;  ///< The packet timestamp counts ms modulo this.

/// CRC8 of the LD06 protocol: polynomial 0x4D, init 0, no reflection, no final xor ("123456789" -> 0xC3).
/// O(n): one lookup per byte in a 256-byte table generated at compile time.
std::uint8_t ld06_crc8(const std::uint8_t* data, std::size_t n);

/// One measurement packet's fields.
struct Ld06Packet {
  std::uint16_t speed_dps = 0;       ///< Rotation speed, deg/s.
  std::uint16_t start_cdeg = 0;      ///< Angle of point 0, 0.01 deg, sensor convention (clockwise).
  std::uint16_t end_cdeg = 0;        ///< Angle of point 11, 0.01 deg.
  std::uint16_t timestamp_ms = 0;    ///< Sensor time, ms, wraps at 30000.
  std::uint16_t distance_mm[kLd06PointsPerPacket] = {};  ///< 0 = no return.
  std::uint8_t intensity[kLd06PointsPerPacket] = {};
};

/// Writes the 47 bytes of `p` (CRC included). O(47).
void ld06_encode_packet(const Ld06Packet& p, std::uint8_t out[kLd06PacketBytes]);
/// Decodes 47 bytes; false (out untouched) when the header, kind or CRC is wrong. O(47).
bool ld06_decode_packet(const std::uint8_t in[kLd06PacketBytes], Ld06Packet& out);
/// Angle of point i (0..11) of a packet in 0.01 deg, [0, 36000): start + i * span / 11 with span = (end - start)
/// mod 36000. Exact interpolation (the vendor truncates the step to whole 0.01 deg; up to 0.11 deg off at point 11).
Real ld06_point_angle_cdeg(std::uint16_t start_cdeg, std::uint16_t end_cdeg, std::size_t i);

struct Ld06Config {
  std::uint32_t bins_per_turn = 450;  ///< Grid of the published scans (LD06 at 10 Hz measures 450 points/turn).
  Real angle_min_rad = -kPi;          ///< Core angle of bin 0.
  LidarAngleConvention convention{true, 0};  ///< LD06/LD19: clockwise, 0 deg = +x (see lidar_scan_assembler.hpp).
  Real point_rate_hz = 4500;          ///< Points per second (LD06/LD19: 4500); span check and per-point stamps.
  /// Vendor sanity check: a packet whose span exceeds span_tolerance * speed * 12 / point_rate is rejected
  /// (counted in bad_span). <= 0 disables the check.
  Real span_tolerance = static_cast<Real>(1.5);
  /// The first turn after configure()/reset() started mid-turn unless its first point is within this many degrees
  /// after 0; such a partial turn is discarded (samples_discarded) instead of published.
  Real first_turn_max_start_deg = 10;
  /// Stamp packets from the sensor's own clock (the packet timestamp, ms) mapped to host time, instead of their
  /// arrival: host = sensor + the smallest (arrival - sensor) seen. A packet that waited in a buffer behind a
  /// reader running late then keeps the time it was measured, so an old turn is not taken for a fresh one.
  bool sensor_clock = true;
  /// How fast the smallest offset may creep up (host clock running faster than the sensor's), ppm of sensor time.
  std::uint32_t sensor_clock_drift_ppm = 1000;
  /// A step in the sensor time larger than this (a stall, a restarted sensor, a timestamp going back) restarts the
  /// mapping from that packet's arrival.
  std::uint32_t sensor_clock_max_step_ms = 1000;
  /// Packets later than their mapped time by more than sensor_clock_lag_ms, continuously for sensor_clock_relock_ms
  /// of host time, restart the mapping too: a backlog drains within that time, a paused sensor clock does not.
  std::uint32_t sensor_clock_lag_ms = 100;
  std::uint32_t sensor_clock_relock_ms = 1000;
  // A timestamp that stays put for 8 packets in a row marks the clock unusable (arrival stamps until reset()).
};

/// Byte-at-a-time LD06 parser. Framing: a candidate starts at 0x54 followed by a known kind; when the packet's CRC
/// fails (or the kind is unknown) only the first byte is dropped and the rest is RESCANNED, so a truncated packet
/// costs nothing of the good packet behind it (the vendor drops all 47 bytes). A turn ends where a point's sensor
/// angle is more than 180 deg below the previous point's (the 360 -> 0 wrap, detected per point, so a packet that
/// straddles 0 deg is split exactly). Storage ~130 KiB (two LaserScans + 47-byte buffer); cost O(1) amortised per
/// byte, worst case O(47) per byte on garbage (rescan shift), plus O(bins) per published scan.
class Ld06Parser {
 public:
  /// Applies cfg and resets framing and the turn in progress (counters kept). False (nothing changed) for bins out
  /// of [1, kMaxScanPoints], a non-finite angle_min, or point_rate_hz <= 0.
  bool configure(const Ld06Config& cfg);
  /// Forgets buffered bytes (counted as dropped) and the turn in progress (samples counted as discarded); next turn
  /// is treated as a first turn. Use after a reconnect. O(bins).
  void reset();
  /// Feeds one byte that arrived at host time stamp_us (monotonic µs; used only to stamp scans). Returns true when
  /// this byte completed a scan (take_scan() then returns it). Amortised O(1).
  bool feed(std::uint8_t byte, std::uint64_t stamp_us);
  /// Feeds n bytes that all arrived at stamp_us; returns the number of scans completed. O(n).
  std::size_t feed(const std::uint8_t* data, std::size_t n, std::uint64_t stamp_us);
  /// Copies the newest complete scan into out; false (out untouched) if none is waiting. Scan stamp = host time of
  /// the turn's first point: its packet's time (sensor clock mapped to host time, or the arrival of its first byte
  /// when sensor_clock is off) minus (12 - i) point periods. O(bins).
  bool take_scan(LaserScan& out) { return out_.take(out); }
  /// The waiting scan in place (LidarScanOutput::take()): valid until the parser is fed again; nullptr when none.
  const LaserScan* take_scan() { return out_.take(); }
  bool scan_ready() const { return out_.ready(); }
  const LidarParserCounters& counters() const { return counters_; }
  std::size_t buffered() const { return len_; }          ///< Bytes held for an incomplete packet (<= 47).
  const Ld06Packet& last_packet() const { return last_; }  ///< Last accepted measurement packet.
  std::uint8_t last_health_error() const { return health_error_; }  ///< Error byte of the last health packet.
  const Ld06Config& config() const { return cfg_; }
  /// True while scans are stamped from the sensor clock (configured, synced and not found frozen).
  bool sensor_clock_active() const { return cfg_.sensor_clock && clock_valid_ && !clock_frozen_; }

 private:
  void process();
  void drop_first();
  void consume(std::size_t n);
  void on_data_packet(const Ld06Packet& p, std::uint64_t stamp_us);
  void add_point(Real sensor_deg, Real range_m, Real intensity, std::uint64_t stamp_us);
  void end_turn();
  /// Host time of a packet stamped ts_ms by the sensor that arrived at arrival_us (config sensor_clock).
  std::uint64_t map_sensor_clock(std::uint16_t ts_ms, std::uint64_t arrival_us);

  Ld06Config cfg_{};
  LidarScanOutput out_{};
  LidarParserCounters counters_{};
  Ld06Packet last_{};
  std::uint8_t buf_[kLd06PacketBytes] = {};
  std::uint64_t stamp_[kLd06PacketBytes] = {};
  std::size_t len_ = 0;
  bool synced_ = false;
  bool have_prev_ = false;
  Real prev_deg_ = 0;
  bool turn_open_ = false;       ///< A turn is being assembled.
  bool turn_from_wrap_ = false;  ///< It began at a wrap (complete), not mid-turn after start.
  Real turn_first_deg_ = 0;
  std::uint8_t health_error_ = 0;
  static constexpr std::uint32_t kFrozenClockPackets = 8;  ///< Packets in a row with one timestamp: clock unusable.
  bool clock_valid_ = false;     ///< sensor_us_/offset_us_ describe the running sensor clock.
  bool clock_frozen_ = false;    ///< The sensor's timestamp does not advance: arrival stamps until reset().
  std::uint32_t still_steps_ = 0;
  bool lagging_ = false;          ///< The last packets arrived over sensor_clock_lag_ms after their mapped time...
  std::uint64_t lag_since_us_ = 0;  ///< ...since this arrival.
  std::uint16_t prev_ts_ms_ = 0;
  std::uint64_t sensor_us_ = 0;  ///< Unwrapped sensor time of the last packet, in host microseconds at sync.
  std::int64_t offset_us_ = 0;   ///< Smallest arrival - sensor time seen (with drift allowance).
};

/// Turns scans into a continuous LD06 packet stream, the way the sensor sends it: points are taken clockwise from
/// sensor 0 deg at M = round(2 pi / |increment|) points per turn, 12 per packet; a turn's last points that do not
/// fill a packet wait for the next scan's first points (packets straddle 0 deg as on the real sensor). Points the
/// scan does not cover (a < 360 deg scan) are sent as no return. Ranges are rounded to mm (0 if invalid or
/// > 65.535 m), intensities clamped to 0..255. O(M) per scan, no state but < 12 pending points.
class Ld06StreamEncoder {
 public:
  /// convention: the lidar's (LD06 default). speed_dps is written into every packet.
  void configure(const LidarAngleConvention& convention, std::uint16_t speed_dps);
  /// Encodes one scan; writes whole packets into out (capacity cap bytes, a multiple of 47 is used). Returns the
  /// bytes written; points that did not fit are counted in points_lost(). timestamp_ms: sensor time of the scan's
  /// first point; each packet carries the time of its last point, as the sensor's do (at speed_dps, M points/turn).
  std::size_t encode_scan(const ScanView& scan, std::uint16_t timestamp_ms, std::uint8_t* out, std::size_t cap);
  std::uint32_t points_lost() const { return lost_; }

 private:
  LidarAngleConvention conv_{true, 0};
  std::uint16_t speed_dps_ = 3600;
  std::uint16_t pend_angle_[kLd06PointsPerPacket] = {};
  std::uint16_t pend_dist_[kLd06PointsPerPacket] = {};
  std::uint8_t pend_int_[kLd06PointsPerPacket] = {};
  std::size_t pending_ = 0;
  std::uint32_t lost_ = 0;
};

}  // namespace dockcore
