// Counting malloc for dock-sim (see alloc_count.hpp). glibc's __libc_* entry points do the allocating, as in
// tests/alloc/alloc_trap.cpp; the counters are relaxed atomics because montecarlo runs worker threads (it never arms
// the counter, so its cost there is one relaxed load per heap call).
#include "alloc_count.hpp"

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer) || __has_feature(thread_sanitizer)
#define DOCKSIM_NO_ALLOC_COUNT 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__) || !defined(__GLIBC__)
#define DOCKSIM_NO_ALLOC_COUNT 1
#endif

#if !defined(DOCKSIM_NO_ALLOC_COUNT)
#include <malloc.h>
#endif

namespace {
std::atomic<bool> g_armed{false};
std::atomic<bool> g_in_scope{false};
std::atomic<std::uint64_t> g_total{0};
std::atomic<std::uint64_t> g_scope{0};

inline void count_one() {
  if (!g_armed.load(std::memory_order_relaxed)) return;
  g_total.fetch_add(1, std::memory_order_relaxed);
  if (g_in_scope.load(std::memory_order_relaxed)) g_scope.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

#if !defined(DOCKSIM_NO_ALLOC_COUNT)
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void __libc_free(void*);

void* malloc(std::size_t n) {
  count_one();
  return __libc_malloc(n);
}
void* calloc(std::size_t a, std::size_t b) {
  count_one();
  return __libc_calloc(a, b);
}
void* realloc(void* p, std::size_t n) {
  count_one();
  return __libc_realloc(p, n);
}
void free(void* p) { __libc_free(p); }
}
#endif

namespace docksim_cli {

bool alloc_count_available() {
#if defined(DOCKSIM_NO_ALLOC_COUNT)
  return false;
#else
  return true;
#endif
}

void alloc_count_arm(bool on) { g_armed.store(on, std::memory_order_relaxed); }

AllocCounts alloc_counts() {
  AllocCounts c;
  c.total = g_total.load(std::memory_order_relaxed);
  c.in_scope = g_scope.load(std::memory_order_relaxed);
  return c;
}

std::size_t heap_in_use_bytes() {
#if !defined(DOCKSIM_NO_ALLOC_COUNT) && defined(__GLIBC_PREREQ)
#if __GLIBC_PREREQ(2, 33)
  const struct mallinfo2 mi = mallinfo2();
  return mi.uordblks + mi.hblkhd;
#endif
#endif
  return 0;
}

long rss_kib() {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (f == nullptr) return -1;
  char line[256];
  long kib = -1;
  while (std::fgets(line, sizeof line, f) != nullptr) {
    if (std::strncmp(line, "VmRSS:", 6) == 0) {
      kib = std::strtol(line + 6, nullptr, 10);
      break;
    }
  }
  std::fclose(f);
  return kib;
}

AllocScope::AllocScope() { g_in_scope.store(true, std::memory_order_relaxed); }
AllocScope::~AllocScope() { g_in_scope.store(false, std::memory_order_relaxed); }

}  // namespace docksim_cli
