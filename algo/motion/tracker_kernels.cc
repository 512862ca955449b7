#include "algo/motion/tracker_kernels.h"

#include "algo/core/cpu.h"

namespace lb::tk {
namespace {

void SampleC(const uint8_t* p, ptrdiff_t stride, int32_t fx, int32_t fy, int32_t n, int32_t* out) {
  for (int32_t j = 0; j < n; ++j) {
    for (int32_t i = 0; i < n; ++i) out[j * n + i] = SampleQ4(p + j * stride + i, stride, fx, fy);
  }
}

WindowSums SumsC(const uint8_t* p, ptrdiff_t stride, int32_t fx, int32_t fy, int32_t n,
                 const int32_t* tmpl, const int32_t* gx, const int32_t* gy) {
  WindowSums s;
  for (int32_t j = 0; j < n; ++j) {
    for (int32_t i = 0; i < n; ++i) {
      const int32_t k = j * n + i;
      AddError(SampleQ4(p + j * stride + i, stride, fx, fy) - tmpl[k], gx[k], gy[k], &s);
    }
  }
  return s;
}

}  // namespace

const Kernels kReference = {SampleC, SumsC};

const Kernels* SimdKernels() {
  const CpuFeatures cpu = CurrentCpu();
  if (const Kernels* k = cpu.avx2 ? Avx2Kernels() : nullptr) return k;
  return cpu.neon ? NeonKernels() : nullptr;
}

}  // namespace lb::tk
