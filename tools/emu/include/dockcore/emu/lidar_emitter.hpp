#pragma once
// Lidar emulator: turns core scans (ScanView) into real LD06 / RPLIDAR byte streams on a pty, or LD06 / Lakibeam
// datagrams on UDP, using core's encoders, with fault injection (corrupted bytes, dropped packets, stalls,
// unplugging). Host-side (tools/): heap and std::string are fine; nothing ever blocks.
//
// Typical use (chassis-sim, lidar-emu):
//   dockcore::emu::LidarEmitterOptions o;
//   o.protocol = dockcore::emu::EmuProtocol::kLd06;
//   o.pty_link = "/tmp/dockcore-lidar";       // a driver opens this path as its serial device
//   std::string err;
//   auto emitter = dockcore::emu::LidarEmitter::open(o, err);   // nullptr + err on failure
//   ... every 100 ms: emitter->emit_scan(scan.view());
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "dockcore/laser_scan.hpp"

namespace dockcore::emu {

enum class EmuProtocol : std::uint8_t { kLd06 = 0, kRplidar = 1, kLakibeam = 2 };

/// "ld06" | "rplidar" | "lakibeam" -> protocol; false for anything else.
bool parse_emu_protocol(const std::string& name, EmuProtocol* out);

struct LidarEmitterOptions {
  EmuProtocol protocol = EmuProtocol::kLd06;
  /// pty mode (ld06, rplidar): symlink created at this path pointing at the pty slave ("" = no link; the slave path
  /// is still available from slave_path()). An existing symlink there is replaced; any other file is an error.
  std::string pty_link;
  /// UDP mode (ld06, lakibeam) when udp_port != 0: datagrams are sent to udp_host:udp_port (IPv4 literal).
  std::string udp_host = "127.0.0.1";
  std::uint16_t udp_port = 0;
  double rate_hz = 10.0;          ///< Turn rate written into LD06 speed fields (deg/s = 360 * rate).
  double corrupt_fraction = 0.0;  ///< Probability that a byte gets one random bit flipped (0..1).
  /// Probability that a packet (LD06 packet, RPLIDAR node, datagram) gets one random bit flipped. Per-byte
  /// corruption of p ruins 1 - (1-p)^47 of LD06 packets (5 % of bytes: 91 %); this is the gentler knob.
  double corrupt_packet_fraction = 0.0;
  double drop_fraction = 0.0;     ///< Probability that a packet (LD06 packet, RPLIDAR node, datagram) is not sent.
  std::uint64_t seed = 1;         ///< Seeds the fault injection (deterministic for a seed).
  /// RPLIDAR: stream nodes only after the host sent SCAN (A5 20), as the sensor does; false = stream at once.
  bool rplidar_wait_for_scan_request = true;
  /// pty mode: send each packet (LD06) / node (RPLIDAR) when the sensor would, spread over the turn that begins at
  /// the scan's stamp (packet k of n at stamp + (k+1)/n turn periods), instead of the whole turn at once; the owner
  /// calls pump() at least every few ms. A turn sent at once carries packet timestamps up to a turn in the future of
  /// its arrival, which a receiver mapping the sensor clock (dockd) reads as a turn measured a period earlier than it
  /// was rendered. Needs scans with a stamp (monotonic µs); unstamped scans are sent at once.
  bool paced = false;
};

/// What the emitter did (all monotonic counters).
struct LidarEmitterStats {
  std::uint64_t scans = 0;            ///< emit_scan calls that produced output.
  std::uint64_t scans_suppressed = 0; ///< emit_scan calls while stalled, unplugged or (RPLIDAR) not asked to scan.
  std::uint64_t packets = 0;          ///< Packets / nodes / datagrams encoded.
  std::uint64_t packets_dropped = 0;  ///< ... of which deliberately not sent (drop_fraction).
  std::uint64_t bytes_written = 0;    ///< Bytes accepted by the pty / socket.
  std::uint64_t bytes_unwritten = 0;  ///< Bytes that could not be written without blocking (pty full, EAGAIN).
  std::uint64_t bytes_corrupted = 0;  ///< Bytes with a flipped bit.
  std::uint64_t requests_seen = 0;    ///< RPLIDAR requests (A5 xx) read from the host.
  /// CLOCK_REALTIME µs at which the last turn's final packet was written (paced or not); 0 = none yet. The reference
  /// of chassis-sim's "last good scan" for the stale-lidar rows.
  std::int64_t last_turn_written_wall_us = 0;
  std::uint64_t paced_packets_discarded = 0;  ///< Queued packets dropped because the sensor stalled or was unplugged.
  /// Paced packets written more than 30 ms after they were due: the emulator's own process ran late (a starved
  /// simulator), which a receiver sees as a late sensor.
  std::uint64_t paced_packets_late = 0;
};

class LidarEmitter {
 public:
  /// Opens the pty (openpty, slave in raw mode, symlink) or the UDP socket. nullptr with a message on failure.
  static std::unique_ptr<LidarEmitter> open(const LidarEmitterOptions& options, std::string& error);
  ~LidarEmitter();
  LidarEmitter(const LidarEmitter&) = delete;
  LidarEmitter& operator=(const LidarEmitter&) = delete;

  /// Encodes one turn with the protocol and writes it without blocking (bytes that do not fit are counted in
  /// stats().bytes_unwritten and lost, as on a real overrun). Also answers RPLIDAR requests waiting on the pty.
  /// Returns false when nothing was sent (stalled, unplugged, RPLIDAR not started) or on a socket/pty error.
  /// Cost O(points per turn).
  bool emit_scan(const ScanView& scan);
  /// Reads and answers pending RPLIDAR requests (SCAN -> descriptor, STOP, GET_HEALTH -> health). emit_scan calls
  /// it; call it yourself between scans for a faster reply. No-op for other protocols.
  void service_requests();
  /// Paced mode: writes the queued packets due at monotonic `now_us`; drops the queue while stalled or unplugged
  /// (the sensor stopped mid-turn). No-op otherwise. O(packets written).
  void pump(std::uint64_t now_us);

  /// Stops sending (the sensor freezes) while true; the pty stays open.
  void set_stalled(bool stalled) { stalled_ = stalled; }
  bool stalled() const { return stalled_; }
  /// Simulates unplugging: closes the pty (the reader sees EIO / hang-up) and removes the symlink. pty mode only.
  void unplug();
  /// Plugs back in: a new pty, the symlink re-pointed at it. False with a message on failure.
  bool replug(std::string& error);
  bool plugged() const { return master_fd_ >= 0 || udp_fd_ >= 0; }

  void set_corrupt_fraction(double f) { opt_.corrupt_fraction = f; }
  void set_drop_fraction(double f) { opt_.drop_fraction = f; }
  /// Line model between the encoder and the serial port (pty mode): called with each chunk of bytes, after the
  /// bit-flip corruption and before the write, it may rewrite or resize the chunk (e.g. the garbage a receiver at
  /// the wrong baud rate reads). Empty function = bytes pass unchanged. chassis-sim uses it for the wrong-baud fault.
  void set_line_filter(std::function<void(std::vector<std::uint8_t>&)> filter) { line_filter_ = std::move(filter); }

  /// Path of the current pty slave ("/dev/pts/N"); "" in UDP mode or while unplugged.
  const std::string& slave_path() const { return slave_path_; }
  const LidarEmitterStats& stats() const { return stats_; }
  const LidarEmitterOptions& options() const { return opt_; }

 private:
  struct Impl;
  explicit LidarEmitter(const LidarEmitterOptions& options);
  bool open_pty(std::string& error);
  bool open_udp(std::string& error);
  void send_stream_packets(const std::uint8_t* data, std::size_t n, std::size_t packet_bytes, std::uint64_t stamp_us);
  void note_turn_written();
  void write_bytes(std::vector<std::uint8_t>& bytes);
  void send_datagram(const std::uint8_t* data, std::size_t n);
  double uniform();

  LidarEmitterOptions opt_;
  std::unique_ptr<Impl> impl_;
  int master_fd_ = -1;
  int slave_fd_ = -1;
  int udp_fd_ = -1;
  std::string slave_path_;
  bool stalled_ = false;
  bool rplidar_scanning_ = false;
  bool rplidar_need_descriptor_ = false;
  std::uint64_t rng_state_ = 0;
  std::uint64_t ms_ = 0;
  LidarEmitterStats stats_{};
  std::function<void(std::vector<std::uint8_t>&)> line_filter_;
};

}  // namespace dockcore::emu
