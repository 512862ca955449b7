// The data term's row kernels (data_term.h): a plain C reference (data_term_ref.cc) and SIMD
// twins that give the same bits (data_term_avx2.cc on x86-64, data_term_neon.cc on ARM), picked
// once when the data term is carved. Internal to algo/depth.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/depth/data_term.h"

namespace lb {

struct DataTerm::Kernels {
  void (*census)(const uint8_t* const* rows, int32_t x0, int32_t x1, int32_t w, uint8_t* out);
  void (*cost)(const uint8_t* ref, const uint8_t* img, const uint8_t* cref, const uint8_t* cimg,
               ptrdiff_t plane, int32_t n, int32_t f, int32_t trunc, int32_t cw, uint8_t* out);
  void (*hsum)(const uint8_t* cost, int32_t x0, int32_t x1, uint16_t* hsum);
  void (*select)(const uint16_t* const* rows, int32_t others, int32_t x0, int32_t x1,
                 uint16_t* out);
};

namespace dtk {

inline constexpr int32_t kMaxBest = 8;  // best half of up to 15 other views

// Q15 reciprocal of `keep`: the mean of the kept sums, rounded (error < 1 for D <= 2295).
inline uint32_t RecipQ15(int32_t keep) {
  return (32768u + static_cast<uint32_t>(keep) / 2) / static_cast<uint32_t>(keep);
}

void CensusRowC(const uint8_t* const* rows, int32_t x0, int32_t x1, int32_t w, uint8_t* out);
void CostRowC(const uint8_t* ref, const uint8_t* img, const uint8_t* cref, const uint8_t* cimg,
              ptrdiff_t plane, int32_t n, int32_t f, int32_t trunc, int32_t cw, uint8_t* out);
void HSumRowC(const uint8_t* cost, int32_t x0, int32_t x1, uint16_t* hsum);
void SelectRowC(const uint16_t* const* rows, int32_t others, int32_t x0, int32_t x1, uint16_t* out);

extern const DataTerm::Kernels kReference;
// This target's SIMD kernels when the processor has them, else nullptr.
const DataTerm::Kernels* SimdKernels();

}  // namespace dtk
}  // namespace lb
