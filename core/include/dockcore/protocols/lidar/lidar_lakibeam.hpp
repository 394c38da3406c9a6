#pragma once
/// @file Richbeam Lakibeam1 UDP datagrams: parser (one datagram at a time) assembling turns into LaserScans, and an
/// encoder of scans into datagrams (emulator, tests). Datagram, 1206 bytes little-endian: 12 blocks of
/// {0xFF 0xEE, azimuth u16 0.01 deg, 16 x {dist1 u16 mm, rssi1 u8, dist2 u16 mm, rssi2 u8}} (100 bytes each), then
/// timestamp u32 and the factory bytes 0x40 0x37.

#include <cstddef>
#include <cstdint>

#include "dockcore/protocols/lidar/lidar_scan_assembler.hpp"

namespace dockcore {

constexpr std::size_t kLakibeamDatagramBytes = 1206;
constexpr std::size_t kLakibeamBlocks = 12;
constexpr std::size_t kLakibeamPointsPerBlock = 16;
constexpr std::size_t kLakibeamBlockBytes = 100;
constexpr std::size_t kLakibeamPointsPerDatagram = kLakibeamBlocks * kLakibeamPointsPerBlock;

struct LakibeamConfig {
  std::uint32_t bins_per_turn = 1440;  ///< 0.25 deg grid (Lakibeam1 resolution is configurable 0.1..0.5 deg).
  Real angle_min_rad = -kPi;
  /// Counter-clockwise, sensor 0 deg = core -pi (the ROS driver puts azimuth 0 at angle_min = -180 deg).
  LidarAngleConvention convention{false, -kPi};
  /// The first turn after configure()/reset() is discarded unless it starts within this many degrees after 0.
  Real first_turn_max_start_deg = 2;
};

/// Lakibeam parser. Each datagram is checked whole (size 1206, every block marker FF EE, trailer 40 37, azimuths
/// < 36000) and rejected whole (bad_packets, its bytes dropped_bytes) on any failure; the SDK drops wrong sizes too.
/// Point k of block b lies at az_b + k * ((az_{b+1} - az_b) mod 36000) / 16, the last block reusing the previous
/// step. The first echo (dist1, rssi1) is used; the second echo is ignored. A turn ends where the azimuth falls by
/// more than 180 deg. Storage ~130 KiB; O(192) per datagram plus O(bins) per published scan.
class LakibeamParser {
 public:
  bool configure(const LakibeamConfig& cfg);
  /// Forgets the turn in progress (its samples counted as discarded). O(1).
  void reset();
  /// Parses one datagram received at host time stamp_us; returns the number of scans completed by it (0..2).
  std::size_t feed_datagram(const std::uint8_t* data, std::size_t n, std::uint64_t stamp_us);
  /// Newest complete scan (stamp: arrival of the datagram holding its first point); false if none waiting.
  bool take_scan(LaserScan& out) { return out_.take(out); }
  /// The waiting scan in place (LidarScanOutput::take()): valid until the parser is fed again; nullptr when none.
  const LaserScan* take_scan() { return out_.take(); }
  bool scan_ready() const { return out_.ready(); }
  const LidarParserCounters& counters() const { return counters_; }
  std::uint32_t last_timestamp() const { return last_timestamp_; }  ///< Sensor timestamp of the last good datagram.
  const LakibeamConfig& config() const { return cfg_; }

 private:
  void add_point(Real sensor_deg, Real range_m, Real intensity, std::uint64_t stamp_us);
  LakibeamConfig cfg_{};
  LidarScanOutput out_{};
  LidarParserCounters counters_{};
  bool have_prev_ = false;
  Real prev_deg_ = 0;
  bool turn_open_ = false;
  bool turn_from_wrap_ = false;
  Real turn_first_deg_ = 0;
  std::uint32_t last_timestamp_ = 0;
};

/// Encodes scans as Lakibeam datagrams: M = round(2 pi / |increment|) points per turn counter-clockwise from sensor
/// 0 deg, 192 per datagram, points of an unfinished datagram carried to the next scan (as the sensor streams).
/// dist2/rssi2 carry a copy of the first echo. O(M) per scan.
class LakibeamEncoder {
 public:
  void configure(const LidarAngleConvention& convention) {
    conv_ = convention;
    pending_ = 0;
  }
  /// Calls emit(datagram, 1206, user) for every complete datagram. Returns the number emitted.
  std::size_t encode_scan(const ScanView& scan, std::uint32_t timestamp,
                          void (*emit)(const std::uint8_t* datagram, std::size_t n, void* user), void* user);

 private:
  LidarAngleConvention conv_{false, -kPi};
  std::uint8_t dgram_[kLakibeamDatagramBytes] = {};
  std::size_t pending_ = 0;
};

}  // namespace dockcore
