// What the processor offers the row kernels. algo/ asks the OS nothing, so on ARM, where only
// the kernel knows whether a 32-bit core has NEON (HWCAP), the firmware reads the capabilities
// once at start (firmware/platform/cpu_features.h) and hands them in here; the stages pick their
// kernel tables from them when they are configured. Until then: what the build assumes (NEON on
// aarch64, none on armhf) and, on x86-64, what cpuid says.
#pragma once

namespace lb {

struct CpuFeatures {
  bool ssse3 = false;
  bool avx2 = false;
  bool neon = false;
};

// The features the kernel tables are picked from.
CpuFeatures CurrentCpu();
// Replaces them (the firmware's reading; tests force a subset). Before any stage is configured:
// a table already picked stays.
void SetCpu(const CpuFeatures& features);

}  // namespace lb
