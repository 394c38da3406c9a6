#pragma once
// Counts malloc/calloc/realloc calls made while armed, for the heap tests (core_alloc_trap, test_dockd_heap,
// test_camera_heap). The counting functions interpose libc's in malloc_count.cpp, which the test links as one of
// its own sources; not for sanitizer builds, whose runtime owns malloc.
#include <cstddef>

namespace dockcore_test {

/// Counting is on while this is true.
extern volatile bool g_armed;
/// Allocation calls counted so far (never reset by the counter).
extern volatile std::size_t g_allocs;

}  // namespace dockcore_test
