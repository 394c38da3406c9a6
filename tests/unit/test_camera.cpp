// The V4L2 driver without a camera: its frame bookkeeping (YUYV → grey, strided grey copies, sequence gaps,
// short-buffer test), option checks, an absent device (retried, reported as disconnected, message naming the device
// and the call) and a device that is no camera. The driver against a real V4L2 device is the HIL case camera_vivid.
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "dockcore/drivers/v4l2_camera.hpp"

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
  CHECK_FALSE(parse_camera_pixel_format("mjpeg").has_value());
  STRCMP_EQUAL("yuyv", to_string(CameraPixelFormat::kYuyv));
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
