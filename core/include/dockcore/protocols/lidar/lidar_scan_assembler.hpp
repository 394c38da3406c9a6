#pragma once
/// @file What every lidar parser shares: the counters (a superset of hal::LidarCounters' fields, same names), the
/// little-endian 16-bit field codec of the LD06 and Lakibeam wire formats, the angle convention conversion from a
/// sensor's own angle to core's (counter-clockwise seen from above, 0 = +x forward), and the assembler that drops
/// (angle, range, intensity) samples onto a fixed angular grid to make one LaserScan per turn. Pure core: no heap, no
/// clocks; times come in as parameters.

#include <cstddef>
#include <cstdint>

#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"

namespace dockcore {

/// The little-endian u16 at p[0..1]. O(1).
inline std::uint16_t read_le16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
/// Writes `v` little-endian to p[0..1]. O(1).
inline void write_le16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v & 0xFFu);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}

/// Counters every lidar parser keeps. The first four have hal::LidarCounters' names and meaning, so a driver copies
/// them field by field; the rest say why something was discarded. Counters only grow (u32 wrap after 2^32 events).
/// Byte accounting of the byte-stream parsers: bytes == bytes_accepted + dropped_bytes + pending bytes (buffered(),
/// at most one packet) at every moment, so no byte disappears without a counter.
struct LidarParserCounters {
  std::uint32_t scans = 0;          ///< Complete scans published (made ready for take_scan()).
  std::uint32_t crc_errors = 0;     ///< Packets whose checksum failed (LD06).
  std::uint32_t resyncs = 0;        ///< Times the parser lost packet framing (first byte dropped after a good packet).
  std::uint32_t dropped_bytes = 0;  ///< Bytes that belonged to no valid packet.
  std::uint64_t bytes = 0;          ///< Bytes fed (byte-stream parsers) or datagram bytes (Lakibeam).
  std::uint64_t bytes_accepted = 0; ///< Bytes that were part of a valid packet / descriptor / datagram.
  std::uint32_t packets = 0;        ///< Valid measurement packets (LD06 packets, RPLIDAR nodes, Lakibeam datagrams).
  std::uint32_t bad_span = 0;       ///< LD06: CRC-valid packets rejected by the angular span sanity check.
  std::uint32_t health_packets = 0; ///< LD06 0x54 0xE0 / RPLIDAR health responses recognised.
  std::uint32_t info_packets = 0;   ///< LD06 0x54 0x0F / RPLIDAR device-info responses recognised.
  std::uint32_t descriptors = 0;    ///< RPLIDAR scan response descriptors (A5 5A 05 00 00 40 81) seen.
  std::uint32_t bad_packets = 0;    ///< Lakibeam datagrams of the wrong size or with bad block / trailer markers.
  std::uint32_t samples = 0;        ///< Samples put into scans.
  std::uint32_t samples_discarded = 0; ///< Samples of a partial first turn, or before the first RPLIDAR S=1 node.
  std::uint32_t bin_collisions = 0; ///< Samples that fell into an already filled grid bin (see LidarScanAssembler).
  std::uint32_t stray_start = 0;    ///< RPLIDAR: S=1 nodes ignored (out of sequence, or the turn not swept yet).
  std::uint32_t scans_overwritten = 0; ///< A ready scan was replaced by a newer one before take_scan() read it.
  std::uint32_t clock_resyncs = 0;  ///< LD06: sensor-clock mapping restarted (step over the limit) or found frozen.
  /// RPLIDAR: the part of dropped_bytes dropped outside scan mode (no scan descriptor yet with require_descriptor):
  /// a stream joined mid-scan, echoed requests before SCAN. dropped_bytes - idle_bytes were skipped to resync.
  std::uint32_t idle_bytes = 0;
};

/// How a sensor's own angle maps to core's angle: core = zero_offset + sign * sensor, sign = -1 for clockwise
/// sensors. LD06/LD19 and RPLIDAR count clockwise seen from above (their ROS drivers reverse the array: LD06's
/// `laser_scan_dir` maps index i to n-1-i, i.e. core = -sensor; rplidar_ros publishes angle_min = pi - angle_max
/// with the data reversed, i.e. core = pi - sensor, so the RPLIDAR's 0 deg points backwards). Lakibeam1 counts
/// counter-clockwise with 0 deg pointing backwards (its ROS driver publishes azimuth 0 at angle_min = -180 deg with
/// the data in order): core = sensor - pi.
struct LidarAngleConvention {
  bool clockwise = true;   ///< True: the sensor's angle grows clockwise seen from above (the lidar's top).
  Real zero_offset_rad = 0;///< Core angle of the sensor's 0.
  /// Sensor angle (rad, any value) -> core angle (rad, not wrapped). O(1).
  Real to_core(Real sensor_rad) const { return zero_offset_rad + (clockwise ? -sensor_rad : sensor_rad); }
  /// Core angle (rad) -> sensor angle (rad) wrapped to [0, 2 pi). O(1).
  Real to_sensor(Real core_rad) const;
};

/// Wraps any finite angle to [0, 2 pi). O(1), no loops.
Real wrap_angle_positive(Real angle_rad);

/// Points per full turn of a scan's grid: round(2 pi / |angle_increment|), clamped to [1, 65535]; 1 for a zero or
/// non-finite increment. Encoders sample the sensor's turn at this density. O(1).
std::uint32_t scan_points_per_turn(const ScanView& scan);
/// The sample of `scan` nearest core angle `angle_rad` (grid lookup, wrapping at 2 pi): true with its range and
/// intensity (0 when the view has none), false when the angle falls outside the scan's samples. O(1).
bool scan_lookup(const ScanView& scan, Real angle_rad, Real* range_m, Real* intensity);

/// Turns samples into one LaserScan on a fixed grid: bin k covers angle_min + k * 2 pi / bins ± half a bin, bins
/// spanning one full turn (the scan wraps()). Several samples in one bin: a return beats a no-return, and among
/// returns the NEAREST range wins (what the LDROBOT ROS driver does: the conservative choice for obstacles); each
/// extra sample counts one bin collision. Bins no sample reached stay 0 = no return.
/// Storage: the LaserScan it builds into is its owner's (LidarScanOutput alternates two); no heap.
class LidarScanAssembler {
 public:
  /// Builds into `storage`, which must outlive the assembler. O(1).
  explicit LidarScanAssembler(LaserScan* storage) : scan_(storage) {}
  LidarScanAssembler(const LidarScanAssembler&) = delete;
  LidarScanAssembler& operator=(const LidarScanAssembler&) = delete;
  ~LidarScanAssembler() = default;
  /// Builds the next turn into `storage`, keeping the grid; the next begin() clears it. O(1).
  void retarget(LaserScan* storage) { scan_ = storage; }
  /// Sets the grid; clears the scan. bins_per_turn in [1, kMaxScanPoints], angle_min finite; false (nothing
  /// changed) otherwise. O(bins).
  bool configure(std::uint32_t bins_per_turn, Real angle_min_rad);
  /// Starts a new scan: clears every bin (O(bins)) and sets stamp_us as its stamp.
  void begin(std::uint64_t stamp_us);
  /// Adds one sample at core angle `angle_rad` (any finite value; wrapped). range_m <= 0 or non-finite = no
  /// return. Returns false (and adds nothing) for a non-finite angle. O(1).
  bool add(Real angle_rad, Real range_m, Real intensity);
  /// Grid index a core angle falls into. O(1). Precondition: finite angle.
  std::uint32_t bin_of(Real angle_rad) const;
  std::uint32_t samples() const { return samples_; }        ///< Samples added since begin().
  std::uint32_t collisions() const { return collisions_; }  ///< Bin collisions since begin().
  std::uint32_t bins() const { return bins_; }
  const LaserScan& scan() const { return *scan_; }

 private:
  LaserScan* scan_;
  std::uint32_t bins_ = 0;
  Real angle_min_rad_ = 0;
  Real increment_rad_ = 0;
  std::uint32_t samples_ = 0;
  std::uint32_t collisions_ = 0;
};

/// Double buffer the parsers share: one scan is built while the last published one waits to be read. publish()
/// hands the built scan over by swapping the two buffers, so no scan is copied on its way out of a parser.
/// Storage ~128 KiB with double (two LaserScans). Not copyable (the assembler points into it).
class LidarScanOutput {
 public:
  LidarScanOutput() : building_(&scans_[0]) {}
  LidarScanOutput(const LidarScanOutput&) = delete;
  LidarScanOutput& operator=(const LidarScanOutput&) = delete;
  ~LidarScanOutput() = default;
  bool configure(std::uint32_t bins_per_turn, Real angle_min_rad);
  LidarScanAssembler& building() { return building_; }
  const LidarScanAssembler& building() const { return building_; }
  /// Publishes the building scan (a buffer swap, plus an O(count) pass that normalises its no-return marks) and
  /// counts it in c.scans (and c.scans_overwritten if the previous one was never taken).
  void publish(LidarParserCounters& c);
  /// True when a scan is waiting for take().
  bool ready() const { return ready_; }
  /// The waiting scan, in place, and clears ready(); nullptr when none. The scan stays as it is until the parser
  /// publishes the next one: read or copy it before feeding the parser again. O(1).
  const LaserScan* take();
  /// Copies the waiting scan into out (O(count)) and clears ready(); false (out untouched) when none.
  bool take(LaserScan& out);
  /// The waiting scan (valid while ready()). O(1).
  const LaserScan& peek() const { return scans_[ready_index_]; }

 private:
  LaserScan scans_[2]{};
  LidarScanAssembler building_;
  std::size_t building_index_ = 0;
  std::size_t ready_index_ = 1;
  bool ready_ = false;
};

}  // namespace dockcore
