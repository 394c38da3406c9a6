// JPEG to grey with libjpeg (see dockcore/drivers/jpeg_grey.hpp). Compiled only when libjpeg is found.
#include "dockcore/drivers/jpeg_grey.hpp"

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <new>

// jpeglib.h needs FILE and size_t declared before it.
#include <jpeglib.h>

namespace dockcore::drivers {

namespace jpeg_detail {
struct DecoderState {
  jpeg_decompress_struct cinfo{};
  jpeg_error_mgr mgr{};
  std::jmp_buf jump{};
  char message[JMSG_LENGTH_MAX] = "";
};
}  // namespace jpeg_detail

namespace {

jpeg_detail::DecoderState* state_of(j_common_ptr c) {
  // The constructor stores the State in client_data: the callbacks get only the libjpeg struct.
  return static_cast<jpeg_detail::DecoderState*>(c->client_data);
}

[[noreturn]] void on_error(j_common_ptr c) {
  jpeg_detail::DecoderState* s = state_of(c);
  (*c->err->format_message)(c, s->message);
  std::longjmp(s->jump, 1);
}

/// Warnings (msg_level −1) abort the decode like errors: a truncated or damaged frame is not a frame. Trace messages
/// (level ≥ 0) are ignored.
void on_message(j_common_ptr c, int msg_level) {
  if (msg_level < 0) on_error(c);
}

}  // namespace

JpegGreyDecoder::JpegGreyDecoder() : s_(std::make_unique<jpeg_detail::DecoderState>()) {
  s_->cinfo.err = jpeg_std_error(&s_->mgr);
  s_->mgr.error_exit = on_error;
  s_->mgr.emit_message = on_message;
  s_->cinfo.client_data = s_.get();
  // libjpeg's only failure here is running out of memory (its error handler jumps back): start-up code, so thrown.
  if (setjmp(s_->jump) != 0) throw std::bad_alloc();
  jpeg_create_decompress(&s_->cinfo);
}

JpegGreyDecoder::~JpegGreyDecoder() {
  jpeg_destroy_decompress(&s_->cinfo);
}

const char* JpegGreyDecoder::error() const {
  return s_->message;
}

namespace {

/// The decode itself. libjpeg reports errors by longjmp back into this frame, so it holds no C++ object with a
/// destructor; `out` (when not null) is resized here, `grey` (when not null) must hold want_w × want_h.
bool run_decode(jpeg_detail::DecoderState& s, const std::uint8_t* data, std::size_t bytes, std::uint32_t want_w,
                std::uint32_t want_h, std::uint8_t* grey, GreyImage* out) {
  jpeg_decompress_struct& c = s.cinfo;
  s.message[0] = '\0';
  if (setjmp(s.jump) != 0) {
    jpeg_abort_decompress(&c);  // back to the reusable start state
    return false;
  }
  if (bytes == 0) {
    std::snprintf(s.message, sizeof s.message, "empty buffer");
    return false;
  }
  jpeg_mem_src(&c, data, static_cast<unsigned long>(bytes));
  jpeg_read_header(&c, TRUE);
  c.out_color_space = JCS_GRAYSCALE;
  std::uint8_t* dst = grey;
  if (out != nullptr) {
    out->width_px = c.image_width;
    out->height_px = c.image_height;
    out->pixels.assign(static_cast<std::size_t>(c.image_width) * c.image_height, 0);
    dst = out->pixels.data();
  } else if (c.image_width != want_w || c.image_height != want_h) {
    std::snprintf(s.message, sizeof s.message, "image is %ux%u, the frame %ux%u", c.image_width, c.image_height, want_w,
                  want_h);
    jpeg_abort_decompress(&c);
    return false;
  }
  jpeg_start_decompress(&c);
  const std::size_t row_bytes = c.output_width;
  while (c.output_scanline < c.output_height) {
    JSAMPROW row = dst + static_cast<std::size_t>(c.output_scanline) * row_bytes;
    jpeg_read_scanlines(&c, &row, 1);
  }
  jpeg_finish_decompress(&c);
  return true;
}

}  // namespace

bool JpegGreyDecoder::decode(const std::uint8_t* data, std::size_t bytes, std::uint32_t width_px,
                             std::uint32_t height_px, std::uint8_t* grey) {
  return run_decode(*s_, data, bytes, width_px, height_px, grey, nullptr);
}

bool JpegGreyDecoder::decode(const std::uint8_t* data, std::size_t bytes, GreyImage& out) {
  return run_decode(*s_, data, bytes, 0, 0, nullptr, &out);
}

bool read_jpeg_grey(const std::string& path, GreyImage& out, std::string& error) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) {
    error = path + ": cannot open: " + std::strerror(errno);
    return false;
  }
  std::vector<std::uint8_t> bytes;
  std::uint8_t chunk[65536];
  std::size_t n = 0;
  while ((n = std::fread(chunk, 1, sizeof chunk, f)) > 0) bytes.insert(bytes.end(), chunk, chunk + n);
  const bool read_error = std::ferror(f) != 0;
  std::fclose(f);
  if (read_error) {
    error = path + ": read error";
    return false;
  }
  JpegGreyDecoder d;
  if (!d.decode(bytes.data(), bytes.size(), out)) {
    error = path + ": " + d.error();
    return false;
  }
  return true;
}

}  // namespace dockcore::drivers
