// The data term's row kernels (data_term.h) and the plane sweep's span kernel (warp_cost.h): a
// plain C reference (data_term_ref.cc, warp_cost.cc) and SIMD twins that give the same bits
// (data_term_avx2.cc and warp_cost_avx2.cc on x86-64, data_term_neon.cc and warp_cost_neon.cc on
// ARM), picked once when the data term is carved (SimdKernels, the one place that chooses). On
// x86-64 the C cost kernel is also compiled for SSSE3 (the table of a CPU without AVX2) and for
// AVX2 (the AVX2 kernel's short rows). Every table is run against the reference by
// tests/algo/depth/data_term_kernels_test.cc. Internal to algo/depth.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/depth/data_term.h"
#include "algo/depth/warp_cost.h"

namespace lb {

struct DataTerm::Kernels {
  void (*census)(const uint8_t* const* rows, int32_t x0, int32_t x1, int32_t w, uint8_t* out);
  void (*cost)(const uint8_t* ref, const uint8_t* img, const uint8_t* cref, const uint8_t* cimg,
               ptrdiff_t plane, int32_t n, int32_t f, int32_t trunc, int32_t cw, uint8_t* out);
  void (*hsum)(const uint8_t* cost, int32_t x0, int32_t x1, uint16_t* hsum);
  void (*select)(const uint16_t* const* rows, int32_t others, int32_t x0, int32_t x1,
                 uint16_t* out);
  PlaneSpanFn plane;  // the plane sweep's pixel costs, a run of spans (warp_cost.h)
  // The reference row's lanes for `plane` (warp_cost.h: RefLanes) of columns x0..x1-1 of the
  // row at ref / cref (width columns), column x0 at lanes[0]; nullptr when `plane` does not
  // read them.
  void (*plane_lanes)(const uint8_t* ref, const uint8_t* cref, int32_t width, int32_t x0,
                      int32_t x1, int32_t* lanes, ptrdiff_t stride);
};

namespace dtk {

inline constexpr int32_t kMaxBest = 8;  // best half of up to 15 other views
// A select kernel (the signature of Kernels::select); the SIMD twins keep one instance per
// kept count, 1 .. kMaxBest, in a table.
using SelectRowFn = void (*)(const uint16_t* const* rows, int32_t others, int32_t x0, int32_t x1,
                             uint16_t* out);
// The select kernel that runs the instance of `by_keep` (kMaxBest entries) for the kept count.
template <const SelectRowFn* by_keep>
void SelectByKeep(const uint16_t* const* rows, int32_t others, int32_t x0, int32_t x1,
                  uint16_t* out) {
  by_keep[(others + 1) / 2 - 1](rows, others, x0, x1, out);
}

// Q15 reciprocal of `keep`: the mean of the kept sums, rounded (error < 1 for D <= 2295).
inline uint32_t RecipQ15(int32_t keep) {
  return (32768u + static_cast<uint32_t>(keep) / 2) / static_cast<uint32_t>(keep);
}

void CensusRowC(const uint8_t* const* rows, int32_t x0, int32_t x1, int32_t w, uint8_t* out);
void CostRowC(const uint8_t* ref, const uint8_t* img, const uint8_t* cref, const uint8_t* cimg,
              ptrdiff_t plane, int32_t n, int32_t f, int32_t trunc, int32_t cw, uint8_t* out);
#if defined(__x86_64__)
// CostRowC's source compiled for SSSE3 and for AVX2 (the caller checks the CPU).
void CostRowCSsse3(const uint8_t* ref, const uint8_t* img, const uint8_t* cref, const uint8_t* cimg,
                   ptrdiff_t plane, int32_t n, int32_t f, int32_t trunc, int32_t cw, uint8_t* out);
void CostRowCAvx2(const uint8_t* ref, const uint8_t* img, const uint8_t* cref, const uint8_t* cimg,
                  ptrdiff_t plane, int32_t n, int32_t f, int32_t trunc, int32_t cw, uint8_t* out);
#endif
// The plane sweep's span kernels, one run of spans a call: the C reference (warp_cost.cc), AVX2
// (warp_cost_avx2.cc, the caller checks the CPU) and NEON (warp_cost_neon.cc).
void PlaneSpansC(const WarpRow& row, const WarpRun& run, uint8_t* out);
#if defined(__x86_64__)
void PlaneSpansAvx2(const WarpRow& row, const WarpRun& run, uint8_t* out);
void PlaneLanesAvx2(const uint8_t* ref, const uint8_t* cref, int32_t width, int32_t x0, int32_t x1,
                    int32_t* lanes, ptrdiff_t stride);
#endif
#if defined(__ARM_NEON) || defined(__arm__)
void PlaneSpansNeon(const WarpRow& row, const WarpRun& run, uint8_t* out);
#endif
void HSumRowC(const uint8_t* cost, int32_t x0, int32_t x1, uint16_t* hsum);
void SelectRowC(const uint16_t* const* rows, int32_t others, int32_t x0, int32_t x1, uint16_t* out);

extern const DataTerm::Kernels kReference;
// Each table when this build has it, else nullptr: AVX2 intrinsics (x86-64, also checked with
// cpuid), the C reference compiled for SSSE3 (x86-64, likewise), NEON intrinsics (ARM; armhf
// compiles them whatever its baseline, so the caller must know the core has NEON).
const DataTerm::Kernels* Avx2Kernels();
const DataTerm::Kernels* Ssse3Kernels();
const DataTerm::Kernels* NeonKernels();
// The fastest of those the processor has (AVX2, NEON, SSSE3), from the features the firmware
// read (algo/core/cpu.h); nullptr when none. The one place that chooses, asked at each Carve.
const DataTerm::Kernels* SimdKernels();

// Every table this processor runs (by algo/core/cpu.h for NEON), the reference first (tests
// compare them all).
struct Variant {
  const char* name;
  const DataTerm::Kernels* kernels;
};
inline constexpr int32_t kMaxVariants = 4;
int32_t Variants(Variant* out);  // out: kMaxVariants entries

}  // namespace dtk
}  // namespace lb
