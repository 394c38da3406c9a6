// The interposers behind malloc_count.hpp: every call goes on to libc; armed calls are counted. free is not counted.
#include "malloc_count.hpp"

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void __libc_free(void*);
}

namespace dockcore_test {
volatile bool g_armed = false;
volatile std::size_t g_allocs = 0;
}  // namespace dockcore_test

using dockcore_test::g_allocs;
using dockcore_test::g_armed;

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
