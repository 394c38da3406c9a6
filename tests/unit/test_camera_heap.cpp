// The V4L2 driver's heap after start-up: retrying a device that is not there (open attempts with back-off, each
// failure written into last_error()) calls malloc/calloc/realloc zero times. The calls are counted by
// tests/support/malloc_count.hpp; not built in sanitizer builds, whose runtime owns malloc.
#include <cstddef>
#include <string>

#include "../support/malloc_count.hpp"
#include "dockcore/drivers/v4l2_camera.hpp"

#include "CppUTest/TestHarness.h"

using dockcore_test::g_allocs;
using dockcore_test::g_armed;

TEST_GROUP(V4l2Heap){};

namespace {
/// Retries an absent device of `format`: zero heap calls after the first attempt.
void check_retries_allocate_nothing(dockcore::drivers::CameraPixelFormat format) {
  dockcore::drivers::V4l2CameraOptions o;
  o.format = format;
  o.device = "/nonexistent/video9";
  o.reconnect_min_ms = 10;
  o.reconnect_max_ms = 10;
  std::string err;
  auto cam = dockcore::drivers::open_v4l2_camera(o, err);
  CHECK_TEXT(cam != nullptr, err.c_str());
  dockcore::hal::CameraFrame f;
  cam->next_frame(f, 5);  // first use of anything lazily set up (strerror's locale data)
  // The counter counts (through a volatile pointer, so the call cannot be optimised away).
  void* (*volatile alloc)(std::size_t) = malloc;
  g_allocs = 0;
  g_armed = true;
  void* p = alloc(16);
  g_armed = false;
  free(p);
  CHECK_EQUAL(1u, static_cast<unsigned>(g_allocs));
  g_allocs = 0;
  g_armed = true;
  for (int i = 0; i < 5; ++i) cam->next_frame(f, 30);  // ≈ 15 open attempts
  g_armed = false;
  CHECK_EQUAL(0u, static_cast<unsigned>(g_allocs));
  STRCMP_CONTAINS("camera /nonexistent/video9: open: No such file or directory", cam->last_error());
}
}  // namespace

TEST(V4l2Heap, RetryingAnAbsentDeviceAllocatesNothing) {
  check_retries_allocate_nothing(dockcore::drivers::CameraPixelFormat::kGrey);
}

#if DOCKCORE_HAVE_JPEG
// MJPEG's spare frame and decoder are made with the camera, not per open attempt.
TEST(V4l2Heap, RetryingAnAbsentMjpegDeviceAllocatesNothing) {
  check_retries_allocate_nothing(dockcore::drivers::CameraPixelFormat::kMjpeg);
}
#endif
