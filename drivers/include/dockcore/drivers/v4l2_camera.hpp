#pragma once
/// @file V4L2 capture behind hal::CameraFrameSource (docs/camera.md): opens a video capture device by path,
/// negotiates a grey, YUYV or MJPEG format of the configured size, streams through mmap'ed driver buffers and hands
/// out 8-bit grey frames stamped with the driver's own capture time. A device that vanishes (unplugged, driver
/// unbound, module removed) is closed, counted and reopened with exponential back-off. Every ioctl is checked;
/// failures name the device and the ioctl ("camera /dev/video0: VIDIOC_S_FMT: Invalid argument"). Heap: the grey
/// frame (two for MJPEG, which decodes into a spare one) and the JPEG decoder, allocated when the camera is created;
/// nothing after for grey and YUYV (the capture buffers are the driver's, mapped). libjpeg allocates inside every
/// MJPEG decode: next_frame() runs on the detection thread, which allocates anyway (libapriltag).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dockcore/hal/camera.hpp"

namespace dockcore::drivers {

/// Pixel formats the driver negotiates.
enum class CameraPixelFormat : std::uint8_t {
  kGrey = 0,   ///< V4L2_PIX_FMT_GREY: 8-bit luma, used as is.
  kYuyv = 1,   ///< V4L2_PIX_FMT_YUYV: 4:2:2, Y0 U Y1 V; the Y samples are the grey frame.
  kMjpeg = 2,  ///< V4L2_PIX_FMT_MJPEG: one JPEG per buffer, decoded to grey (needs libjpeg: DOCKCORE_HAVE_JPEG).
};

/// "grey" | "yuyv" | "mjpeg" → format; nullopt otherwise.
std::optional<CameraPixelFormat> parse_camera_pixel_format(std::string_view name);
const char* to_string(CameraPixelFormat f);

struct V4l2CameraOptions {
  std::string device = "/dev/video0";
  CameraPixelFormat format = CameraPixelFormat::kGrey;
  std::uint32_t width_px = 640;  ///< The device must grant exactly this size.
  std::uint32_t height_px = 480;
  std::uint32_t fps = 0;                 ///< Frame rate asked for with VIDIOC_S_PARM; 0 = the device's default.
  std::uint32_t buffers = 4;             ///< Capture buffers asked for (2..kMaxV4l2Buffers; the driver may grant more).
  std::uint32_t late_ms = 100;           ///< A frame dequeued more than this after its capture stamp counts as late.
  std::uint32_t reconnect_min_ms = 200;  ///< First reopen delay after the device vanished; doubles per failure.
  std::uint32_t reconnect_max_ms = 2000;  ///< Cap of the reopen delay.
};

/// Most capture buffers the driver maps.
constexpr std::uint32_t kMaxV4l2Buffers = 8;
/// Largest frame side accepted, px.
constexpr std::uint32_t kMaxCameraSidePx = 8192;

/// A V4L2 capture device with the lifecycle dockd needs on top of hal::CameraFrameSource.
class V4l2Camera : public hal::CameraFrameSource {
 public:
  virtual ~V4l2Camera() = default;
  /// True when the open device stamps buffers on CLOCK_MONOTONIC (V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC). When it does
  /// not, frames are stamped with CLOCK_MONOTONIC at dequeue (later than the exposure) and this is false.
  virtual bool driver_stamps() const = 0;
  /// The format as granted: bytes per row and bytes per image of the device's buffers.
  virtual std::uint32_t bytes_per_line() const = 0;
  virtual std::uint32_t size_image() const = 0;
};

/// Creates the camera and tries to open the device once. A device that is absent (ENOENT, ENODEV, ENXIO) is not an
/// error: next_frame() keeps retrying with back-off. nullptr + message in `error` when the options are invalid or the
/// device is there but is no streaming capture device or refuses the format or size (retrying would not help).
std::unique_ptr<V4l2Camera> open_v4l2_camera(const V4l2CameraOptions& options, std::string& error);

/// The frame bookkeeping of the driver, separated so it can be tested without a device.
namespace v4l2_detail {

/// Copies the Y samples of a YUYV image (`stride_bytes` per row, ≥ 2·width) into `grey` (width per row). O(w·h).
void yuyv_to_grey(const std::uint8_t* yuyv, std::uint32_t stride_bytes, std::uint32_t width_px, std::uint32_t height_px,
                  std::uint8_t* grey);
/// Copies a GREY image with row stride `stride_bytes` into a packed `grey` buffer. O(w·h).
void copy_grey(const std::uint8_t* src, std::uint32_t stride_bytes, std::uint32_t width_px, std::uint32_t height_px,
               std::uint8_t* grey);

/// Sequence-gap counting: frames the device numbered but did not deliver. reset() after a (re)open.
class SequenceTracker {
 public:
  /// Frames missing between the previous sequence number and `sequence` (0 for the first after reset, and for a
  /// number that did not advance). O(1).
  std::uint64_t gap(std::uint32_t sequence) {
    std::uint64_t missing = 0;
    if (have_ && sequence > last_) missing = static_cast<std::uint64_t>(sequence - last_ - 1u);
    have_ = true;
    last_ = sequence;
    return missing;
  }
  void reset() { have_ = false; }

 private:
  bool have_ = false;
  std::uint32_t last_ = 0;
};

/// A buffer is a usable frame when the driver did not flag it as errored and filled at least the image size.
inline bool frame_complete(std::uint32_t bytes_used, std::uint32_t expected_bytes, bool error_flag) {
  return !error_flag && bytes_used >= expected_bytes;
}

/// A dequeued buffer → the grey frame, for every format: GREY and YUYV copied (row stride bytes_per_line), MJPEG
/// decoded with libjpeg. Owns the frame (and for MJPEG a spare frame and the decoder). A buffer that is not a frame —
/// flagged errored, fewer bytes than a GREY/YUYV image, an empty, undecodable or damaged JPEG, a JPEG of another
/// size — is counted in corrupt() and leaves frame() untouched.
class FrameConverter {
 public:
  /// Allocates the frame(s) and, for MJPEG, the decoder. The layout defaults to packed rows.
  FrameConverter(CameraPixelFormat format, std::uint32_t width_px, std::uint32_t height_px);
  ~FrameConverter();
  FrameConverter(const FrameConverter&) = delete;
  FrameConverter& operator=(const FrameConverter&) = delete;
  /// The granted row stride of GREY and YUYV buffers, bytes (≥ a row of pixels; ignored for MJPEG). O(1).
  void set_bytes_per_line(std::uint32_t bytes_per_line);
  /// Bytes a complete GREY / YUYV buffer fills (the last row needs only its pixels); 0 for MJPEG. O(1).
  std::uint32_t min_bytes() const;
  /// Converts `bytes_used` bytes of a dequeued buffer. True: frame() holds the new image. False: corrupt (counted;
  /// the reason in error()), frame() as before. O(w·h) (MJPEG: plus the decode).
  bool convert(const std::uint8_t* data, std::uint32_t bytes_used, bool error_flag);
  /// The latest good frame: width × height, packed rows (all zero before the first).
  const std::uint8_t* frame() const { return frame_; }
  std::uint64_t corrupt() const { return corrupt_; }
  /// Why the last convert() failed; "" after a success. Never null.
  const char* error() const { return error_; }

 private:
  bool reject(const char* why);

  CameraPixelFormat format_;
  std::uint32_t width_px_, height_px_;
  std::uint32_t bytes_per_line_;
  std::vector<std::uint8_t> a_, b_;  ///< The frame and, for MJPEG, the spare the next one is decoded into.
  std::uint8_t* frame_ = nullptr;
  std::uint8_t* spare_ = nullptr;
  struct Jpeg;
  std::unique_ptr<Jpeg> jpeg_;
  std::uint64_t corrupt_ = 0;
  char error_[200] = "";
};

}  // namespace v4l2_detail

}  // namespace dockcore::drivers
