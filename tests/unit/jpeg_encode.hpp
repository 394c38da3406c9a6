#pragma once
// Encodes test images as JPEG with libjpeg (grey, or RGB stored as YCbCr 4:2:0), for the camera suites that feed the
// decoder (test_camera) or write JPEG frames for camera-check (test_camera_calib). Test code: allocates.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <jpeglib.h>

namespace camera_test {

/// `px`: width × height × components (1 grey, 3 RGB), packed rows.
inline std::vector<std::uint8_t> encode_jpeg(const std::vector<std::uint8_t>& px, int components,
                                             std::uint32_t width_px, std::uint32_t height_px, int quality = 95) {
  jpeg_compress_struct c{};
  jpeg_error_mgr err{};
  c.err = jpeg_std_error(&err);
  jpeg_create_compress(&c);
  unsigned char* buf = nullptr;
  unsigned long len = 0;
  jpeg_mem_dest(&c, &buf, &len);
  c.image_width = width_px;
  c.image_height = height_px;
  c.input_components = components;
  c.in_color_space = components == 1 ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_set_defaults(&c);
  jpeg_set_quality(&c, quality, TRUE);
  jpeg_start_compress(&c, TRUE);
  while (c.next_scanline < height_px) {
    JSAMPROW row = const_cast<JSAMPROW>(px.data() + static_cast<std::size_t>(c.next_scanline) * width_px *
                                                        static_cast<std::size_t>(components));
    jpeg_write_scanlines(&c, &row, 1);
  }
  jpeg_finish_compress(&c);
  jpeg_destroy_compress(&c);
  std::vector<std::uint8_t> out(buf, buf + len);
  std::free(buf);
  return out;
}

/// Writes `bytes` to `path`; false when it cannot.
inline bool write_file(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return false;
  const bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  return std::fclose(f) == 0 && ok;
}

}  // namespace camera_test
