#pragma once
/// @file JPEG to 8-bit grey with libjpeg (its own colour conversion to JCS_GRAYSCALE, which for a YCbCr image keeps
/// the Y channel and does not decode the chroma). One decoder for the V4L2 driver's MJPEG frames and the tools'
/// JPEG files (camera-check, the detector's real-photo test). Built when libjpeg is found (DOCKCORE_HAVE_JPEG).
///
/// Streams without Huffman tables (many UVC cameras send MJPEG frames without a DHT segment and rely on the
/// standard tables of the JPEG specification, Annex K.3): libjpeg-turbo inserts those tables itself when a frame has
/// none, so such frames decode as they are (tests/unit/test_camera.cpp, group V4l2Mjpeg, checks it).
///
/// Any libjpeg warning — a premature end of data, a corrupt entropy segment, an unexpected marker — is treated as an
/// error: libjpeg would otherwise fill the missing part of a truncated image with grey and report success.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace dockcore::drivers {

/// A decoded grey image, packed rows.
struct GreyImage {
  std::uint32_t width_px = 0;
  std::uint32_t height_px = 0;
  std::vector<std::uint8_t> pixels;  ///< width_px × height_px.
};

namespace jpeg_detail {
struct DecoderState;  ///< libjpeg's structs (jpeglib.h stays out of this header).
}  // namespace jpeg_detail

/// A reusable libjpeg decompressor (its state is created once; libjpeg allocates its per-image memory inside every
/// decode, so decode on a thread that may allocate). Not thread-safe: one decoder per thread.
class JpegGreyDecoder {
 public:
  /// Creates libjpeg's decompressor; std::bad_alloc when it cannot allocate.
  JpegGreyDecoder();
  ~JpegGreyDecoder();
  JpegGreyDecoder(const JpegGreyDecoder&) = delete;
  JpegGreyDecoder& operator=(const JpegGreyDecoder&) = delete;

  /// Decodes the JPEG in `data` (`bytes` long) into `grey` (`width_px` × `height_px`, packed) when the image is
  /// exactly that size. False, with the reason in error(), for a stream libjpeg cannot decode cleanly, or another
  /// size (then `grey` is untouched; after a decoding error part of it may have been written). O(bytes + w·h).
  bool decode(const std::uint8_t* data, std::size_t bytes, std::uint32_t width_px, std::uint32_t height_px,
              std::uint8_t* grey);
  /// The same for an image of any size: `out` resized to it (allocates). O(bytes + w·h).
  bool decode(const std::uint8_t* data, std::size_t bytes, GreyImage& out);
  /// Why the last decode failed ("" after a success). Never null.
  const char* error() const;

 private:
  std::unique_ptr<jpeg_detail::DecoderState> s_;
};

/// Reads and decodes a JPEG file. True + `out`, or false + `error` ("FILE: why"). Allocates.
bool read_jpeg_grey(const std::string& path, GreyImage& out, std::string& error);

}  // namespace dockcore::drivers
