// Counts every operator new of the test binary (alloc_counter.cc replaces the global one), so a
// test can prove that a capture allocates nothing. Its own file: the replacement must not be
// inlined into the code it watches (GCC then flags new/free pairs at -O3).
#pragma once

#include <cstddef>

namespace lb::testing {
size_t AllocationCount();
}  // namespace lb::testing
