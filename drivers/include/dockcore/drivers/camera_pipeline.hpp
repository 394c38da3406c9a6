#pragma once
/// @file dockd's own camera target (docs/camera.md): a thread that takes grey frames from a hal::CameraFrameSource
/// (the V4L2 driver), runs the AprilTag detector on each and hands the target tag to the control tick through a
/// bounded single-producer single-consumer queue. The tick side (poll_target, stats) never blocks and never
/// allocates: it drains the queue (lock-free) and keeps the newest target; when the tick has not collected for a
/// whole queue, further results are dropped and counted. The same hal::CameraTargetSource as the UDP datagram, so the
/// controllers see one kind of input whichever produced it.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "dockcore/control/controller.hpp"
#include "dockcore/drivers/apriltag_detector.hpp"
#include "dockcore/hal/camera.hpp"

namespace dockcore::drivers {

struct CameraPipelineOptions {
  std::int32_t target_id = -1;          ///< Only this tag id is the target; -1 = any (the strongest).
  std::uint32_t max_age_ms = 500;       ///< Targets older than this when polled are refused (counted stale).
  double full_confidence_margin = 100;  ///< Decision margin reported as confidence 1 (confidence = margin / this, ≤ 1).
  int frame_timeout_ms = 100;           ///< Longest wait for a frame before the thread checks for stop.
};

/// What one frame's detections give the control tick: seed 003's camera target and, when the detector had
/// intrinsics, the target tag's pose for the fusion.
struct TagFrameResult {
  CameraTarget target{};  ///< Invalid when the frame holds no target tag.
  bool has_pose = false;
  TagObservation tag{};  ///< Valid when has_pose.
};

/// The target tag among a frame's `count` detections (sorted strongest first, as TagDetector::detect gives them):
/// the first with id `target_id`, or the strongest when it is −1. Its centre becomes the target (confidence =
/// decision margin / `full_confidence_margin`, at most 1), its pose the observation, both stamped `stamp_us`.
/// Returns the chosen detection, or nullptr (and `out` reset: target invalid, no pose) when none is the target. The
/// one conversion dockd's pipeline and the simulator's rendered camera share. O(count).
const TagDetection* select_target_tag(const TagDetection* detections, std::size_t count, std::int32_t target_id,
                                      double full_confidence_margin, std::uint64_t stamp_us, TagFrameResult* out);

/// The tag's pose, corners and decode quality of `d` (which must have its pose) as the core's dock-pose input, stamped
/// with its frame's capture time. O(1).
TagObservation tag_observation(const TagDetection& d, std::uint64_t stamp_us);

/// Results the thread can queue before the tick collects them.
constexpr std::size_t kCameraQueueCapacity = 8;

/// A snapshot of the pipeline for status reports (copied, so it is consistent).
struct CameraPipelineStats {
  hal::CameraFrameCounters capture{};  ///< The frame source's counters.
  bool connected = false;
  std::uint64_t frames_processed = 0;  ///< Frames the detector ran on.
  std::uint64_t target_frames = 0;     ///< Frames in which the target tag was found.
  std::uint64_t queue_full = 0;        ///< Results dropped: the tick had not collected the queue.
  std::uint64_t stale = 0;             ///< Targets older than max_age_ms when polled.
  double detect_last_ms = 0;           ///< Detector time on the last frame.
  double detect_worst_ms = 0;
  bool have_tag = false;    ///< The last frame held the target:
  TagDetection last_tag{};  ///< its detection (centre, id, margin, pose).
  std::uint64_t last_tag_stamp_us = 0;
};

/// Also a hal::TagPoseSource: the target tag's pose of every frame that had one (with intrinsics), in frame order; a
/// hal::CameraFrameMonitor: when the thread last received a frame; and a hal::CameraStatusSource: its stats() as a
/// status report shows them.
class CameraPipeline final : public hal::CameraTargetSource,
                             public hal::TagPoseSource,
                             public hal::CameraFrameMonitor,
                             public hal::CameraStatusSource {
 public:
  /// Starts the thread. The source and the detector must outlive the pipeline; only the thread uses them.
  /// nullptr + message when the wake-up descriptor or the thread cannot be created.
  static std::unique_ptr<CameraPipeline> start(hal::CameraFrameSource& source, TagDetector& detector,
                                               const CameraPipelineOptions& options, std::string& error);
  ~CameraPipeline();
  CameraPipeline(const CameraPipeline&) = delete;
  CameraPipeline& operator=(const CameraPipeline&) = delete;

  /// Newest target queued since the last call and not older than max_age_ms; false otherwise. Never blocks. O(queue).
  bool poll_target(CameraTarget& out) override;
  /// The oldest queued tag pose not yet handed out (results drained from the queue by either poll keep their pose
  /// here, at most kCameraQueueCapacity; older ones are dropped and counted in tags_dropped()). Never blocks. O(1).
  bool poll_tag(TagObservation& out) override;
  /// Tag poses dropped because poll_tag was not called for kCameraQueueCapacity results. Tick side only.
  std::uint64_t tags_dropped() const { return tags_dropped_; }
  /// CLOCK_MONOTONIC µs at which the thread last got a frame from the source, before detecting in it; 0 before the
  /// first. Lock-free, never blocks. O(1).
  std::uint64_t last_frame_us() const override { return last_frame_us_.load(std::memory_order_relaxed); }
  /// An eventfd that is readable when the thread has queued a result (poll_target clears it).
  int fd() const override { return event_fd_; }
  /// The latest snapshot; never blocks (when the thread is updating it, the previous snapshot is returned).
  CameraPipelineStats stats() const;
  /// stats()' connection, capture counters and last target tag id. Never blocks, as stats(). O(1).
  hal::CameraStatus camera_status() const override;
  /// Stops and joins the thread (also done by the destructor). Idempotent.
  void stop();

 private:
  using Result = TagFrameResult;
  /// Moves every queued result into pending_target_ and the tag buffer. Tick side only.
  void drain();
  CameraPipeline(hal::CameraFrameSource& s, TagDetector& d, const CameraPipelineOptions& o, int efd);
  void run();
  bool push(const Result& r);

  hal::CameraFrameSource& source_;
  TagDetector& detector_;
  CameraPipelineOptions opt_;
  int event_fd_ = -1;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  // SPSC ring: the thread writes slots and head_, the tick reads them and writes tail_.
  Result ring_[kCameraQueueCapacity];
  std::atomic<std::size_t> head_{0};
  std::atomic<std::size_t> tail_{0};
  std::atomic<std::uint64_t> stale_{0};
  std::atomic<std::uint64_t> last_frame_us_{0};
  // Tick side only: the newest drained target not yet polled, and the drained tag poses not yet polled.
  bool pending_target_ = false;
  CameraTarget pending_target_value_{};
  TagObservation tags_[kCameraQueueCapacity];
  std::size_t tags_head_ = 0, tags_count_ = 0;
  std::uint64_t tags_dropped_ = 0;
  mutable std::mutex stats_mutex_;
  CameraPipelineStats stats_{};              ///< Written by the thread under stats_mutex_.
  mutable CameraPipelineStats last_read_{};  ///< The tick's copy when the lock was busy.
};

}  // namespace dockcore::drivers
