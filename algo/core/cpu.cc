#include "algo/core/cpu.h"

#include <atomic>

namespace lb {
namespace {

CpuFeatures BuildDefault() {
  CpuFeatures f;
#if defined(__x86_64__) || defined(__i386__)
  f.ssse3 = __builtin_cpu_supports("ssse3");
  f.avx2 = __builtin_cpu_supports("avx2");
#endif
#if defined(__aarch64__)
  f.neon = true;  // part of the architecture
#endif
  return f;
}

// Three bits, so the features are read and replaced whole by any thread.
std::atomic<unsigned> g_bits{~0u};

unsigned Pack(const CpuFeatures& f) {
  return (f.ssse3 ? 1u : 0u) | (f.avx2 ? 2u : 0u) | (f.neon ? 4u : 0u);
}

}  // namespace

CpuFeatures CurrentCpu() {
  unsigned bits = g_bits.load(std::memory_order_acquire);
  if (bits == ~0u) bits = Pack(BuildDefault());
  CpuFeatures f;
  f.ssse3 = (bits & 1u) != 0;
  f.avx2 = (bits & 2u) != 0;
  f.neon = (bits & 4u) != 0;
  return f;
}

void SetCpu(const CpuFeatures& features) {
  g_bits.store(Pack(features), std::memory_order_release);
}

}  // namespace lb
