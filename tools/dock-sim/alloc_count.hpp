#pragma once
// Heap-call counter of the dock-sim process (alloc_count.cpp interposes malloc/calloc/realloc, which operator new
// goes through). Used by `dock-sim soak` to show that dockcore's calls never allocate while the simulator around them
// may. Counting is off until alloc_count_arm(true); it is not available in sanitizer builds (their runtime owns
// malloc) — then alloc_count_available() is false and every count stays 0.
#include <cstddef>
#include <cstdint>

namespace docksim_cli {

/// Heap calls counted since arming.
struct AllocCounts {
  std::uint64_t total = 0;     ///< Every malloc/calloc/realloc (and so every operator new) in the process.
  std::uint64_t in_scope = 0;  ///< Those made while an AllocScope was open (dock-sim soak: inside dockcore's calls).
};

/// True when the counting malloc is linked in (plain builds on glibc). O(1).
bool alloc_count_available();
/// Starts (true) or stops (false) counting. O(1).
void alloc_count_arm(bool on);
/// Counts so far (never reset; subtract two readings). O(1).
AllocCounts alloc_counts();
/// Bytes in use by the malloc heap now (glibc mallinfo2 uordblks + hblkhd), or 0 when unavailable. O(arenas).
std::size_t heap_in_use_bytes();
/// The process's resident set (VmRSS of /proc/self/status) in KiB, or -1 when unreadable. Opens a file (allocates).
long rss_kib();

/// Marks the calls made while it lives as "in scope" (not nestable). Single-threaded use.
class AllocScope {
 public:
  AllocScope();
  ~AllocScope();
  AllocScope(const AllocScope&) = delete;
  AllocScope& operator=(const AllocScope&) = delete;
};

}  // namespace docksim_cli
