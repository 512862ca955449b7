#include "firmware/platform/cpu_features.h"

#if defined(__arm__)
#include <asm/hwcap.h>
#include <sys/auxv.h>
#endif

namespace lb {

CpuFeatures DetectCpu() {
  CpuFeatures f;
#if defined(__x86_64__) || defined(__i386__)
  f.ssse3 = __builtin_cpu_supports("ssse3");
  f.avx2 = __builtin_cpu_supports("avx2");
#elif defined(__aarch64__)
  f.neon = true;
#elif defined(__arm__)
  f.neon = (getauxval(AT_HWCAP) & HWCAP_NEON) != 0;
#endif
  return f;
}

void UseThisCpu() { SetCpu(DetectCpu()); }

}  // namespace lb
