#pragma once
/// @file HAL: the camera. Two interfaces for the two places a camera's data can come from:
///  - CameraTargetSource: the dock target as the controllers use it (pixel column/row, confidence, stamp), from any
///    vision process (the UDP datagram of docs/dockd.md) or from dockd's own detector (docs/camera.md);
///  - TagPoseSource: the dock tag's pose per frame (DockcoreBase::on_tag's input), from dockd's own detector;
///  - CameraFrameSource: raw grey frames from a capture device (a V4L2 camera), stamped by the driver, for a
///    detector that runs on the robot's board;
///  - CameraFrameMonitor: when such a source last delivered a frame (the stall watchdog);
///  - CameraStatusSource: such a camera's state for a status report (connected, its counters, the tag seen last).

#include <cstddef>
#include <cstdint>

#include "dockcore/control/controller.hpp"
#include "dockcore/perception/tag_measurement.hpp"

namespace dockcore::hal {

class CameraTargetSource {
 public:
  /// Newest target since the last call; false when none arrived (out untouched).
  virtual bool poll_target(CameraTarget& out) = 0;
  /// A descriptor that becomes readable when a target may be waiting (epoll), or -1 when there is none.
  virtual int fd() const = 0;

 protected:
  ~CameraTargetSource() = default;
};

/// Tag poses in frame order, each handed out once (the dock-pose fusion, docs/camera.md "Fusion").
class TagPoseSource {
 public:
  /// The oldest tag pose not yet handed out; false when none is waiting (out untouched). Never blocks.
  virtual bool poll_tag(TagObservation& out) = 0;

 protected:
  ~TagPoseSource() = default;
};

/// When the camera last delivered a frame, for a watchdog on the control tick (dockd's camera stall, docs/camera.md).
class CameraFrameMonitor {
 public:
  /// CLOCK_MONOTONIC µs at which the newest frame arrived from the device (whether or not it held a tag); 0 before
  /// the first. Never blocks. O(1).
  virtual std::uint64_t last_frame_us() const = 0;

 protected:
  ~CameraFrameMonitor() = default;
};

/// One captured frame as 8-bit grey, row-major. The pixels belong to the source and stay valid until the next
/// next_frame() call on it.
struct CameraFrame {
  const std::uint8_t* grey = nullptr;  ///< width_px × height_px luma samples, `stride_bytes` apart per row.
  std::uint32_t width_px = 0;
  std::uint32_t height_px = 0;
  std::uint32_t stride_bytes = 0;
  std::uint64_t stamp_us = 0;  ///< Capture time on CLOCK_MONOTONIC, µs (the driver's stamp, not the read time).
  std::uint32_t sequence = 0;  ///< The device's frame counter (gaps are dropped frames).
};

/// Counters of a frame source since it was created (never reset, so a reader can take differences).
struct CameraFrameCounters {
  std::uint64_t frames = 0;   ///< Frames handed out by next_frame().
  std::uint64_t dropped = 0;  ///< Frames the device numbered but never delivered (sequence gaps).
  std::uint64_t late = 0;     ///< Frames older than the source's late threshold when dequeued (a backlog).
  std::uint64_t corrupt =
      0;  ///< Frames skipped: flagged as errored, fewer bytes than the format needs, or undecodable.
  std::uint32_t disconnects = 0;  ///< Times the device went away (open failures not counted).
  std::uint32_t reconnects = 0;   ///< Times it was opened again after a disconnect.
};

/// A camera's state as a status report shows it: a snapshot of the capture and of the tag detector's last frame.
struct CameraStatus {
  bool connected = false;         ///< The capture device is open and streaming.
  CameraFrameCounters capture{};  ///< The frame source's counters.
  std::int32_t tag_id = -1;       ///< The target tag's id in the last frame; -1 when the last frame had none.
};

/// The state of a camera that captures and detects on the robot's board (dockd's own camera, docs/camera.md).
class CameraStatusSource {
 public:
  /// A snapshot copy. Never blocks (a source updated by another thread returns its previous snapshot while that
  /// thread holds it), no allocation. O(1).
  virtual CameraStatus camera_status() const = 0;

 protected:
  ~CameraStatusSource() = default;
};

/// Why next_frame() returned without a frame.
enum class CameraFrameStatus : std::uint8_t {
  kFrame = 0,     ///< `out` holds a new frame.
  kTimeout,       ///< No frame within the timeout (device open and streaming).
  kDisconnected,  ///< The device is closed (vanished, or not there yet); the source retries by itself.
};

class CameraFrameSource {
 public:
  /// Waits at most `timeout_ms` for the next good frame. Skips (and counts) corrupt frames; when the device is
  /// closed, tries to reopen it once its back-off has expired. The previous frame's pixels become invalid.
  virtual CameraFrameStatus next_frame(CameraFrame& out, int timeout_ms) = 0;
  virtual bool connected() const = 0;
  virtual const CameraFrameCounters& counters() const = 0;
  /// Human-readable reason of the last failure, naming the device and the call ("" when none). Never null.
  virtual const char* last_error() const = 0;

 protected:
  ~CameraFrameSource() = default;
};

}  // namespace dockcore::hal
