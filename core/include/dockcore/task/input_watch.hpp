#pragma once
/// @file InputWatch: the one judge of whether the loop's inputs are fresh (docs/dockd.md, "Watchdogs").
///
/// - Lidar: a scan is stamped with its first sample, so its turn ends one scan period later (the period is learnt
///   from consecutive stamps). The lidar is stale when the newest usable scan's turn ended more than lidar_stale_ms
///   ago, measured from when it was read if that was earlier (a backlog of old bytes must not pass for a live
///   sensor). A scan whose turn ended more than lidar_stale_ms before it is read is late: steering by it would be as
///   wrong as by none, so it is counted and not used. Until the period is known (the first scan) the scan's read
///   time stands for its turn's end.
/// - Chassis: stale when its newest feedback stamp is more than chassis_stale_ms old (a stamp after the evaluation
///   time is a frame read during the tick: fresh).
/// - Stale input holds the robot at once (hold()); only when it stays stale for fault_after_ms does the task manager
///   hear of it (lidar_ok()/chassis_ok() false: faults 185/184), so a short gap continues the same approach.
/// Both start stale. O(1) everything, no heap.

#include <cstdint>

namespace dockcore {

/// The watchdog's thresholds, ms (integers: they are compared with µs stamps).
struct WatchdogParams {
  std::uint32_t lidar_stale_ms = 200;    ///< Newest turn ended longer ago than this: lidar stale, robot held.
  std::uint32_t chassis_stale_ms = 200;  ///< Newest chassis feedback older than this: chassis stale, robot held.
  std::uint32_t fault_after_ms = 1000;   ///< Stale this long after the hold began: the task manager faults.
  /// A dock or undock that such a fault interrupted is issued again once both inputs have been fresh this long.
  std::uint32_t resume_after_ms = 500;
  std::uint8_t max_resumes = 3;  ///< Resumes per task; then the fault stays (a flapping link ends, not loops).
};

class InputWatch {
 public:
  /// New thresholds; the inputs' history is kept. O(1).
  void configure(const WatchdogParams& p) { p_ = p; }
  /// Forgets every input (both stale, counters kept). O(1).
  void reset();

  /// A scan stamped `stamp_us` (µs, its first sample; already clamped to `now_us`) read at `now_us`. True: fresh
  /// enough to use. False: late (counted in late_scans()); the caller must not use it. O(1).
  bool on_scan(std::uint64_t stamp_us, std::uint64_t now_us);

  /// Which verdicts an update() changed.
  struct Change {
    bool lidar = false;
    bool chassis = false;
  };
  /// Judges both inputs at `now_us`; `chassis_valid`/`chassis_stamp_us`: whether chassis feedback has arrived and
  /// the newest one's stamp. Idempotent for the same arguments. O(1).
  Change update(std::uint64_t now_us, bool chassis_valid, std::uint64_t chassis_stamp_us);

  bool lidar_stale() const { return lidar_stale_; }
  bool chassis_stale() const { return chassis_stale_; }
  /// Either input stale: the drive must get zero. O(1).
  bool hold() const { return lidar_stale_ || chassis_stale_; }
  /// False once the lidar has been stale for fault_after_ms at `now_us` (the task manager's lidar_ok). O(1).
  bool lidar_ok(std::uint64_t now_us) const { return !(lidar_stale_ && now_us - lidar_since_us_ >= fault_us()); }
  /// The same for the chassis. O(1).
  bool chassis_ok(std::uint64_t now_us) const { return !(chassis_stale_ && now_us - chassis_since_us_ >= fault_us()); }
  /// The last update() at which an input was stale (0: never fresh yet): both fresh since then. O(1).
  std::uint64_t fresh_since_us() const { return fresh_since_us_; }
  /// When the newest usable scan's turn ended (0 before the first), and when it was read, µs.
  std::uint64_t turn_end_us() const { return turn_end_us_; }
  std::uint64_t scan_read_us() const { return scan_read_us_; }
  std::uint32_t late_scans() const { return late_scans_; }
  std::uint32_t lidar_trips() const { return lidar_trips_; }      ///< Times the lidar went stale.
  std::uint32_t chassis_trips() const { return chassis_trips_; }  ///< Times the chassis went stale.
  const WatchdogParams& params() const { return p_; }

 private:
  std::uint64_t fault_us() const { return static_cast<std::uint64_t>(p_.fault_after_ms) * 1000u; }

  WatchdogParams p_{};
  bool have_scan_ = false;
  std::uint64_t prev_stamp_us_ = 0;
  std::uint64_t period_us_ = 0;  ///< Spacing of the last two plausible stamps; 0 = unknown.
  std::uint64_t turn_end_us_ = 0;
  std::uint64_t scan_read_us_ = 0;
  bool lidar_stale_ = true;
  bool chassis_stale_ = true;
  std::uint64_t lidar_since_us_ = 0;
  std::uint64_t chassis_since_us_ = 0;
  std::uint64_t fresh_since_us_ = 0;
  std::uint32_t late_scans_ = 0;
  std::uint32_t lidar_trips_ = 0;
  std::uint32_t chassis_trips_ = 0;
};

}  // namespace dockcore
