// The data term's kernel tables a test forces one by one (data_term_kernels.h): every table this
// processor runs but the C reference, and a skip when there is none.
#pragma once

#include <vector>

#if defined(__arm__)
#include <asm/hwcap.h>
#include <sys/auxv.h>
#endif

#include "algo/core/cpu.h"
#include "algo/depth/data_term_kernels.h"

namespace lb::kerneltest {

inline std::vector<dtk::Variant> Others() {
#if defined(__arm__)
  // armhf builds the NEON tables whatever its baseline: as the firmware does, they count where
  // the kernel says the core has NEON.
  CpuFeatures cpu = CurrentCpu();
  cpu.neon = (getauxval(AT_HWCAP) & HWCAP_NEON) != 0;
  SetCpu(cpu);
#endif
  dtk::Variant v[dtk::kMaxVariants];
  const int32_t n = dtk::Variants(v);
  return std::vector<dtk::Variant>(v + 1, v + n);  // v[0] is the reference
}

}  // namespace lb::kerneltest

#define LB_SKIP_WITHOUT_VARIANTS()                                                  \
  if (lb::kerneltest::Others().empty()) {                                           \
    GTEST_SKIP() << "this processor runs no data term kernels but the C reference"; \
  }
