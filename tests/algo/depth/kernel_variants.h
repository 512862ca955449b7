// The data term's kernel tables a test forces one by one (data_term_kernels.h): every table this
// processor runs but the C reference, and a skip when there is none.
#pragma once

#include <vector>

#include "algo/core/cpu.h"
#include "algo/depth/data_term_kernels.h"

namespace lb::kerneltest {

// (armhf builds the NEON tables whatever its baseline: they count where the kernel says the core
// has NEON, which the tests' main read as the programs do: tests/support/test_main.cc.)
inline std::vector<dtk::Variant> Others() {
  dtk::Variant v[dtk::kMaxVariants];
  const int32_t n = dtk::Variants(v);
  return std::vector<dtk::Variant>(v + 1, v + n);  // v[0] is the reference
}

}  // namespace lb::kerneltest

#define LB_SKIP_WITHOUT_VARIANTS()                                                  \
  if (lb::kerneltest::Others().empty()) {                                           \
    GTEST_SKIP() << "this processor runs no data term kernels but the C reference"; \
  }
