// V4L2 capture (see dockcore/drivers/v4l2_camera.hpp): raw ioctls of linux/videodev2.h, mmap streaming, driver
// stamps, reconnect with back-off, counters.
#include "dockcore/drivers/v4l2_camera.hpp"

#if DOCKCORE_HAVE_JPEG
#include "dockcore/drivers/jpeg_grey.hpp"
#endif

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <utility>
#include <vector>

namespace dockcore::drivers {

std::optional<CameraPixelFormat> parse_camera_pixel_format(std::string_view name) {
  if (name == "grey") return CameraPixelFormat::kGrey;
  if (name == "yuyv") return CameraPixelFormat::kYuyv;
  if (name == "mjpeg") return CameraPixelFormat::kMjpeg;
  return std::nullopt;
}

const char* to_string(CameraPixelFormat f) {
  switch (f) {
    case CameraPixelFormat::kGrey:
      return "grey";
    case CameraPixelFormat::kYuyv:
      return "yuyv";
    case CameraPixelFormat::kMjpeg:
      return "mjpeg";
  }
  return "?";
}

namespace v4l2_detail {

void yuyv_to_grey(const std::uint8_t* yuyv, std::uint32_t stride_bytes, std::uint32_t width_px, std::uint32_t height_px,
                  std::uint8_t* grey) {
  for (std::uint32_t r = 0; r < height_px; ++r) {
    const std::uint8_t* s = yuyv + static_cast<std::size_t>(r) * stride_bytes;
    std::uint8_t* d = grey + static_cast<std::size_t>(r) * width_px;
    for (std::uint32_t c = 0; c < width_px; ++c) d[c] = s[2u * c];
  }
}

void copy_grey(const std::uint8_t* src, std::uint32_t stride_bytes, std::uint32_t width_px, std::uint32_t height_px,
               std::uint8_t* grey) {
  for (std::uint32_t r = 0; r < height_px; ++r) {
    std::memcpy(grey + static_cast<std::size_t>(r) * width_px, src + static_cast<std::size_t>(r) * stride_bytes,
                width_px);
  }
}

#if DOCKCORE_HAVE_JPEG
struct FrameConverter::Jpeg {
  JpegGreyDecoder decoder;
};
#else
struct FrameConverter::Jpeg {};
#endif

FrameConverter::FrameConverter(CameraPixelFormat format, std::uint32_t width_px, std::uint32_t height_px)
    : format_(format),
      width_px_(width_px),
      height_px_(height_px),
      bytes_per_line_(format == CameraPixelFormat::kYuyv ? 2 * width_px : width_px),
      a_(static_cast<std::size_t>(width_px) * height_px, 0) {
  frame_ = a_.data();
  if (format_ == CameraPixelFormat::kMjpeg) {
    // A JPEG is decoded into the spare and the two swap on success: a damaged one leaves the frame as it was.
    b_.assign(a_.size(), 0);
    spare_ = b_.data();
    jpeg_ = std::make_unique<Jpeg>();
  }
}

FrameConverter::~FrameConverter() = default;

void FrameConverter::set_bytes_per_line(std::uint32_t bytes_per_line) {
  bytes_per_line_ = bytes_per_line;
}

std::uint32_t FrameConverter::min_bytes() const {
  if (format_ == CameraPixelFormat::kMjpeg) return 0;
  const std::uint32_t bpp = format_ == CameraPixelFormat::kYuyv ? 2u : 1u;
  return bytes_per_line_ * (height_px_ - 1u) + width_px_ * bpp;
}

bool FrameConverter::reject(const char* why) {
  ++corrupt_;
  std::snprintf(error_, sizeof error_, "%s", why);
  return false;
}

bool FrameConverter::convert(const std::uint8_t* data, std::uint32_t bytes_used, bool error_flag) {
  if (error_flag) return reject("buffer flagged V4L2_BUF_FLAG_ERROR");
  switch (format_) {
    case CameraPixelFormat::kGrey:
    case CameraPixelFormat::kYuyv:
      if (!frame_complete(bytes_used, min_bytes(), false)) return reject("buffer shorter than a frame");
      if (format_ == CameraPixelFormat::kGrey) {
        copy_grey(data, bytes_per_line_, width_px_, height_px_, frame_);
      } else {
        yuyv_to_grey(data, bytes_per_line_, width_px_, height_px_, frame_);
      }
      break;
    case CameraPixelFormat::kMjpeg: {
#if DOCKCORE_HAVE_JPEG
      if (!jpeg_->decoder.decode(data, bytes_used, width_px_, height_px_, spare_)) {
        char why[sizeof error_];
        std::snprintf(why, sizeof why, "JPEG: %s", jpeg_->decoder.error());
        return reject(why);
      }
      std::swap(frame_, spare_);
      break;
#else
      (void)data;
      (void)bytes_used;
      return reject("MJPEG: built without libjpeg");
#endif
    }
  }
  error_[0] = '\0';
  return true;
}

}  // namespace v4l2_detail

namespace {

std::uint64_t mono_us() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000u + static_cast<std::uint64_t>(ts.tv_nsec) / 1000u;
}

/// ioctl, retried on EINTR.
int xioctl(int fd, unsigned long request, void* arg) {
  int r;
  do {
    r = ::ioctl(fd, request, arg);
  } while (r < 0 && errno == EINTR);
  return r;
}

/// A descriptor of mmap capture buffer `index` (DQBUF fills the index in).
v4l2_buffer mmap_capture_buffer(std::uint32_t index) {
  v4l2_buffer b{};
  b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  b.memory = V4L2_MEMORY_MMAP;
  b.index = index;
  return b;
}

std::uint32_t fourcc(CameraPixelFormat f) {
  switch (f) {
    case CameraPixelFormat::kGrey:
      return V4L2_PIX_FMT_GREY;
    case CameraPixelFormat::kYuyv:
      return V4L2_PIX_FMT_YUYV;
    case CameraPixelFormat::kMjpeg:
      return V4L2_PIX_FMT_MJPEG;
  }
  return 0;
}

/// The four characters of a FourCC code, NUL-terminated, in `out`.
const char* fourcc_name(std::uint32_t f, char (&out)[5]) {
  for (int i = 0; i < 4; ++i) out[i] = static_cast<char>((f >> (8 * i)) & 0xFFu);
  out[4] = '\0';
  return out;
}

/// Why an open attempt failed.
enum class OpenResult : std::uint8_t { kOk, kAbsent, kFailed, kRefused };

class V4l2CameraImpl final : public V4l2Camera {
 public:
  explicit V4l2CameraImpl(const V4l2CameraOptions& o)
      : opt_(o), conv_(o.format, o.width_px, o.height_px), delay_ms_(o.reconnect_min_ms) {}
  ~V4l2CameraImpl() override { close_device(false); }

  /// One open + negotiate + map + stream-on attempt. On failure everything opened is closed again.
  OpenResult try_open() {
    const int fd = ::open(opt_.device.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
      const int e = errno;
      fail("open", e);
      return (e == ENOENT || e == ENODEV || e == ENXIO) ? OpenResult::kAbsent : OpenResult::kFailed;
    }
    fd_ = fd;
    const OpenResult r = negotiate_and_stream();
    if (r != OpenResult::kOk) close_device(false);
    return r;
  }

  hal::CameraFrameStatus next_frame(hal::CameraFrame& out, int timeout_ms) override {
    const std::uint64_t start = mono_us();
    const std::uint64_t deadline = start + static_cast<std::uint64_t>(std::max(timeout_ms, 0)) * 1000u;
    for (;;) {
      const std::uint64_t now = mono_us();
      if (fd_ < 0) {
        if (now >= next_open_us_) {
          const OpenResult r = try_open();
          if (r == OpenResult::kOk) continue;
          next_open_us_ = now + static_cast<std::uint64_t>(delay_ms_) * 1000u;
          delay_ms_ = std::min(opt_.reconnect_max_ms, std::max<std::uint32_t>(1, delay_ms_) * 2u);
        }
        // Closed: wait until the next attempt or the timeout, whichever is first.
        const std::uint64_t until = std::min(deadline, next_open_us_);
        if (until > now) sleep_us(until - now);
        if (mono_us() >= deadline) return hal::CameraFrameStatus::kDisconnected;
        continue;
      }
      const int wait_ms = deadline > now ? static_cast<int>((deadline - now + 999u) / 1000u) : 0;
      pollfd p{fd_, POLLIN, 0};
      const int n = ::poll(&p, 1, wait_ms);
      if (n < 0) {
        if (errno == EINTR) continue;
        lose("poll", errno);
        continue;
      }
      if (n == 0) return hal::CameraFrameStatus::kTimeout;
      if ((p.revents & (POLLERR | POLLHUP | POLLNVAL)) != 0) {
        // A device that was unregistered (unplugged, unbound) reports POLLERR | POLLHUP; DQBUF would say ENODEV.
        lose("poll", (p.revents & POLLNVAL) != 0 ? EBADF : ENODEV);
        continue;
      }
      v4l2_buffer b = mmap_capture_buffer(0);
      if (xioctl(fd_, VIDIOC_DQBUF, &b) < 0) {
        if (errno == EAGAIN) {
          if (mono_us() >= deadline) return hal::CameraFrameStatus::kTimeout;
          continue;
        }
        lose("VIDIOC_DQBUF", errno);
        continue;
      }
      const std::uint64_t dq_us = mono_us();
      counters_.dropped += seq_.gap(b.sequence);
      std::uint64_t stamp = dq_us;
      if (driver_stamps_) {
        stamp =
            static_cast<std::uint64_t>(b.timestamp.tv_sec) * 1000000u + static_cast<std::uint64_t>(b.timestamp.tv_usec);
        if (stamp > dq_us) stamp = dq_us;  // never in the future of its own dequeue
      }
      // An index outside the mapped buffers, or a bytesused beyond the buffer, is the driver's error: not a frame.
      const bool in_range = b.index < nbuf_ && b.bytesused <= maps_[b.index].length;
      const bool ok = conv_.convert(in_range ? static_cast<const std::uint8_t*>(maps_[b.index].addr) : nullptr,
                                    b.bytesused, !in_range || (b.flags & V4L2_BUF_FLAG_ERROR) != 0);
      counters_.corrupt = conv_.corrupt();
      // Back to the driver at once: the pixels were copied (or decoded).
      if (xioctl(fd_, VIDIOC_QBUF, &b) < 0) {
        lose("VIDIOC_QBUF", errno);
        continue;
      }
      if (!ok) {
        // Counted; the reason stays readable (camera-check prints it) until the next failure.
        std::snprintf(error_, sizeof error_, "camera %s: frame %u skipped (corrupt): %s", opt_.device.c_str(),
                      b.sequence, conv_.error());
        if (mono_us() >= deadline) return hal::CameraFrameStatus::kTimeout;
        continue;
      }
      if (dq_us - stamp > static_cast<std::uint64_t>(opt_.late_ms) * 1000u) ++counters_.late;
      ++counters_.frames;
      out.grey = conv_.frame();
      out.width_px = opt_.width_px;
      out.height_px = opt_.height_px;
      out.stride_bytes = opt_.width_px;
      out.stamp_us = stamp;
      out.sequence = b.sequence;
      return hal::CameraFrameStatus::kFrame;
    }
  }

  bool connected() const override { return fd_ >= 0; }
  const hal::CameraFrameCounters& counters() const override { return counters_; }
  const char* last_error() const override { return error_; }
  bool driver_stamps() const override { return driver_stamps_; }
  std::uint32_t bytes_per_line() const override { return bytes_per_line_; }
  std::uint32_t size_image() const override { return size_image_; }

 private:
  // Messages go into a fixed buffer: a reopen attempt after start allocates nothing.
  void fail(const char* call, int err) {
    std::snprintf(error_, sizeof error_, "camera %s: %s: %s", opt_.device.c_str(), call, std::strerror(err));
  }
  __attribute__((format(printf, 2, 3))) void refuse(const char* fmt, ...) {
    const int n = std::snprintf(error_, sizeof error_, "camera %s: ", opt_.device.c_str());
    if (n < 0 || static_cast<std::size_t>(n) >= sizeof error_) return;
    va_list ap;
    va_start(ap, fmt);
    std::vsnprintf(error_ + n, sizeof error_ - static_cast<std::size_t>(n), fmt, ap);
    va_end(ap);
  }

  static void sleep_us(std::uint64_t us) {
    timespec ts{static_cast<time_t>(us / 1000000u), static_cast<long>((us % 1000000u) * 1000u)};
    while (::nanosleep(&ts, &ts) != 0 && errno == EINTR) {
    }
  }

  OpenResult negotiate_and_stream() {
    v4l2_capability cap{};
    if (xioctl(fd_, VIDIOC_QUERYCAP, &cap) < 0) {
      const int e = errno;
      fail("VIDIOC_QUERYCAP", e);
      return e == ENOTTY ? OpenResult::kRefused : OpenResult::kFailed;
    }
    const std::uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) != 0 ? cap.device_caps : cap.capabilities;
    if ((caps & V4L2_CAP_VIDEO_CAPTURE) == 0) {
      refuse("is not a video capture device (driver %.16s)", reinterpret_cast<const char*>(cap.driver));
      return OpenResult::kRefused;
    }
    if ((caps & V4L2_CAP_STREAMING) == 0) {
      refuse("does not support streaming I/O (VIDIOC_QUERYCAP: no V4L2_CAP_STREAMING)");
      return OpenResult::kRefused;
    }
    v4l2_format f{};
    f.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    f.fmt.pix.width = opt_.width_px;
    f.fmt.pix.height = opt_.height_px;
    f.fmt.pix.pixelformat = fourcc(opt_.format);
    f.fmt.pix.field = V4L2_FIELD_NONE;
    if (xioctl(fd_, VIDIOC_S_FMT, &f) < 0) {
      const int e = errno;
      fail("VIDIOC_S_FMT", e);
      return e == EBUSY ? OpenResult::kFailed : OpenResult::kRefused;
    }
    if (f.fmt.pix.pixelformat != fourcc(opt_.format)) {
      char want[5], got[5];
      refuse("VIDIOC_S_FMT: asked for %s, the device gives %s (camera.device.format)",
             fourcc_name(fourcc(opt_.format), want), fourcc_name(f.fmt.pix.pixelformat, got));
      return OpenResult::kRefused;
    }
    if (f.fmt.pix.width != opt_.width_px || f.fmt.pix.height != opt_.height_px) {
      refuse("VIDIOC_S_FMT: asked for %ux%u, the device gives %ux%u (camera.device.width_px / height_px)",
             opt_.width_px, opt_.height_px, f.fmt.pix.width, f.fmt.pix.height);
      return OpenResult::kRefused;
    }
    if (opt_.format == CameraPixelFormat::kMjpeg) {
      // Compressed: no rows; a buffer holds one JPEG of bytesused bytes, at most sizeimage.
      bytes_per_line_ = 0;
      size_image_ = f.fmt.pix.sizeimage;
      if (size_image_ == 0) {
        refuse("VIDIOC_S_FMT: MJPEG with sizeimage 0");
        return OpenResult::kRefused;
      }
    } else {
      const std::uint32_t bpp = opt_.format == CameraPixelFormat::kGrey ? 1u : 2u;
      bytes_per_line_ = f.fmt.pix.bytesperline != 0 ? f.fmt.pix.bytesperline : opt_.width_px * bpp;
      if (bytes_per_line_ < opt_.width_px * bpp) {
        refuse("VIDIOC_S_FMT: bytesperline %u is less than a row of pixels", bytes_per_line_);
        return OpenResult::kRefused;
      }
      conv_.set_bytes_per_line(bytes_per_line_);
      // The bytes a complete frame fills: rows of bytesperline, the last one needing only its pixels.
      size_image_ = conv_.min_bytes();
    }
    if (opt_.fps > 0) {
      v4l2_streamparm sp{};
      sp.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      sp.parm.capture.timeperframe.numerator = 1;
      sp.parm.capture.timeperframe.denominator = opt_.fps;
      // A device without frame-rate control answers ENOTTY / EINVAL: it runs at its own rate (documented).
      if (xioctl(fd_, VIDIOC_S_PARM, &sp) < 0 && errno != ENOTTY && errno != EINVAL) {
        fail("VIDIOC_S_PARM", errno);
        return OpenResult::kFailed;
      }
    }
    v4l2_requestbuffers rb{};
    rb.count = opt_.buffers;
    rb.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    rb.memory = V4L2_MEMORY_MMAP;
    if (xioctl(fd_, VIDIOC_REQBUFS, &rb) < 0) {
      const int e = errno;
      fail("VIDIOC_REQBUFS", e);
      return e == EINVAL ? OpenResult::kRefused : OpenResult::kFailed;
    }
    if (rb.count < 2) {
      refuse("VIDIOC_REQBUFS: the driver granted %u buffer(s), streaming needs 2", rb.count);
      return OpenResult::kFailed;
    }
    nbuf_ = std::min<std::uint32_t>(rb.count, kMaxV4l2Buffers);
    for (std::uint32_t i = 0; i < nbuf_; ++i) {
      v4l2_buffer b = mmap_capture_buffer(i);
      if (xioctl(fd_, VIDIOC_QUERYBUF, &b) < 0) {
        fail("VIDIOC_QUERYBUF", errno);
        return OpenResult::kFailed;
      }
      if (i == 0) {
        const std::uint32_t tsflags = b.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK;
        driver_stamps_ = tsflags == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
      }
      void* a = ::mmap(nullptr, b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, b.m.offset);
      if (a == MAP_FAILED) {
        fail("mmap", errno);
        return OpenResult::kFailed;
      }
      maps_[i] = {a, b.length};
      if (b.length < size_image_) {
        refuse("VIDIOC_QUERYBUF: buffer %u holds %u bytes, a frame needs %u", i, b.length, size_image_);
        return OpenResult::kRefused;
      }
    }
    for (std::uint32_t i = 0; i < nbuf_; ++i) {
      v4l2_buffer b = mmap_capture_buffer(i);
      if (xioctl(fd_, VIDIOC_QBUF, &b) < 0) {
        fail("VIDIOC_QBUF", errno);
        return OpenResult::kFailed;
      }
    }
    v4l2_buf_type t = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (xioctl(fd_, VIDIOC_STREAMON, &t) < 0) {
      fail("VIDIOC_STREAMON", errno);
      return OpenResult::kFailed;
    }
    streaming_ = true;
    seq_.reset();
    error_[0] = '\0';
    if (was_connected_) ++counters_.reconnects;
    was_connected_ = true;
    delay_ms_ = opt_.reconnect_min_ms;
    return OpenResult::kOk;
  }

  /// The device went away (or failed) while open: record why, close, count, schedule a reopen.
  void lose(const char* call, int err) {
    fail(call, err);
    close_device(true);
    ++counters_.disconnects;
    next_open_us_ = mono_us() + static_cast<std::uint64_t>(delay_ms_) * 1000u;
  }

  /// Stops streaming, unmaps and closes. `vanished`: the device is gone, so STREAMOFF failing is expected; on an
  /// orderly close a STREAMOFF failure is recorded in last_error().
  void close_device(bool vanished) {
    if (fd_ < 0) return;
    if (streaming_) {
      v4l2_buf_type t = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      if (xioctl(fd_, VIDIOC_STREAMOFF, &t) < 0 && !vanished) fail("VIDIOC_STREAMOFF", errno);
      streaming_ = false;
    }
    for (std::uint32_t i = 0; i < kMaxV4l2Buffers; ++i) {
      if (maps_[i].addr != nullptr) {
        if (::munmap(maps_[i].addr, maps_[i].length) != 0 && !vanished) fail("munmap", errno);
        maps_[i] = {};
      }
    }
    nbuf_ = 0;
    if (::close(fd_) != 0 && !vanished) fail("close", errno);
    fd_ = -1;
  }

  struct Map {
    void* addr = nullptr;
    std::size_t length = 0;
  };

  V4l2CameraOptions opt_;
  v4l2_detail::FrameConverter conv_;
  int fd_ = -1;
  bool streaming_ = false;
  bool was_connected_ = false;
  bool driver_stamps_ = false;
  Map maps_[kMaxV4l2Buffers] = {};
  std::uint32_t nbuf_ = 0;
  std::uint32_t bytes_per_line_ = 0;
  std::uint32_t size_image_ = 0;
  std::uint32_t delay_ms_;
  std::uint64_t next_open_us_ = 0;
  v4l2_detail::SequenceTracker seq_;
  hal::CameraFrameCounters counters_{};
  char error_[256] = "";
};

}  // namespace

std::unique_ptr<V4l2Camera> open_v4l2_camera(const V4l2CameraOptions& o, std::string& error) {
  if (o.device.empty()) {
    error = "camera: no device path";
    return nullptr;
  }
  if (o.width_px == 0 || o.height_px == 0 || o.width_px > kMaxCameraSidePx || o.height_px > kMaxCameraSidePx) {
    error = "camera " + o.device + ": size " + std::to_string(o.width_px) + "x" + std::to_string(o.height_px) +
            " outside 1.." + std::to_string(kMaxCameraSidePx);
    return nullptr;
  }
#if !DOCKCORE_HAVE_JPEG
  if (o.format == CameraPixelFormat::kMjpeg) {
    error = "camera " + o.device + ": format mjpeg: this build has no libjpeg (tools/setup-deps installs libjpeg-dev)";
    return nullptr;
  }
#endif
  if (o.format == CameraPixelFormat::kYuyv && o.width_px % 2 != 0) {
    error = "camera " + o.device + ": YUYV needs an even width, not " + std::to_string(o.width_px);
    return nullptr;
  }
  if (o.buffers < 2 || o.buffers > kMaxV4l2Buffers) {
    error = "camera " + o.device + ": buffers " + std::to_string(o.buffers) + " outside 2.." +
            std::to_string(kMaxV4l2Buffers);
    return nullptr;
  }
  if (o.reconnect_min_ms == 0 || o.reconnect_max_ms < o.reconnect_min_ms) {
    error = "camera " + o.device + ": reconnect delays must satisfy 0 < min <= max";
    return nullptr;
  }
  auto cam = std::make_unique<V4l2CameraImpl>(o);
  const OpenResult r = cam->try_open();
  if (r == OpenResult::kRefused) {
    error = cam->last_error();
    return nullptr;
  }
  return cam;
}

}  // namespace dockcore::drivers
