#pragma once
/// @file HAL: where complete lidar scans come from. Drivers (serial LD06 / RPLIDAR, UDP Lakibeam) implement it;
/// dockd and tests consume it. Core never sees this header: it takes ScanView.

#include <cstdint>

#include "dockcore/laser_scan.hpp"

namespace dockcore::hal {

/// Counters every lidar source keeps so nothing is dropped silently.
struct LidarCounters {
  std::uint32_t scans = 0;          ///< Complete scans published.
  std::uint32_t crc_errors = 0;     ///< Packets failing their checksum.
  std::uint32_t resyncs = 0;        ///< Times the parser lost and regained packet framing.
  std::uint32_t dropped_bytes = 0;  ///< Bytes discarded while resynchronising.
  std::uint32_t reconnects = 0;     ///< Device reopened after it vanished.
  std::uint32_t foreign_datagrams = 0;  ///< UDP datagrams from a source other than the configured sensor, dropped.
};

/// A lidar delivering complete turns.
class LidarSource {
 public:
  /// The newest complete scan if one arrived since the last call, else nullptr. Non-blocking. The scan is the
  /// source's own buffer, not a copy: it stays as it is until the next poll_scan() (or a driver's service()), so
  /// use or copy it before then. stamp_us is the host's monotonic time of the scan's first sample.
  virtual const LaserScan* poll_scan() = 0;
  /// File descriptor to wait on (epoll), or -1 when the source is polled.
  virtual int fd() const = 0;
  virtual const LidarCounters& counters() const = 0;

 protected:
  ~LidarSource() = default;
};

}  // namespace dockcore::hal
