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
namespace dtk {

inline constexpr int32_t kMaxOthers = 15;  // other views (DataTerm carves up to 16 views)
// Slack either side of a worker's pixel-cost row: the SIMD row kernels write whole vector steps
// that may run past the row's ends.
inline constexpr int32_t kPixelSlack = 32;

// One row of the rectified data term for every other view at once (the kernel's setup paid once
// a row, not once a view): view j's pixel costs at its shift and their horizontal 3-sums.
struct RectRow {
  const uint8_t* ref = nullptr;          // the reference's RGB row, `width` pixels
  const uint8_t* cref = nullptr;         // its census row: 3 planes of `width` bytes
  const uint8_t* img[kMaxOthers] = {};   // view j's RGB row
  const uint8_t* cimg[kMaxOthers] = {};  // view j's census row
  int32_t shift_q8[kMaxOthers] = {};     // column x samples view j at x * 256 + shift_q8[j]
  uint16_t* hsum[kMaxOthers] = {};       // out: view j's 3-sums of columns x0..x1-1, by x
  int32_t others = 0, width = 0, x0 = 0, x1 = 0;
  int32_t trunc = 0, cw = 0, invalid = 255;  // DataTermParams, DataTerm::invalid_cost()
  // Scratch of width + 2 + 2 * kPixelSlack bytes: column x's cost at pixel[kPixelSlack + 1 + x].
  uint8_t* pixel = nullptr;
};

// Where view j's samples are valid for columns c0..c1-1: x_lo..x_hi-1 (empty when not less);
// the sample's whole pixel (off) and Q8 fraction (f) of the right-hand one.
struct ValidSpan {
  int32_t off, f, x_lo, x_hi;
};
inline ValidSpan ValidColumns(int32_t shift_q8, int32_t width, int32_t c0, int32_t c1) {
  ValidSpan v;
  v.off = shift_q8 >> 8;  // floor
  v.f = shift_q8 & 255;
  const int32_t lo = -v.off, hi = width - (v.f > 0 ? 1 : 0) - v.off;
  v.x_lo = lo < c0 ? c0 : (lo > c1 ? c1 : lo);
  v.x_hi = hi < v.x_lo ? v.x_lo : (hi > c1 ? c1 : hi);
  return v;
}

using CostRowFn = void (*)(const uint8_t* ref, const uint8_t* img, const uint8_t* cref,
                           const uint8_t* cimg, ptrdiff_t plane, int32_t n, int32_t f,
                           int32_t trunc, int32_t cw, uint8_t* out);
using HSumRowFn = void (*)(const uint8_t* cost, int32_t x0, int32_t x1, uint16_t* hsum);

// The rectified row from a cost and a 3-sum kernel: out-of-image samples cost `invalid`, the
// 3-sums replicate the image's border pixels. The reference (with CostRowC and HSumRowC) and the
// tables without a fused kernel of their own.
template <CostRowFn kCost, HSumRowFn kHSum>
void RectRowWith(const RectRow& r) {
  const int32_t w = r.width;
  const int32_t c0 = r.x0 > 0 ? r.x0 - 1 : 0, c1 = r.x1 < w ? r.x1 + 1 : w;
  uint8_t* cost = r.pixel + kPixelSlack + 1;
  const uint8_t invalid = static_cast<uint8_t>(r.invalid);
  for (int32_t j = 0; j < r.others; ++j) {
    const ValidSpan v = ValidColumns(r.shift_q8[j], w, c0, c1);
    for (int32_t x = c0; x < v.x_lo; ++x) cost[x] = invalid;
    for (int32_t x = v.x_hi; x < c1; ++x) cost[x] = invalid;
    if (v.x_hi > v.x_lo) {
      kCost(r.ref + 3 * v.x_lo, r.img[j] + 3 * (v.x_lo + v.off), r.cref + v.x_lo,
            r.cimg[j] + v.x_lo + v.off, w, v.x_hi - v.x_lo, v.f, r.trunc, r.cw, cost + v.x_lo);
    }
    if (r.x0 == 0) cost[-1] = cost[0];
    if (r.x1 == w) cost[w] = cost[w - 1];
    kHSum(cost, r.x0, r.x1, r.hsum[j]);
  }
}

}  // namespace dtk

struct DataTerm::Kernels {
  void (*census)(const uint8_t* const* rows, int32_t x0, int32_t x1, int32_t w, uint8_t* out);
  void (*cost)(const uint8_t* ref, const uint8_t* img, const uint8_t* cref, const uint8_t* cimg,
               ptrdiff_t plane, int32_t n, int32_t f, int32_t trunc, int32_t cw, uint8_t* out);
  void (*hsum)(const uint8_t* cost, int32_t x0, int32_t x1, uint16_t* hsum);
  // D of columns x0..x1-1 from the ring of 3-sums: other view j's three rows (in any order: only
  // their sum counts) at ring + (3 * j + k) * stride, k = 0..2. A window summing to `unseen` (9
  // out-of-image samples) is a view that does not see the pixel (SelectRowC).
  void (*select)(const uint16_t* ring, ptrdiff_t stride, int32_t others, int32_t unseen, int32_t x0,
                 int32_t x1, uint16_t* out);
  // The rectified data term's row for every other view (dtk::RectRow): cost and hsum fused.
  void (*rect_row)(const dtk::RectRow& row);
  PlaneSpanFn plane;  // the plane sweep's pixel costs, a run of spans (warp_cost.h)
  // The reference row's lanes for `plane` (warp_cost.h: RefLanes) of columns x0..x1-1 of the
  // row at ref / cref (width columns), column x0 at lanes[0]; nullptr when `plane` does not
  // read them.
  void (*plane_lanes)(const uint8_t* ref, const uint8_t* cref, int32_t width, int32_t x0,
                      int32_t x1, int32_t* lanes, ptrdiff_t stride);
  PlaneAnchorsFn plane_anchors;  // a row's anchors for `plane` (warp_cost.h)
};

namespace dtk {

inline constexpr int32_t kMaxBest = 8;  // best half of up to 15 other views
// A select kernel (the signature of Kernels::select); the SIMD twins keep one instance per
// kept count, 1 .. kMaxBest, in a table.
using SelectRowFn = void (*)(const uint16_t* ring, ptrdiff_t stride, int32_t others, int32_t unseen,
                             int32_t x0, int32_t x1, uint16_t* out);
// The select kernel that runs the instance of `by_keep` (kMaxBest entries) for the kept count.
template <const SelectRowFn* by_keep>
void SelectByKeep(const uint16_t* ring, ptrdiff_t stride, int32_t others, int32_t unseen,
                  int32_t x0, int32_t x1, uint16_t* out) {
  by_keep[(others + 1) / 2 - 1](ring, stride, others, unseen, x0, x1, out);
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
// (warp_cost_avx2.cc, the caller checks the CPU) and NEON (warp_cost_neon.cc). Its anchor
// kernels, a row's anchors a call: the C reference and AVX2 (warp_cost_prep_avx2.cc; ARM takes the
// reference: aarch64 divides in one instruction, and NEON has no integer division to do it four at
// a time).
void PlaneSpansC(const WarpRow& row, const WarpRun& run, uint8_t* out);
bool PlaneAnchorsC(const int64_t* sums, const int64_t* changes, int32_t count, int32_t* x_q16,
                   int32_t* y_q16, bool* ok);
#if defined(__x86_64__)
void PlaneSpansAvx2(const WarpRow& row, const WarpRun& run, uint8_t* out);
bool PlaneAnchorsAvx2(const int64_t* sums, const int64_t* changes, int32_t count, int32_t* x_q16,
                      int32_t* y_q16, bool* ok);
void PlaneLanesAvx2(const uint8_t* ref, const uint8_t* cref, int32_t width, int32_t x0, int32_t x1,
                    int32_t* lanes, ptrdiff_t stride);
#endif
#if defined(__ARM_NEON) || defined(__arm__)
void PlaneSpansNeon(const WarpRow& row, const WarpRun& run, uint8_t* out);
#endif
void HSumRowC(const uint8_t* cost, int32_t x0, int32_t x1, uint16_t* hsum);
void SelectRowC(const uint16_t* ring, ptrdiff_t stride, int32_t others, int32_t unseen, int32_t x0,
                int32_t x1, uint16_t* out);

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
