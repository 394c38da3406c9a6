#pragma once
/// @file Slamtec RPLIDAR A1/A2, legacy standard scan: request encoders, a byte-at-a-time parser for response
/// descriptors, health / device-info responses and 5-byte measurement nodes, and an encoder of scans as the sensor
/// streams them (emulator, tests). Layouts in docs/lidars.md.

#include <cstddef>
#include <cstdint>

#include "dockcore/protocols/lidar/lidar_scan_assembler.hpp"

namespace dockcore {

constexpr std::uint8_t kRplidarSync = 0xA5;
constexpr std::uint8_t kRplidarSync2 = 0x5A;
constexpr std::uint8_t kRplidarCmdStop = 0x25;
constexpr std::uint8_t kRplidarCmdScan = 0x20;
constexpr std::uint8_t kRplidarCmdReset = 0x40;
constexpr std::uint8_t kRplidarCmdGetInfo = 0x50;
constexpr std::uint8_t kRplidarCmdGetHealth = 0x52;
constexpr std::size_t kRplidarDescriptorBytes = 7;
constexpr std::size_t kRplidarNodeBytes = 5;
constexpr std::size_t kRplidarHealthBytes = 3;   ///< Health payload: status u8, error code u16.
constexpr std::size_t kRplidarInfoBytes = 20;    ///< Info payload: model, firmware u16, hardware, serial[16].
/// The standard scan's response descriptor: size 5, mode 1 (multiple responses), type 0x81.
constexpr std::uint8_t kRplidarScanDescriptor[kRplidarDescriptorBytes] = {0xA5, 0x5A, 0x05, 0x00, 0x00, 0x40, 0x81};
constexpr std::uint8_t kRplidarHealthDescriptor[kRplidarDescriptorBytes] = {0xA5, 0x5A, 0x03, 0x00, 0x00, 0x00, 0x06};
constexpr std::uint8_t kRplidarInfoDescriptor[kRplidarDescriptorBytes] = {0xA5, 0x5A, 0x14, 0x00, 0x00, 0x00, 0x04};

/// Writes the request for `cmd` (0xA5 cmd; these commands carry no payload). Returns 2. O(1).
std::size_t rplidar_encode_request(std::uint8_t cmd, std::uint8_t out[2]);

/// One measurement node's fields.
struct RplidarNode {
  bool start = false;            ///< S: first node of a new turn.
  std::uint8_t quality = 0;      ///< 0..63.
  std::uint16_t angle_q6 = 0;    ///< Sensor angle, 1/64 deg (clockwise), 0..23039 in practice (15 bits).
  std::uint16_t distance_q2 = 0; ///< Range, 1/4 mm; 0 = no return.
};
/// Encodes a node (S / !S, check bit set). O(1).
void rplidar_encode_node(const RplidarNode& n, std::uint8_t out[kRplidarNodeBytes]);
/// Decodes 5 bytes; false when S == !S or the check bit is 0 (the only integrity checks this mode has). O(1).
bool rplidar_decode_node(const std::uint8_t in[kRplidarNodeBytes], RplidarNode& out);

/// Health response payload.
struct RplidarHealth {
  std::uint8_t status = 0;       ///< 0 good, 1 warning, 2 error.
  std::uint16_t error_code = 0;
};

struct RplidarConfig {
  std::uint32_t bins_per_turn = 360;  ///< A1: ~360 nodes per turn at 5.5 Hz.
  Real angle_min_rad = -kPi;
  LidarAngleConvention convention{true, kPi};  ///< Clockwise, sensor 0 deg = core pi (backwards), see assembler.
  /// Nodes are accepted only after a scan descriptor (the vendor SDK's rule: a mid-stream start is ambiguous).
  /// false: nodes are accepted at once (reading a capture that starts mid-stream).
  bool require_descriptor = true;
};

/// A node is "in sequence" when its angle is within this many 1/64 deg of the previous node's (either way, wrapped
/// at 360 deg). A real A1/A2 steps ~1 deg per node; a misaligned node decoded after corruption lands anywhere. 20 deg:
/// streams need >= 18 nodes per turn.
constexpr std::uint16_t kRplidarMaxNodeStepQ6 = 20u * 64u;
/// An S=1 node ends the turn in progress only once that turn has swept at least this angle (1/64 deg; the sum of its
/// in-sequence node steps). 270 deg: a complete turn sweeps ~358 deg, so up to 88 deg lost to corruption still count.
constexpr std::int32_t kRplidarMinTurnSweepQ6 = 270 * 64;

/// Byte-at-a-time RPLIDAR parser. At every position it tries, in order: a known 7-byte response descriptor (scan,
/// health, info; health and info are followed by their payload), then — once a scan descriptor was seen — a 5-byte
/// node passing the S/!S and check-bit tests, unless a known descriptor starts inside those 5 bytes (its 7 exact
/// bytes outweigh a node's 3 check bits: a relay's echoed requests misalign nodes right before a response; the node
/// waits until the overlap is decided, at most 6 bytes). When neither fits, the first byte is dropped and the rest
/// rescanned (counted: dropped_bytes, idle_bytes outside scan mode, and resyncs when the stream had been in sync).
///
/// Turns (what Slamtec's SDK does, plus a guard for a stray S): the S=1 node starts a turn. It ends the turn in
/// progress when it is in sequence with the previous node (kRplidarMaxNodeStepQ6) and that turn has swept at least
/// kRplidarMinTurnSweepQ6; the S node's own angle does not matter (real A1 captures report 350..359 deg; encoder: 0).
/// Any other S=1 node while a turn is open is stray — a misaligned node after corruption, or the echo of a STOP
/// request (A5 25) read as a node — and is counted (stray_start) and not used: no split, no sample. Every node
/// belongs to the turn open when it arrives: the S node and the nodes after it go into the new turn, each in the bin
/// of its own angle (so a node at 358 deg before an S at 359 deg stays in the old turn's bin for 358 deg, and the
/// S node at 359 deg fills the new turn's bin for 359 deg). Nodes before the first turn start after configure(),
/// reset() or a scan descriptor are discarded (samples_discarded), as is a turn open when a scan descriptor arrives.
/// Counters: packets = nodes decoded = samples + stray_start + nodes discarded before a turn start.
///
/// Storage ~130 KiB; O(1) amortised per byte, worst case O(27) per byte on garbage, plus O(bins) per published scan.
/// No checksum exists in this mode, so corrupted node bytes that still pass the bit tests are decoded: the grid keeps
/// the nearest return per bin.
class RplidarParser {
 public:
  /// False (nothing changed) for bins outside [1, kMaxScanPoints] or a non-finite angle_min.
  bool configure(const RplidarConfig& cfg);
  /// Forgets buffered bytes (dropped), the turn in progress and the descriptor state. Use after a reconnect.
  void reset();
  /// Feeds one byte received at host time stamp_us; true when it completed a scan. Amortised O(1).
  bool feed(std::uint8_t byte, std::uint64_t stamp_us);
  std::size_t feed(const std::uint8_t* data, std::size_t n, std::uint64_t stamp_us);
  /// Newest complete scan (stamp: arrival of the first byte of the turn's S=1 node); false if none waiting.
  bool take_scan(LaserScan& out) { return out_.take(out); }
  /// The waiting scan in place (LidarScanOutput::take()): valid until the parser is fed again; nullptr when none.
  const LaserScan* take_scan() { return out_.take(); }
  bool scan_ready() const { return out_.ready(); }
  const LidarParserCounters& counters() const { return counters_; }
  std::size_t buffered() const { return len_; }
  bool in_scan_mode() const { return scanning_; }  ///< A scan descriptor was seen since configure()/reset().
  const RplidarHealth& last_health() const { return health_; }
  const RplidarConfig& config() const { return cfg_; }

 private:
  static constexpr std::size_t kBufBytes = kRplidarDescriptorBytes + kRplidarInfoBytes;
  void process();
  void drop_first();
  void consume(std::size_t n);
  void on_node(const RplidarNode& n, std::uint64_t stamp_us);

  RplidarConfig cfg_{};
  LidarScanOutput out_{};
  LidarParserCounters counters_{};
  RplidarHealth health_{};
  std::uint8_t buf_[kBufBytes] = {};
  std::uint64_t stamp_[kBufBytes] = {};
  std::size_t len_ = 0;
  bool synced_ = false;
  bool scanning_ = false;
  bool turn_open_ = false;
  bool have_last_ = false;     ///< last_q6_ holds a node of this scan session.
  std::uint16_t last_q6_ = 0;  ///< Angle of the previous node (stray S nodes excluded).
  std::int32_t sweep_q6_ = 0;  ///< Sum of the in-sequence node steps of the turn in progress.
};

/// Where the bytes fed to an RplidarParser went, from its counters: every byte is in exactly one field.
struct RplidarByteAccount {
  std::uint64_t node_bytes = 0;        ///< 5 per decoded node (packets).
  std::uint64_t descriptor_bytes = 0;  ///< 7 per scan descriptor.
  std::uint64_t response_bytes = 0;    ///< Health (10) and device-info (27) responses, their descriptors included.
  std::uint64_t resync_bytes = 0;      ///< Dropped in scan mode to regain framing, or flushed by reset().
  std::uint64_t idle_bytes = 0;        ///< Dropped outside scan mode (before a scan descriptor).
  std::uint64_t pending_bytes = 0;     ///< Buffered, not decided yet (RplidarParser::buffered()).
  /// Sum of all fields; equals LidarParserCounters::bytes.
  std::uint64_t total() const {
    return node_bytes + descriptor_bytes + response_bytes + resync_bytes + idle_bytes + pending_bytes;
  }
};
/// Splits an RplidarParser's bytes by category (counters(), buffered()). O(1).
RplidarByteAccount rplidar_byte_account(const LidarParserCounters& c, std::size_t pending_bytes);

/// Encodes scans as the sensor streams them: M = round(2 pi / |increment|) nodes per turn clockwise from sensor
/// 0 deg, the first with S=1. quality = clamp(round(intensity), 0, 63); distance in 1/4 mm (0 when invalid or
/// >= 16384 mm). write_descriptor() gives the 7 bytes the sensor sends once after a SCAN request. O(M) per scan.
class RplidarEncoder {
 public:
  void configure(const LidarAngleConvention& convention) { conv_ = convention; }
  /// Writes the scan descriptor; returns 7.
  static std::size_t write_descriptor(std::uint8_t out[kRplidarDescriptorBytes]);
  /// Writes whole nodes into out (cap bytes); returns bytes written (nodes that did not fit: points_lost()).
  std::size_t encode_scan(const ScanView& scan, std::uint8_t* out, std::size_t cap);
  /// Writes a health response (descriptor + 3 bytes); returns 10.
  static std::size_t write_health(const RplidarHealth& h, std::uint8_t out[kRplidarDescriptorBytes + kRplidarHealthBytes]);
  std::uint32_t points_lost() const { return lost_; }

 private:
  LidarAngleConvention conv_{true, kPi};
  std::uint32_t lost_ = 0;
};

}  // namespace dockcore
