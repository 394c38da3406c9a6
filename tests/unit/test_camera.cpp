// The V4L2 driver without a camera: its frame bookkeeping (YUYV → grey, strided grey copies, MJPEG decoding of JPEGs
// encoded here with libjpeg — grey and YCbCr, with and without Huffman tables —, sequence gaps, short, damaged and
// errored buffers counted corrupt with the frame left as it was), option checks, an absent device (retried, reported as
// disconnected, message naming the device and the call) and a device that is no camera. The driver against a real V4L2
// device is the HIL case camera_vivid.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "dockcore/drivers/v4l2_camera.hpp"

#if DOCKCORE_HAVE_JPEG
#include "jpeg_encode.hpp"
#endif

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using namespace dockcore::drivers;

TEST_GROUP(V4l2Frames){};

TEST(V4l2Frames, YuyvKeepsTheLumaOfEveryPixelAndSkipsRowPadding) {
  // 4×2 image, rows of 12 bytes (8 used + 4 padding): Y0 U Y1 V ...
  const std::uint8_t yuyv[24] = {10, 200, 11, 201, 12, 202, 13, 203, 99, 99, 99, 99,
                                 20, 210, 21, 211, 22, 212, 23, 213, 99, 99, 99, 99};
  std::uint8_t grey[8] = {};
  v4l2_detail::yuyv_to_grey(yuyv, 12, 4, 2, grey);
  const std::uint8_t want[8] = {10, 11, 12, 13, 20, 21, 22, 23};
  MEMCMP_EQUAL(want, grey, sizeof want);
}

TEST(V4l2Frames, GreyCopyPacksStridedRows) {
  const std::uint8_t src[12] = {1, 2, 3, 0, 0, 0, 4, 5, 6, 0, 0, 0};
  std::uint8_t grey[6] = {};
  v4l2_detail::copy_grey(src, 6, 3, 2, grey);
  const std::uint8_t want[6] = {1, 2, 3, 4, 5, 6};
  MEMCMP_EQUAL(want, grey, sizeof want);
}

TEST(V4l2Frames, SequenceGapsCountDroppedFramesAndRestartAfterReset) {
  v4l2_detail::SequenceTracker s;
  CHECK_EQUAL(0u, s.gap(100));  // first frame: nothing known before it
  CHECK_EQUAL(0u, s.gap(101));
  CHECK_EQUAL(3u, s.gap(105));  // 102, 103, 104 never arrived
  CHECK_EQUAL(0u, s.gap(105));  // a repeated number is no gap
  s.reset();                    // reopened: the device counts from anew
  CHECK_EQUAL(0u, s.gap(0));
  CHECK_EQUAL(1u, s.gap(2));
}

TEST(V4l2Frames, ShortOrErroredBuffersAreNotFrames) {
  CHECK_TRUE(v4l2_detail::frame_complete(640 * 480, 640 * 480, false));
  CHECK_TRUE(v4l2_detail::frame_complete(640 * 480 + 16, 640 * 480, false));
  CHECK_FALSE(v4l2_detail::frame_complete(640 * 480 - 1, 640 * 480, false));
  CHECK_FALSE(v4l2_detail::frame_complete(0, 640 * 480, false));
  CHECK_FALSE(v4l2_detail::frame_complete(640 * 480, 640 * 480, true));
}

TEST(V4l2Frames, FormatNames) {
  CHECK(parse_camera_pixel_format("grey") == CameraPixelFormat::kGrey);
  CHECK(parse_camera_pixel_format("yuyv") == CameraPixelFormat::kYuyv);
  CHECK(parse_camera_pixel_format("mjpeg") == CameraPixelFormat::kMjpeg);
  CHECK_FALSE(parse_camera_pixel_format("jpeg").has_value());
  STRCMP_EQUAL("yuyv", to_string(CameraPixelFormat::kYuyv));
  STRCMP_EQUAL("mjpeg", to_string(CameraPixelFormat::kMjpeg));
}

TEST(V4l2Frames, ConverterCopiesStridedYuyvAndCountsShortAndErroredBuffers) {
  v4l2_detail::FrameConverter conv(CameraPixelFormat::kYuyv, 4, 2);
  conv.set_bytes_per_line(12);
  CHECK_EQUAL(20u, conv.min_bytes());  // one padded row and the last row's 8 bytes
  const std::uint8_t yuyv[24] = {10, 200, 11, 201, 12, 202, 13, 203, 99, 99, 99, 99,
                                 20, 210, 21, 211, 22, 212, 23, 213, 99, 99, 99, 99};
  CHECK_TRUE(conv.convert(yuyv, 24, false));
  const std::uint8_t want[8] = {10, 11, 12, 13, 20, 21, 22, 23};
  MEMCMP_EQUAL(want, conv.frame(), sizeof want);
  const std::uint8_t other[24] = {};
  CHECK_FALSE(conv.convert(other, 19, false));
  CHECK_FALSE(conv.convert(other, 24, true));
  CHECK_EQUAL(2u, conv.corrupt());
  MEMCMP_EQUAL(want, conv.frame(), sizeof want);
}

TEST_GROUP(V4l2Open){};

TEST(V4l2Open, BadOptionsAreRefusedWithAMessage) {
  std::string err;
  V4l2CameraOptions o;
  o.device = "/nonexistent/video9";
  o.width_px = 0;
  POINTERS_EQUAL(nullptr, open_v4l2_camera(o, err).get());
  CHECK(err.find("/nonexistent/video9") != std::string::npos);
  o.width_px = 641;
  o.format = CameraPixelFormat::kYuyv;
  POINTERS_EQUAL(nullptr, open_v4l2_camera(o, err).get());
  CHECK(err.find("even width") != std::string::npos);
  o.width_px = 640;
  o.buffers = 1;
  POINTERS_EQUAL(nullptr, open_v4l2_camera(o, err).get());
  CHECK(err.find("buffers") != std::string::npos);
}

TEST(V4l2Open, AbsentDeviceIsRetriedAndReportedAsDisconnected) {
  std::string err;
  V4l2CameraOptions o;
  o.device = "/nonexistent/video9";
  o.reconnect_min_ms = 10;
  o.reconnect_max_ms = 20;
  auto cam = open_v4l2_camera(o, err);
  CHECK_TEXT(cam != nullptr, err.c_str());
  CHECK_FALSE(cam->connected());
  STRCMP_CONTAINS("camera /nonexistent/video9: open: No such file or directory", cam->last_error());
  hal::CameraFrame f;
  CHECK(cam->next_frame(f, 50) == hal::CameraFrameStatus::kDisconnected);
  CHECK(f.grey == nullptr);
  CHECK_EQUAL(0u, cam->counters().frames);
  CHECK_EQUAL(0u, cam->counters().disconnects);  // never connected: not a loss
}

TEST(V4l2Open, ANonCameraDeviceIsRefusedNamingTheIoctl) {
  std::string err;
  V4l2CameraOptions o;
  o.device = "/dev/null";
  POINTERS_EQUAL(nullptr, open_v4l2_camera(o, err).get());
  STRCMP_CONTAINS("camera /dev/null: VIDIOC_QUERYCAP:", err.c_str());
}

#if DOCKCORE_HAVE_JPEG

namespace {

constexpr std::uint32_t kW = 64, kH = 48;

/// A smooth test image: `components` 1 (grey) or 3 (RGB), values varying over the frame.
std::vector<std::uint8_t> test_image(int components) {
  std::vector<std::uint8_t> px(static_cast<std::size_t>(kW) * kH * static_cast<std::size_t>(components));
  for (std::uint32_t y = 0; y < kH; ++y) {
    for (std::uint32_t x = 0; x < kW; ++x) {
      for (int c = 0; c < components; ++c) {
        const std::uint32_t v =
            (x * (3 + 2 * static_cast<std::uint32_t>(c)) + y * (2 + static_cast<std::uint32_t>(c))) % 200 + 20;
        px[(static_cast<std::size_t>(y) * kW + x) * static_cast<std::size_t>(components) +
           static_cast<std::size_t>(c)] = static_cast<std::uint8_t>(v / (c + 1) + 30 * c);
      }
    }
  }
  return px;
}

/// The grey a decoder should give: the image itself, or the luma of the RGB one (JFIF's Y).
std::vector<double> luma(const std::vector<std::uint8_t>& px, int components) {
  std::vector<double> y(static_cast<std::size_t>(kW) * kH);
  for (std::size_t i = 0; i < y.size(); ++i) {
    if (components == 1) {
      y[i] = px[i];
    } else {
      y[i] = 0.299 * px[3 * i] + 0.587 * px[3 * i + 1] + 0.114 * px[3 * i + 2];
    }
  }
  return y;
}

/// Encodes with libjpeg (grey, or RGB stored as YCbCr 4:2:0) at quality 95.
std::vector<std::uint8_t> encode(const std::vector<std::uint8_t>& px, int components, std::uint32_t w = kW,
                                 std::uint32_t h = kH) {
  return camera_test::encode_jpeg(px, components, w, h);
}

/// The same stream without its DHT segments, as UVC cameras send MJPEG (the decoder must use the standard tables).
std::vector<std::uint8_t> strip_dht(const std::vector<std::uint8_t>& j) {
  std::vector<std::uint8_t> out(j.begin(), j.begin() + 2);  // SOI
  std::size_t i = 2;
  while (i + 4 <= j.size()) {
    if (j[i] == 0xFF && j[i + 1] == 0xDA) {  // start of scan: the rest is entropy-coded data
      out.insert(out.end(), j.begin() + static_cast<long>(i), j.end());
      break;
    }
    const std::size_t len = 2u + (static_cast<std::size_t>(j[i + 2]) << 8 | j[i + 3]);
    if (j[i + 1] != 0xC4)
      out.insert(out.end(), j.begin() + static_cast<long>(i), j.begin() + static_cast<long>(i + len));
    i += len;
  }
  return out;
}

bool has_dht(const std::vector<std::uint8_t>& j) {
  for (std::size_t i = 0; i + 1 < j.size(); ++i) {
    if (j[i] == 0xFF && j[i + 1] == 0xC4) return true;
  }
  return false;
}

/// Largest and mean absolute difference of the frame from the expected grey.
void compare(const std::uint8_t* frame, const std::vector<double>& want, double& max_err, double& mean_err) {
  max_err = 0;
  mean_err = 0;
  for (std::size_t i = 0; i < want.size(); ++i) {
    const double e = std::abs(static_cast<double>(frame[i]) - want[i]);
    max_err = e > max_err ? e : max_err;
    mean_err += e;
  }
  mean_err /= static_cast<double>(want.size());
}

void check_decodes(int components, bool without_dht) {
  const std::vector<std::uint8_t> px = test_image(components);
  std::vector<std::uint8_t> jpeg = encode(px, components);
  CHECK_TRUE(has_dht(jpeg));
  if (without_dht) {
    jpeg = strip_dht(jpeg);
    CHECK_FALSE(has_dht(jpeg));
  }
  v4l2_detail::FrameConverter conv(CameraPixelFormat::kMjpeg, kW, kH);
  CHECK_TRUE_TEXT(conv.convert(jpeg.data(), static_cast<std::uint32_t>(jpeg.size()), false), conv.error());
  double max_err = 0, mean_err = 0;
  compare(conv.frame(), luma(px, components), max_err, mean_err);
  // Quality 95 on a smooth image: a few grey levels at most (JPEG's own rounding of Y included).
  CHECK_TEXT(max_err <= 8, std::to_string(max_err).c_str());
  CHECK_TEXT(mean_err <= 1.5, std::to_string(mean_err).c_str());
  CHECK_EQUAL(0u, conv.corrupt());
}

}  // namespace

TEST_GROUP(V4l2Mjpeg){};

TEST(V4l2Mjpeg, GreyJpegDecodesToItsPixels) {
  check_decodes(1, false);
}
TEST(V4l2Mjpeg, YCbCrJpegDecodesToItsLuma) {
  check_decodes(3, false);
}
TEST(V4l2Mjpeg, GreyFrameWithoutHuffmanTablesDecodes) {
  check_decodes(1, true);
}
TEST(V4l2Mjpeg, YCbCrFrameWithoutHuffmanTablesDecodes) {
  check_decodes(3, true);
}

TEST(V4l2Mjpeg, DamagedBuffersAreCorruptAndLeaveTheFrameAsItWas) {
  // The frame holds a flat image; the damaged buffers are made from another one, so any pixel written shows.
  const std::vector<std::uint8_t> flat = encode(std::vector<std::uint8_t>(static_cast<std::size_t>(kW) * kH, 7), 1);
  const std::vector<std::uint8_t> good = encode(test_image(3), 3);
  v4l2_detail::FrameConverter conv(CameraPixelFormat::kMjpeg, kW, kH);
  CHECK_TRUE_TEXT(conv.convert(flat.data(), static_cast<std::uint32_t>(flat.size()), false), conv.error());
  const std::vector<std::uint8_t> before(conv.frame(), conv.frame() + static_cast<std::size_t>(kW) * kH);
  auto check_refused = [&](const std::vector<std::uint8_t>& buf, std::uint64_t corrupt, const char* why) {
    CHECK_FALSE_TEXT(conv.convert(buf.data(), static_cast<std::uint32_t>(buf.size()), false), why);
    CHECK_EQUAL(corrupt, conv.corrupt());
    CHECK_TEXT(conv.error()[0] != '\0', why);
    MEMCMP_EQUAL(before.data(), conv.frame(), before.size());
  };
  // Cut after 60 % (libjpeg would fill the rest with grey and call it a success, with a warning).
  check_refused(std::vector<std::uint8_t>(good.begin(), good.begin() + static_cast<long>(good.size() * 6 / 10)), 1,
                "truncated");
  std::vector<std::uint8_t> garbage(good.size());
  std::srand(5);
  for (std::uint8_t& b : garbage) b = static_cast<std::uint8_t>(std::rand());
  check_refused(garbage, 2, "garbage");
  check_refused({}, 3, "empty");
  // Entropy-coded data damaged in the middle.
  std::vector<std::uint8_t> damaged = good;
  for (std::size_t i = good.size() / 2; i < good.size() / 2 + 40; ++i) damaged[i] = 0xFF;
  check_refused(damaged, 4, "damaged");
  // A good JPEG of another size.
  const std::vector<std::uint8_t> small = encode(std::vector<std::uint8_t>(32 * 24, 100), 1, 32, 24);
  check_refused(small, 5, "wrong size");
  STRCMP_CONTAINS("32x24", conv.error());
  // A good JPEG in a buffer the driver flagged as errored.
  CHECK_FALSE(conv.convert(good.data(), static_cast<std::uint32_t>(good.size()), true));
  CHECK_EQUAL(6u, conv.corrupt());
  MEMCMP_EQUAL(before.data(), conv.frame(), before.size());
  // And a good one after all that decodes again.
  CHECK_TRUE_TEXT(conv.convert(good.data(), static_cast<std::uint32_t>(good.size()), false), conv.error());
  CHECK(std::memcmp(before.data(), conv.frame(), before.size()) != 0);
  STRCMP_EQUAL("", conv.error());
}

#endif  // DOCKCORE_HAVE_JPEG
