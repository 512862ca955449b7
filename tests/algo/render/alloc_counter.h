// Counts heap allocations (operator new is replaced for the whole test binary), so a test can
// prove that rendering allocates nothing after Configure.
#pragma once

#include <cstdint>

namespace lb::test {

int64_t AllocationCount();

}  // namespace lb::test
