// Counts heap allocations made by this process: every operator new, and malloc/calloc/realloc
// from the statically linked project libraries (the test links with -Wl,--wrap=malloc etc.).
#pragma once

#include <cstddef>

namespace lb::testing {

size_t AllocationCount();

}  // namespace lb::testing
