#pragma once
// Decodes a JPEG file to 8-bit grey with libjpeg (its own colour conversion, JCS_GRAYSCALE), for camera-check's
// benchmark frame and the detector's real-photo test. Host tool code: allocates freely.
#include <cstdint>
#include <cstdio>
#include <csetjmp>
#include <cstring>
#include <string>
#include <vector>

#include <jpeglib.h>

namespace camera_check {

struct GreyImage {
  std::uint32_t width_px = 0;
  std::uint32_t height_px = 0;
  std::vector<std::uint8_t> pixels;  ///< width × height, packed rows.
};

namespace detail {
struct JpegError {
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};
inline void on_jpeg_error(j_common_ptr c) {
  JpegError* e = reinterpret_cast<JpegError*>(c->err);
  (*c->err->format_message)(c, e->message);
  std::longjmp(e->jump, 1);
}
}  // namespace detail

namespace detail {
/// The decode itself. libjpeg reports errors by longjmp back into this frame, so it holds no C++ object of its own
/// (a string built here could be clobbered): the caller owns the file and turns `message` into its error.
inline bool decode_jpeg_grey_file(std::FILE* f, GreyImage& out, char (&message)[JMSG_LENGTH_MAX]) {
  jpeg_decompress_struct cinfo{};
  JpegError err{};
  cinfo.err = jpeg_std_error(&err.mgr);
  err.mgr.error_exit = on_jpeg_error;
  if (setjmp(err.jump) != 0) {
    std::memcpy(message, err.message, sizeof message);
    jpeg_destroy_decompress(&cinfo);
    return false;
  }
  jpeg_create_decompress(&cinfo);
  jpeg_stdio_src(&cinfo, f);
  jpeg_read_header(&cinfo, TRUE);
  cinfo.out_color_space = JCS_GRAYSCALE;
  jpeg_start_decompress(&cinfo);
  out.width_px = cinfo.output_width;
  out.height_px = cinfo.output_height;
  out.pixels.assign(static_cast<std::size_t>(out.width_px) * out.height_px, 0);
  while (cinfo.output_scanline < cinfo.output_height) {
    JSAMPROW row = out.pixels.data() + static_cast<std::size_t>(cinfo.output_scanline) * out.width_px;
    jpeg_read_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  return true;
}
}  // namespace detail

/// True + `out` filled, or false + `error` ("FILE: why").
inline bool decode_jpeg_grey(const std::string& path, GreyImage& out, std::string& error) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) {
    error = path + ": cannot open";
    return false;
  }
  char message[JMSG_LENGTH_MAX] = {};
  const bool ok = detail::decode_jpeg_grey_file(f, out, message);
  std::fclose(f);
  if (!ok) error = path + ": " + message;
  return ok;
}

}  // namespace camera_check
