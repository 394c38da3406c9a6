// The V4L2 driver's heap after start-up: retrying a device that is not there (open attempts with back-off, each
// failure written into last_error()) calls malloc/calloc/realloc zero times. The calls are counted by interposing
// them (as test_dockd_heap.cpp does); not built in sanitizer builds, whose runtime owns malloc.
#include <cstddef>
#include <string>

#include "dockcore/drivers/v4l2_camera.hpp"

#include "CppUTest/TestHarness.h"

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void __libc_free(void*);
}

namespace {
volatile bool g_armed = false;
volatile std::size_t g_allocs = 0;
}  // namespace

extern "C" void* malloc(std::size_t n) {
  if (g_armed) g_allocs = g_allocs + 1;
  return __libc_malloc(n);
}
extern "C" void* calloc(std::size_t a, std::size_t b) {
  if (g_armed) g_allocs = g_allocs + 1;
  return __libc_calloc(a, b);
}
extern "C" void* realloc(void* p, std::size_t n) {
  if (g_armed) g_allocs = g_allocs + 1;
  return __libc_realloc(p, n);
}
extern "C" void free(void* p) { __libc_free(p); }

TEST_GROUP(V4l2Heap){};

TEST(V4l2Heap, RetryingAnAbsentDeviceAllocatesNothing) {
  dockcore::drivers::V4l2CameraOptions o;
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
