// The processor's SIMD capabilities as the kernel tables need them (algo/core/cpu.h): on 32-bit
// ARM only the kernel knows whether the core has NEON, and says so in the auxiliary vector.
#pragma once

#include "algo/core/cpu.h"

namespace lb {

// This processor's features: cpuid on x86-64, HWCAP on 32-bit ARM, NEON always on aarch64.
CpuFeatures DetectCpu();
// Hands DetectCpu() to algo/ (SetCpu); the programs call it once at start, before any stage is
// configured.
void UseThisCpu();

}  // namespace lb
