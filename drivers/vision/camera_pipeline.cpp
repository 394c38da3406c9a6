// The camera detection thread and its bounded queue (see dockcore/drivers/camera_pipeline.hpp).
#include "dockcore/drivers/camera_pipeline.hpp"

#include <sys/eventfd.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <system_error>

namespace dockcore::drivers {

namespace {
std::uint64_t mono_us() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000u + static_cast<std::uint64_t>(ts.tv_nsec) / 1000u;
}
}  // namespace

TagObservation tag_observation(const TagDetection& d, std::uint64_t stamp_us) {
  TagObservation o;
  o.id = d.id;
  o.decision_margin = static_cast<Real>(d.decision_margin);
  o.stamp_us = stamp_us;
  for (int k = 0; k < 9; ++k) o.rotation(k / 3, k % 3) = static_cast<Real>(d.rotation[k]);
  for (int k = 0; k < 3; ++k) o.translation_m(k) = static_cast<Real>(d.translation_m[k]);
  o.has_corners = true;
  for (int k = 0; k < 4; ++k) {
    o.corners[k] = Vec2(static_cast<Real>(d.corners_unit_focal[k][0]), static_cast<Real>(d.corners_unit_focal[k][1]));
  }
  return o;
}

CameraPipeline::CameraPipeline(hal::CameraFrameSource& s, TagDetector& d, const CameraPipelineOptions& o, int efd)
    : source_(s), detector_(d), opt_(o), event_fd_(efd) {}

std::unique_ptr<CameraPipeline> CameraPipeline::start(hal::CameraFrameSource& source, TagDetector& detector,
                                                      const CameraPipelineOptions& options, std::string& error) {
  const int efd = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (efd < 0) {
    error = std::string("camera pipeline: eventfd: ") + std::strerror(errno);
    return nullptr;
  }
  std::unique_ptr<CameraPipeline> p(new CameraPipeline(source, detector, options, efd));
  try {
    p->thread_ = std::thread([q = p.get()] { q->run(); });
  } catch (const std::system_error& e) {
    error = std::string("camera pipeline: thread: ") + e.what();
    return nullptr;  // the destructor closes the eventfd; no thread to join
  }
  return p;
}

CameraPipeline::~CameraPipeline() {
  stop();
  if (event_fd_ >= 0) ::close(event_fd_);
}

void CameraPipeline::stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

const TagDetection* select_target_tag(const TagDetection* detections, std::size_t count, std::int32_t target_id,
                                      double full_confidence_margin, std::uint64_t stamp_us, TagFrameResult* out) {
  *out = TagFrameResult{};
  const TagDetection* tag = nullptr;
  for (std::size_t i = 0; i < count && tag == nullptr; ++i) {
    if (target_id < 0 || detections[i].id == target_id) tag = &detections[i];
  }
  if (tag == nullptr) return nullptr;
  out->target.valid = true;
  out->target.u_px = static_cast<Real>(tag->u_px);
  out->target.v_px = static_cast<Real>(tag->v_px);
  out->target.confidence = static_cast<Real>(std::min(1.0, std::max(0.0, tag->decision_margin / full_confidence_margin)));
  out->target.stamp_us = stamp_us;
  if (tag->has_pose) {
    out->has_pose = true;
    out->tag = tag_observation(*tag, stamp_us);
  }
  return tag;
}

bool CameraPipeline::push(const Result& r) {
  const std::size_t head = head_.load(std::memory_order_relaxed);
  const std::size_t tail = tail_.load(std::memory_order_acquire);
  if (head - tail >= kCameraQueueCapacity) return false;
  ring_[head % kCameraQueueCapacity] = r;
  head_.store(head + 1, std::memory_order_release);
  return true;
}

void CameraPipeline::run() {
  TagDetection dets[kMaxTagDetections];
  while (!stop_.load()) {
    hal::CameraFrame f;
    const hal::CameraFrameStatus st = source_.next_frame(f, opt_.frame_timeout_ms);
    if (st != hal::CameraFrameStatus::kFrame) {
      std::lock_guard<std::mutex> lock(stats_mutex_);
      stats_.capture = source_.counters();
      stats_.connected = source_.connected();
      continue;
    }
    last_frame_us_.store(mono_us(), std::memory_order_relaxed);
    const auto t0 = std::chrono::steady_clock::now();
    const std::size_t n = detector_.detect(f.grey, f.width_px, f.height_px, f.stride_bytes, dets, kMaxTagDetections);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    Result r;
    const TagDetection* tag = select_target_tag(dets, n, opt_.target_id, opt_.full_confidence_margin, f.stamp_us, &r);
    bool dropped = false;
    if (tag != nullptr) {
      if (push(r)) {
        const std::uint64_t one = 1;
        // The counter only saturates after 2^64 - 2 unread writes; EAGAIN then means "already readable".
        if (::write(event_fd_, &one, sizeof one) < 0 && errno != EAGAIN) {
          // Nothing else to do from this thread: the tick also polls on every control tick.
        }
      } else {
        dropped = true;
      }
    }
    std::lock_guard<std::mutex> lock(stats_mutex_);
    stats_.capture = source_.counters();
    stats_.connected = source_.connected();
    ++stats_.frames_processed;
    stats_.detect_last_ms = ms;
    stats_.detect_worst_ms = std::max(stats_.detect_worst_ms, ms);
    if (dropped) ++stats_.queue_full;
    stats_.have_tag = tag != nullptr;
    if (tag != nullptr) {
      ++stats_.target_frames;
      stats_.last_tag = *tag;
      stats_.last_tag_stamp_us = f.stamp_us;
    }
  }
}

void CameraPipeline::drain() {
  std::uint64_t v = 0;
  // Clears the wake-up; EAGAIN (nothing written since) is the common case.
  if (::read(event_fd_, &v, sizeof v) < 0 && errno != EAGAIN) {
    // A failing eventfd read does not stop the queue from being drained below.
  }
  const std::size_t head = head_.load(std::memory_order_acquire);
  std::size_t tail = tail_.load(std::memory_order_relaxed);
  if (head == tail) return;
  for (; tail != head; ++tail) {
    const Result& r = ring_[tail % kCameraQueueCapacity];
    if (!r.has_pose) continue;
    if (tags_count_ == kCameraQueueCapacity) {  // the oldest goes: the fusion wants recent frames
      tags_head_ = (tags_head_ + 1) % kCameraQueueCapacity;
      --tags_count_;
      ++tags_dropped_;
    }
    tags_[(tags_head_ + tags_count_) % kCameraQueueCapacity] = r.tag;
    ++tags_count_;
  }
  pending_target_ = true;
  pending_target_value_ = ring_[(head - 1) % kCameraQueueCapacity].target;  // newest
  tail_.store(head, std::memory_order_release);
}

bool CameraPipeline::poll_target(CameraTarget& out) {
  drain();
  if (!pending_target_) return false;
  pending_target_ = false;
  const CameraTarget& t = pending_target_value_;
  const std::uint64_t now = mono_us();
  if (now > t.stamp_us && now - t.stamp_us > static_cast<std::uint64_t>(opt_.max_age_ms) * 1000u) {
    stale_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  out = t;
  return true;
}

bool CameraPipeline::poll_tag(TagObservation& out) {
  drain();
  if (tags_count_ == 0) return false;
  out = tags_[tags_head_];
  tags_head_ = (tags_head_ + 1) % kCameraQueueCapacity;
  --tags_count_;
  return true;
}

CameraPipelineStats CameraPipeline::stats() const {
  std::unique_lock<std::mutex> lock(stats_mutex_, std::try_to_lock);
  if (lock.owns_lock()) last_read_ = stats_;
  last_read_.stale = stale_.load(std::memory_order_relaxed);
  return last_read_;
}

hal::CameraStatus CameraPipeline::camera_status() const {
  const CameraPipelineStats s = stats();
  hal::CameraStatus c;
  c.connected = s.connected;
  c.capture = s.capture;
  c.tag_id = s.have_tag ? s.last_tag.id : -1;
  return c;
}

}  // namespace dockcore::drivers
