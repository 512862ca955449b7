// Counts the heap allocations of a test binary, so a test can prove that a stage allocates
// nothing after Configure: every operator new and new[] (plain, nothrow and aligned, replaced
// for the whole binary), and malloc, calloc and realloc called from the code linked into it
// (the project's static libraries and the tests: lb_alloc_counter links them with
// -Wl,--wrap=malloc,--wrap=calloc,--wrap=realloc). Calls made inside shared libraries (libc,
// libstdc++) to malloc itself are not seen; their operator new calls are. alloc_counter_test.cc
// checks that each kind counts exactly once.
#pragma once

#include <cstddef>

namespace lb::testing {

// Allocations so far, all kinds together.
size_t AllocationCount();

}  // namespace lb::testing
