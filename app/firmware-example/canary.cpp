// Linked only into firmware-canary: one heap allocation, which the firmware map check must reject.
#include <cstddef>
#include <cstdlib>

extern "C" {
// Kept by -Wl,--undefined (a GC root) although nothing calls it.
void* firmware_canary_alloc(std::size_t n) { return std::malloc(n); }
// newlib's malloc asks _sbrk for memory; a fixed pool is enough for the canary to link.
void* _sbrk(std::ptrdiff_t incr) {
  static unsigned char pool[1024];
  static std::size_t used = 0;
  void* p = pool + used;
  used += static_cast<std::size_t>(incr);
  return p;
}
}
