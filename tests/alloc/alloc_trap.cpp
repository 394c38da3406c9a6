// Runs core's per-scan work with every heap entry point counted; any allocation after set-up is a failure.
// Interposes malloc/calloc/realloc/free (glibc's __libc_* do the work), which also catches operator new.
#include <cstddef>
#include <cstdio>
#include <cstdlib>

#include "dockcore/dock_profile.hpp"
#include "dockcore/laser_scan.hpp"

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

using namespace dockcore;

static int check(const char* what, std::size_t before) {
  const std::size_t n = g_allocs - before;
  std::printf("%-28s allocations: %zu\n", what, n);
  return n == 0 ? 0 : 1;
}

int main() {
  static LaserScan scan;
  scan.reset(720, -kPi, kTwoPi / 720, 0);
  for (std::size_t i = 0; i < scan.count; ++i) scan.ranges_m[i] = 1.0 + 0.001 * static_cast<double>(i % 7);
  static ScanPoints pts;
  int failures = 0;
  g_armed = true;
  // Self-check: the trap must see an allocation, or a pass below would mean nothing.
  std::size_t b = g_allocs;
  void* volatile probe = std::malloc(16);
  std::free(probe);
  if (g_allocs - b != 1) {
    std::printf("FAIL: allocation trap is not counting\n");
    return 1;
  }
  b = g_allocs;
  scan_to_points(scan.view(), Pose2{}, 0.05, 10.0, pts);
  failures += check("scan_to_points", b);
  b = g_allocs;
  DockProfile prof;
  builtin_profile("plate-v", prof);
  failures += check("builtin_profile", b);
  g_armed = false;
  std::printf("%s\n", failures == 0 ? "PASS: no heap use" : "FAIL: heap used on a per-scan path");
  return failures == 0 ? 0 : 1;
}
