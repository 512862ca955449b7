#include "algo/depth/data_term_kernels.h"

#if defined(__ARM_NEON) || defined(__arm__)
#include <arm_neon.h>

// armhf's baseline has no NEON: this file's functions alone are compiled for it (after every
// include, so no inline function of a shared header is), and SimdKernels() takes them only
// where the firmware read that the core has NEON.
#if defined(__arm__)
#pragma GCC push_options
#pragma GCC target("fpu=neon")
#endif

namespace lb::dtk {
namespace {

// ---- NEON kernels (aarch64; armhf when built with NEON), 16 pixels a step, the last step
// overlapping the one before (the same bytes again); ARMv7 intrinsics only ----

void CensusRowNeon(const uint8_t* const* rows, int32_t x0, int32_t x1, int32_t w, uint8_t* out) {
  if (x1 - x0 < 16) return CensusRowC(rows, x0, x1, w, out);
  for (int32_t step = x0; step < x1; step += 16) {
    const int32_t x = step + 16 <= x1 ? step : x1 - 16;
    const int8x16_t c = vreinterpretq_s8_u8(vld1q_u8(rows[2] + x));
    uint8x16_t plane = vdupq_n_u8(0);
    int32_t bit = 0;
    // Unrolled whole, as the AVX2 kernel: the bit count and the plane stores are constants.
#pragma GCC unroll 5
    for (int32_t dy = 0; dy < 5; ++dy) {
#pragma GCC unroll 5
      for (int32_t dx = -2; dx <= 2; ++dx) {
        if (dy == 2 && dx == 0) continue;
        // Shift in one bit per neighbour: the compare mask is all ones where it is darker.
        const int8x16_t nb = vreinterpretq_s8_u8(vld1q_u8(rows[dy] + x + dx));
        plane = vsubq_u8(vaddq_u8(plane, plane), vcltq_s8(nb, c));
        if (++bit % 8 == 0) {
          vst1q_u8(out + (bit / 8 - 1) * w + x, plane);
          plane = vdupq_n_u8(0);
        }
      }
    }
  }
}

// Hamming distance over the three census planes, 0..24.
inline uint8x16_t Hamming(const uint8_t* a, const uint8_t* b, ptrdiff_t plane) {
  uint8x16_t h = vcntq_u8(veorq_u8(vld1q_u8(a), vld1q_u8(b)));
  h = vaddq_u8(h, vcntq_u8(veorq_u8(vld1q_u8(a + plane), vld1q_u8(b + plane))));
  return vaddq_u8(h, vcntq_u8(veorq_u8(vld1q_u8(a + 2 * plane), vld1q_u8(b + 2 * plane))));
}

// a * g + b * f in 16-bit lanes (<= 65280 for bytes, <= 6144 for distances), low and high half.
inline uint16x8_t Mix(uint8x8_t a, uint8x8_t b, uint8x8_t g, uint8x8_t f) {
  return vmlal_u8(vmull_u8(a, g), b, f);
}

// (a * g + b * f + 128) >> 8: the rounding narrow shift, exact below 65408.
inline uint8x16_t Lerp(uint8x16_t a, uint8x16_t b, uint8x8_t g, uint8x8_t f) {
  return vcombine_u8(vrshrn_n_u16(Mix(vget_low_u8(a), vget_low_u8(b), g, f), 8),
                     vrshrn_n_u16(Mix(vget_high_u8(a), vget_high_u8(b), g, f), 8));
}

// The sample's fraction, as in the AVX2 kernel: none (f = 0), any, a half (f = 128), a quarter or
// three quarters (f = 64, 192), the last three by byte averages: (a + b + 1) >> 1 is vrhadd, and
// (3 a + b + 2) >> 2 = vrhadd(a, vhadd(a, b)) (data_term_avx2.cc: QuarterLerp).
constexpr int32_t kWhole = 0, kFraction = 1, kHalf = 2, kQuarter = 3, kThreeQuarters = 4;

template <int32_t kFrac>
inline uint8x16_t MixBytes(uint8x16_t a, uint8x16_t b, uint8x8_t g, uint8x8_t f) {
  if constexpr (kFrac == kHalf) return vrhaddq_u8(a, b);
  if constexpr (kFrac == kQuarter) return vrhaddq_u8(a, vhaddq_u8(a, b));
  if constexpr (kFrac == kThreeQuarters) return vrhaddq_u8(b, vhaddq_u8(a, b));
  return Lerp(a, b, g, f);
}

// vld3 de-interleaves the colours; channel sums saturate at 255 as in the AVX2 kernel.
template <int32_t kFrac>
void CostRowNeonT(const uint8_t* ref, const uint8_t* img, const uint8_t* cref, const uint8_t* cimg,
                  ptrdiff_t plane, int32_t n, int32_t f, int32_t trunc, int32_t cw, uint8_t* out) {
  if (n < 16) return CostRowC(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
  const uint8x8_t g8 = vdup_n_u8(static_cast<uint8_t>(kFrac != kWhole ? 256 - f : 0));
  const uint8x8_t f8 = vdup_n_u8(static_cast<uint8_t>(f));
  const uint16_t cw16 = static_cast<uint16_t>(cw);
  const uint8x16_t trunc8 = vdupq_n_u8(static_cast<uint8_t>(trunc < 255 ? trunc : 255));
  for (int32_t step = 0; step < n; step += 16) {
    const int32_t x = step + 16 <= n ? step : n - 16;
    const uint8x16x3_t r = vld3q_u8(ref + 3 * x);
    const uint8x16x3_t a = vld3q_u8(img + 3 * x);
    const uint8x16_t h0 = Hamming(cref + x, cimg + x, plane);
    uint8x16_t sum = vdupq_n_u8(0), ham;
    if constexpr (kFrac == kFraction) {
      const uint8x16x3_t b = vld3q_u8(img + 3 * x + 3);
      for (int32_t c = 0; c < 3; ++c) {
        sum = vqaddq_u8(sum, vabdq_u8(r.val[c], Lerp(a.val[c], b.val[c], g8, f8)));
      }
      // ((h0 * g + h1 * f) * cw + 128) >> 8, <= 61568 before the shift.
      const uint8x16_t h1 = Hamming(cref + x, cimg + x + 1, plane);
      const uint16x8_t lo = vmulq_n_u16(Mix(vget_low_u8(h0), vget_low_u8(h1), g8, f8), cw16);
      const uint16x8_t hi = vmulq_n_u16(Mix(vget_high_u8(h0), vget_high_u8(h1), g8, f8), cw16);
      ham = vcombine_u8(vrshrn_n_u16(lo, 8), vrshrn_n_u16(hi, 8));
    } else if constexpr (kFrac != kWhole) {
      const uint8x16x3_t b = vld3q_u8(img + 3 * x + 3);
      for (int32_t c = 0; c < 3; ++c) {
        sum = vqaddq_u8(sum, vabdq_u8(r.val[c], MixBytes<kFrac>(a.val[c], b.val[c], g8, f8)));
      }
      // (cw h0) g + (cw h1) f = (h0 g + h1 f) cw, and cw * h <= 240 fits a byte.
      const uint8x16_t cw8 = vdupq_n_u8(static_cast<uint8_t>(cw));
      const uint8x16_t h1 = Hamming(cref + x, cimg + x + 1, plane);
      ham = MixBytes<kFrac>(vmulq_u8(h0, cw8), vmulq_u8(h1, cw8), g8, f8);
    } else {
      for (int32_t c = 0; c < 3; ++c) sum = vqaddq_u8(sum, vabdq_u8(r.val[c], a.val[c]));
      ham = vmulq_u8(h0, vdupq_n_u8(static_cast<uint8_t>(cw)));  // <= 240
    }
    vst1q_u8(out + x, vqaddq_u8(vminq_u8(sum, trunc8), ham));
  }
}

void CostRowNeon(const uint8_t* ref, const uint8_t* img, const uint8_t* cref, const uint8_t* cimg,
                 ptrdiff_t plane, int32_t n, int32_t f, int32_t trunc, int32_t cw, uint8_t* out) {
  switch (f) {
    case 0:
      return CostRowNeonT<kWhole>(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
    case 128:
      return CostRowNeonT<kHalf>(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
    case 64:
      return CostRowNeonT<kQuarter>(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
    case 192:
      return CostRowNeonT<kThreeQuarters>(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
    default:
      return CostRowNeonT<kFraction>(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
  }
}

void HSumRowNeon(const uint8_t* cost, int32_t x0, int32_t x1, uint16_t* hsum) {
  if (x1 - x0 < 16) return HSumRowC(cost, x0, x1, hsum);
  for (int32_t step = x0; step < x1; step += 16) {
    const int32_t x = step + 16 <= x1 ? step : x1 - 16;
    const uint8x16_t a = vld1q_u8(cost + x - 1), b = vld1q_u8(cost + x), c = vld1q_u8(cost + x + 1);
    vst1q_u16(hsum + x, vaddw_u8(vaddl_u8(vget_low_u8(a), vget_low_u8(b)), vget_low_u8(c)));
    vst1q_u16(hsum + x + 8, vaddw_u8(vaddl_u8(vget_high_u8(a), vget_high_u8(b)), vget_high_u8(c)));
  }
}

inline int16x8_t Window(const uint16_t* ring, ptrdiff_t stride, int32_t j, int32_t x) {
  const uint16_t* view = ring + 3 * j * stride + x;
  return vreinterpretq_s16_u16(vaddq_u16(vaddq_u16(vld1q_u16(view), vld1q_u16(view + stride)),
                                         vld1q_u16(view + 2 * stride)));
}

inline void Exchange(int16x8_t* v, int32_t i, int32_t j) {
  const int16x8_t lo = vminq_s16(v[i], v[j]);
  v[j] = vmaxq_s16(v[i], v[j]);
  v[i] = lo;
}

// Ascending sort of kN vectors lane by lane: the optimal 5 exchanges for 4, else insertion.
template <int32_t kN>
inline void SortNetwork(int16x8_t* v) {
  if constexpr (kN == 4) {
    Exchange(v, 0, 1);
    Exchange(v, 2, 3);
    Exchange(v, 0, 2);
    Exchange(v, 1, 3);
    Exchange(v, 1, 2);
  } else {
    for (int32_t i = 1; i < kN; ++i)
      for (int32_t j = i; j > 0; --j) Exchange(v, j - 1, j);
  }
}

// As the AVX2 kernel's SelectSeenStep: every window sorted, the views that see each lane counted,
// the first `keep` summed under a mask and each lane divided by its own keep.
template <int32_t kViews>
__attribute__((noinline)) void SelectSeenStep(const uint16_t* ring, ptrdiff_t stride, int32_t x,
                                              int16x8_t below_unseen, uint16_t* out) {
  constexpr int32_t kMost = (kViews + 1) / 2;
  int16x8_t v[kViews];
  for (int32_t j = 0; j < kViews; ++j) v[j] = Window(ring, stride, j, x);
  SortNetwork<kViews>(v);
  int16x8_t seen = vdupq_n_s16(kViews);  // vcgt gives all ones, -1, per view unseen
  for (int32_t j = 0; j < kViews; ++j) {
    seen = vaddq_s16(seen, vreinterpretq_s16_u16(vcgtq_s16(v[j], below_unseen)));
  }
  const uint16x8_t none = vceqq_s16(seen, vdupq_n_s16(0));
  const int16x8_t keep =
      vbslq_s16(none, vdupq_n_s16(kMost), vshrq_n_s16(vaddq_s16(seen, vdupq_n_s16(1)), 1));
  int16x8_t sum = v[0], recip = vdupq_n_s16(0);
  for (int32_t i = 1; i < kMost; ++i) {
    const uint16x8_t kept = vcgtq_s16(keep, vdupq_n_s16(static_cast<int16_t>(i)));
    sum = vaddq_s16(sum, vandq_s16(v[i], vreinterpretq_s16_u16(kept)));
    const uint16x8_t at_keep = vceqq_s16(keep, vdupq_n_s16(static_cast<int16_t>(i + 1)));
    recip = vbslq_s16(at_keep, vdupq_n_s16(static_cast<int16_t>(RecipQ15(i + 1))), recip);
  }
  const uint16x8_t one = vceqq_s16(keep, vdupq_n_s16(1));
  vst1q_u16(out + x, vreinterpretq_u16_s16(vbslq_s16(one, sum, vqrdmulhq_s16(sum, recip))));
}

// As the AVX2 kernel: the first kKeep windows and the other kB sorted apart, the kept sum that
// of min(A_i, B_(kKeep-1-i)); vqrdmulh is (2 * sum * recip + 2^15) >> 16 =
// (sum * recip + 2^14) >> 15. A step with a lane whose sorted maximum is `unseen` (a view that
// does not see it) goes to SelectSeenStep, which keeps fewer windows there.
template <int32_t kKeep, int32_t kB>
void SelectRowNeonT(const uint16_t* ring, ptrdiff_t stride, int32_t unseen, int32_t x0, int32_t x1,
                    uint16_t* out) {
  const int16x8_t recip = vdupq_n_s16(static_cast<int16_t>(kKeep == 1 ? 0 : RecipQ15(kKeep)));
  const int16x8_t below = vdupq_n_s16(static_cast<int16_t>(unseen - 1));
  for (int32_t step = x0; step < x1; step += 8) {
    const int32_t x = step + 8 <= x1 ? step : x1 - 8;
    int16x8_t a[kKeep], b[kB + (kB == 0 ? 1 : 0)];  // no empty array when kKeep is 1
    for (int32_t j = 0; j < kKeep; ++j) a[j] = Window(ring, stride, j, x);
    for (int32_t j = 0; j < kB; ++j) b[j] = Window(ring, stride, kKeep + j, x);
    SortNetwork<kKeep>(a);
    SortNetwork<kB>(b);
    if constexpr (kKeep > 1) {  // one or two views keep one window whatever they see
      const int16x8_t most = kB > 0 ? vmaxq_s16(a[kKeep - 1], b[kB - 1]) : a[kKeep - 1];
      const uint16x8_t over = vcgtq_s16(most, below);
      const uint16x4_t any = vorr_u16(vget_low_u16(over), vget_high_u16(over));
      if (vget_lane_u64(vreinterpret_u64_u16(any), 0) != 0) {
        SelectSeenStep<kKeep + kB>(ring, stride, x, below, out);
        continue;
      }
    }
    int16x8_t sum = a[0];
    if constexpr (kB == kKeep) sum = vminq_s16(a[0], b[kKeep - 1]);
    for (int32_t i = 1; i < kKeep; ++i) sum = vaddq_s16(sum, vminq_s16(a[i], b[kKeep - 1 - i]));
    vst1q_u16(out + x, vreinterpretq_u16_s16(kKeep == 1 ? sum : vqrdmulhq_s16(sum, recip)));
  }
}

template <int32_t kKeep>
void SelectRowNeonT(const uint16_t* ring, ptrdiff_t stride, int32_t others, int32_t unseen,
                    int32_t x0, int32_t x1, uint16_t* out) {
  if (x1 - x0 < 8) return SelectRowC(ring, stride, others, unseen, x0, x1, out);
  if (others == 2 * kKeep) return SelectRowNeonT<kKeep, kKeep>(ring, stride, unseen, x0, x1, out);
  SelectRowNeonT<kKeep, kKeep - 1>(ring, stride, unseen, x0, x1, out);
}

// The instance for each kept count (others + 1) / 2 = 1 .. kMaxBest.
constexpr SelectRowFn kNeonByKeep[kMaxBest] = {
    SelectRowNeonT<1>, SelectRowNeonT<2>, SelectRowNeonT<3>, SelectRowNeonT<4>,
    SelectRowNeonT<5>, SelectRowNeonT<6>, SelectRowNeonT<7>, SelectRowNeonT<8>};

}  // namespace

const DataTerm::Kernels* NeonKernels() {
  static constexpr DataTerm::Kernels kNeon = {CensusRowNeon,
                                              CostRowNeon,
                                              HSumRowNeon,
                                              SelectByKeep<kNeonByKeep>,
                                              RectRowWith<CostRowNeon, HSumRowNeon>,
                                              PlaneSpansNeon,
                                              nullptr,
                                              PlaneAnchorsC};
  return &kNeon;
}

}  // namespace lb::dtk
#if defined(__arm__)
#pragma GCC pop_options
#endif
#else
namespace lb::dtk {
const DataTerm::Kernels* NeonKernels() { return nullptr; }
}  // namespace lb::dtk
#endif
