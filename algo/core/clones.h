// Plain C++ loops written to vectorize: on x86-64 (GCC) a function marked LB_CLONES_AVX2 is also
// compiled for AVX2 (twice the lanes) and the loader picks the copy the CPU runs; the same source,
// so the same bits (the ctest depth_bits_without_avx2 runs the pinned depth tests on a CPU
// without AVX2, where the baseline copy is chosen). Hand-written SIMD goes elsewhere: in the
// _avx2.cc / _neon.cc twins of a C reference, picked into a kernel table (docs/simd.md).
#pragma once

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define LB_CLONES_AVX2 __attribute__((target_clones("avx2", "default")))
#else
#define LB_CLONES_AVX2
#endif
