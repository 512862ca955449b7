#include "algo/depth/data_term_kernels.h"

#if defined(__x86_64__)
#include <immintrin.h>
#define LB_AVX2 __attribute__((target("avx2")))

namespace lb::dtk {
namespace {

// ---- AVX2 kernels (x86-64, run-time dispatch): the last step of a row overlaps the one
// before (every output depends on its inputs only: the same bytes again); rows shorter than a
// step take the C reference ----

LB_AVX2 inline __m256i Load(const void* p) {
  return _mm256_loadu_si256(static_cast<const __m256i*>(p));
}
LB_AVX2 inline void Store(void* p, __m256i v) { _mm256_storeu_si256(static_cast<__m256i*>(p), v); }

LB_AVX2 void CensusRowAvx2(const uint8_t* const* rows, int32_t x0, int32_t x1, int32_t w,
                           uint8_t* out) {
  if (x1 - x0 < 32) return CensusRowC(rows, x0, x1, w, out);
  for (int32_t step = x0; step < x1; step += 32) {
    const int32_t x = step + 32 <= x1 ? step : x1 - 32;
    const __m256i c = Load(rows[2] + x);
    __m256i plane = _mm256_setzero_si256();
    int32_t bit = 0;
    // Unrolled whole, so the bit count and the plane stores are constants (the loops' own
    // bookkeeping cost more than the compares).
#pragma GCC unroll 5
    for (int32_t dy = 0; dy < 5; ++dy) {
#pragma GCC unroll 5
      for (int32_t dx = -2; dx <= 2; ++dx) {
        if (dy == 2 && dx == 0) continue;
        // Shift in one bit per neighbour: the compare mask is -1 where it is darker.
        plane = _mm256_sub_epi8(_mm256_add_epi8(plane, plane),
                                _mm256_cmpgt_epi8(c, Load(rows[dy] + x + dx)));
        if (++bit % 8 == 0) {
          Store(out + (bit / 8 - 1) * w + x, plane);
          plane = _mm256_setzero_si256();
        }
      }
    }
  }
}

// (a * (256 - f) + b * f + 128) >> 8 per byte = a + ((b - a) * f + 128) >> 8 (floor), in even
// and odd 16-bit lanes; mulhrs by f * 128 is (d * f * 128 + 2^14) >> 15, the same for
// |d| <= 255. Range 0..255, so the halves recombine without carries.
LB_AVX2 inline __m256i Lerp(__m256i a, __m256i b, __m256i f128) {
  const __m256i low = _mm256_set1_epi16(0x00ff);
  const __m256i ae = _mm256_and_si256(a, low), be = _mm256_and_si256(b, low);
  const __m256i ao = _mm256_srli_epi16(a, 8), bo = _mm256_srli_epi16(b, 8);
  const __m256i re = _mm256_add_epi16(ae, _mm256_mulhrs_epi16(_mm256_sub_epi16(be, ae), f128));
  const __m256i ro = _mm256_add_epi16(ao, _mm256_mulhrs_epi16(_mm256_sub_epi16(bo, ao), f128));
  return _mm256_or_si256(re, _mm256_slli_epi16(ro, 8));
}

// Census weight times the bit count of each byte (<= 80): nibble table lookups.
LB_AVX2 inline __m256i WeightedBits(__m256i v, __m256i lut) {
  const __m256i nib = _mm256_set1_epi8(0x0f);
  const __m256i lo = _mm256_shuffle_epi8(lut, _mm256_and_si256(v, nib));
  const __m256i hi = _mm256_shuffle_epi8(lut, _mm256_and_si256(_mm256_srli_epi16(v, 4), nib));
  return _mm256_add_epi8(lo, hi);
}

// cw * (bit count of i) for nibbles i = 0..15 (<= 40), in both lanes: a few vector operations,
// since a scalar table costs more per call than a short row's pixels (the kernel runs per row,
// view and label).
LB_AVX2 inline __m256i WeightedBitTable(int32_t cw) {
  const __m128i bits = _mm_setr_epi8(0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4);
  const __m128i w = _mm_set1_epi16(static_cast<int16_t>(cw));
  const __m128i lo = _mm_mullo_epi16(_mm_cvtepu8_epi16(bits), w);
  const __m128i hi = _mm_mullo_epi16(_mm_cvtepu8_epi16(_mm_srli_si128(bits, 8)), w);
  return _mm256_broadcastsi128_si256(_mm_packus_epi16(lo, hi));
}

// The nibble tables for cw and 2 * cw times the bit count (<= 80).
struct HamLut {
  __m256i one, two;
};
LB_AVX2 inline HamLut HamTables(int32_t cw) {
  return {WeightedBitTable(cw), WeightedBitTable(2 * cw)};
}

// Three census planes: cw * Hamming distance <= 240. The planes' differences x0, x1, x2 pass a
// full adder first, bit by bit (sum s = x0 ^ x1 ^ x2, carry c = majority), and
// bits(x0) + bits(x1) + bits(x2) = bits(s) + 2 bits(c): two table lookups instead of three.
LB_AVX2 inline __m256i WeightedHamming(const uint8_t* a, const uint8_t* b, ptrdiff_t plane,
                                       HamLut lut) {
  const __m256i x0 = _mm256_xor_si256(Load(a), Load(b));
  const __m256i x1 = _mm256_xor_si256(Load(a + plane), Load(b + plane));
  const __m256i x2 = _mm256_xor_si256(Load(a + 2 * plane), Load(b + 2 * plane));
  const __m256i t = _mm256_xor_si256(x0, x1);
  const __m256i sum = _mm256_xor_si256(t, x2);
  const __m256i carry = _mm256_or_si256(_mm256_and_si256(x0, x1), _mm256_and_si256(t, x2));
  return _mm256_add_epi8(WeightedBits(sum, lut.one), WeightedBits(carry, lut.two));
}

// 32 RGB pixels as three vectors whose 128-bit lanes hold pixels 0-15 and 16-31, so the
// in-lane byte shuffles below see 16 whole pixels.
struct Rgb32 {
  __m256i v[3];
};
LB_AVX2 inline Rgb32 LoadRgb32(const uint8_t* p) {
  Rgb32 r;
  for (int32_t k = 0; k < 3; ++k) {
    const __m128i lo = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 16 * k));
    const __m128i hi = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 48 + 16 * k));
    r.v[k] = _mm256_inserti128_si256(_mm256_castsi128_si256(lo), hi, 1);
  }
  return r;
}

// Shuffle masks: byte x of (mask k, channel c) picks byte 3x + c of the lane's 48 bytes when
// that lies in vector k, else zero.
struct GatherMasks {
  alignas(32) int8_t m[3][3][32];
  constexpr GatherMasks() : m() {
    for (int32_t k = 0; k < 3; ++k)
      for (int32_t c = 0; c < 3; ++c)
        for (int32_t i = 0; i < 32; ++i) {
          const int32_t src = 3 * (i % 16) + c - 16 * k;
          m[k][c][i] = static_cast<int8_t>(src >= 0 && src < 16 ? src : -128);
        }
  }
};
constexpr GatherMasks kGather;

// Sum of the three channel differences, saturated at 255: above that the cost is 255 anyway
// (cost = min(min(ad, trunc) + ham, 255) = min(min(ad, 255, trunc) + ham, 255)).
LB_AVX2 inline __m256i ChannelSum(const __m256i* d) {
  __m256i sum = _mm256_setzero_si256();
  for (int32_t c = 0; c < 3; ++c) {
    __m256i g = _mm256_shuffle_epi8(d[0], Load(kGather.m[0][c]));
    g = _mm256_or_si256(g, _mm256_shuffle_epi8(d[1], Load(kGather.m[1][c])));
    g = _mm256_or_si256(g, _mm256_shuffle_epi8(d[2], Load(kGather.m[2][c])));
    sum = _mm256_adds_epu8(sum, g);
  }
  return sum;
}

LB_AVX2 inline __m256i AbsDiff(__m256i a, __m256i b) {
  return _mm256_sub_epi8(_mm256_max_epu8(a, b), _mm256_min_epu8(a, b));
}

// The sample's fraction: none (f = 0), a half (f = 128: an average), a quarter or three
// quarters (f = 64, 192: averages again, below), or any other.
constexpr int32_t kWhole = 0, kFraction = 1, kHalf = 2, kQuarter = 3, kThreeQuarters = 4;

// (192 a + 64 b + 128) >> 8 = (3 a + b + 2) >> 2 = avg(a, floor((a + b) / 2)): the floor of a
// floor is the floor of the quotient, (2 a + 2 + a + b) / 4 = (a + floor((a + b) / 2) + 1) / 2
// after the inner floor, and floor((a + b) / 2) = avg(a, b) - ((a ^ b) & 1).
LB_AVX2 inline __m256i QuarterLerp(__m256i a, __m256i b) {
  const __m256i floor_avg = _mm256_sub_epi8(
      _mm256_avg_epu8(a, b), _mm256_and_si256(_mm256_xor_si256(a, b), _mm256_set1_epi8(1)));
  return _mm256_avg_epu8(a, floor_avg);
}

inline int32_t FracKind(int32_t f) {
  return f == 0     ? kWhole
         : f == 128 ? kHalf
         : f == 64  ? kQuarter
         : f == 192 ? kThreeQuarters
                    : kFraction;
}

// The fraction's interpolation of a (weight 256 - f) and b (weight f), rounded as Lerp.
template <int32_t kFrac>
LB_AVX2 inline __m256i Mix(__m256i a, __m256i b, __m256i f128) {
  if constexpr (kFrac == kHalf) return _mm256_avg_epu8(a, b);  // (a + b + 1) >> 1
  if constexpr (kFrac == kQuarter) return QuarterLerp(a, b);
  if constexpr (kFrac == kThreeQuarters) return QuarterLerp(b, a);
  return Lerp(a, b, f128);
}

// 32 pixels, all in bytes: the interpolated Hamming cost is Lerp of cw * h0 and cw * h1
// ((h0 * g + h1 * f) * cw = (cw h0) g + (cw h1) f exactly). lut: HamTables(cw), trunc8:
// min(trunc, 255) in every byte.
template <int32_t kFrac>
LB_AVX2 inline __attribute__((always_inline)) void CostStep(const uint8_t* ref, const uint8_t* img,
                                                            const uint8_t* cref,
                                                            const uint8_t* cimg, ptrdiff_t plane,
                                                            __m256i f128, HamLut lut,
                                                            __m256i trunc8, uint8_t* out) {
  const Rgb32 r = LoadRgb32(ref);
  const Rgb32 a = LoadRgb32(img);
  __m256i d[3];
  __m256i ham = WeightedHamming(cref, cimg, plane, lut);
  if constexpr (kFrac != kWhole) {
    const Rgb32 b = LoadRgb32(img + 3);
    for (int32_t k = 0; k < 3; ++k) d[k] = AbsDiff(r.v[k], Mix<kFrac>(a.v[k], b.v[k], f128));
    ham = Mix<kFrac>(ham, WeightedHamming(cref, cimg + 1, plane, lut), f128);
  } else {
    for (int32_t k = 0; k < 3; ++k) d[k] = AbsDiff(r.v[k], a.v[k]);
  }
  const __m256i ad = _mm256_min_epu8(ChannelSum(d), trunc8);
  Store(out, _mm256_adds_epu8(ad, ham));
}

// n >= 32 pixels, whole steps and then one overlapping the step before (the same bytes again).
template <int32_t kFrac>
LB_AVX2 inline void CostLoopAvx2(const uint8_t* ref, const uint8_t* img, const uint8_t* cref,
                                 const uint8_t* cimg, ptrdiff_t plane, int32_t n, int32_t f,
                                 HamLut lut, __m256i trunc8, uint8_t* out) {
  const __m256i f128 = _mm256_set1_epi16(static_cast<int16_t>(f * 128));
  int32_t x = 0;
  for (; x + 32 <= n; x += 32) {
    CostStep<kFrac>(ref + 3 * x, img + 3 * x, cref + x, cimg + x, plane, f128, lut, trunc8,
                    out + x);
  }
  if (x < n) {
    x = n - 32;
    CostStep<kFrac>(ref + 3 * x, img + 3 * x, cref + x, cimg + x, plane, f128, lut, trunc8,
                    out + x);
  }
}

LB_AVX2 inline __m256i Trunc8(int32_t trunc) {
  return _mm256_set1_epi8(static_cast<char>(trunc < 255 ? trunc : 255));
}

template <int32_t kFrac>
LB_AVX2 void CostRowAvx2T(const uint8_t* ref, const uint8_t* img, const uint8_t* cref,
                          const uint8_t* cimg, ptrdiff_t plane, int32_t n, int32_t f, int32_t trunc,
                          int32_t cw, uint8_t* out) {
  if (n < 32) return CostRowCAvx2(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
  CostLoopAvx2<kFrac>(ref, img, cref, cimg, plane, n, f, HamTables(cw), Trunc8(trunc), out);
}

LB_AVX2 void CostRowAvx2(const uint8_t* ref, const uint8_t* img, const uint8_t* cref,
                         const uint8_t* cimg, ptrdiff_t plane, int32_t n, int32_t f, int32_t trunc,
                         int32_t cw, uint8_t* out) {
  switch (FracKind(f)) {
    case kWhole:
      return CostRowAvx2T<kWhole>(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
    case kHalf:
      return CostRowAvx2T<kHalf>(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
    case kQuarter:
      return CostRowAvx2T<kQuarter>(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
    case kThreeQuarters:
      return CostRowAvx2T<kThreeQuarters>(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
    default:
      return CostRowAvx2T<kFraction>(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
  }
}

LB_AVX2 inline __m256i Widen16(const uint8_t* p) {
  return _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
}

LB_AVX2 inline void HSumStep(const uint8_t* cost, uint16_t* hsum) {
  const __m256i s = _mm256_add_epi16(Widen16(cost - 1), Widen16(cost));
  Store(hsum, _mm256_add_epi16(s, Widen16(cost + 1)));
}

LB_AVX2 inline __attribute__((always_inline)) void HSumLoopAvx2(const uint8_t* cost, int32_t x0,
                                                                int32_t x1, uint16_t* hsum) {
  if (x1 - x0 < 16) return HSumRowC(cost, x0, x1, hsum);
  int32_t x = x0;
  for (; x + 32 <= x1; x += 32) {
    HSumStep(cost + x, hsum + x);
    HSumStep(cost + x + 16, hsum + x + 16);
  }
  if (x + 16 <= x1) {
    HSumStep(cost + x, hsum + x);
    x += 16;
  }
  if (x < x1) HSumStep(cost + x1 - 16, hsum + x1 - 16);
}

LB_AVX2 void HSumRowAvx2(const uint8_t* cost, int32_t x0, int32_t x1, uint16_t* hsum) {
  HSumLoopAvx2(cost, x0, x1, hsum);
}

// The rectified row (RectRowWith's definition) with the constants set once for every view. A run
// shorter than a vector step takes one whole step where the step's samples all lie in the image
// (ending at the run's end, or else starting at its start), and the out-of-image runs are then
// filled by whole vector stores: the costs a step or a fill writes outside its run are either
// overwritten by those that follow or lie outside the columns the 3-sums read (the pixel row has
// kPixelSlack bytes either side).
LB_AVX2 void RectRowAvx2(const RectRow& r) {
  const int32_t w = r.width;
  const int32_t c0 = r.x0 > 0 ? r.x0 - 1 : 0, c1 = r.x1 < w ? r.x1 + 1 : w;
  uint8_t* cost = r.pixel + kPixelSlack + 1;
  const HamLut lut = HamTables(r.cw);
  const __m256i trunc8 = Trunc8(r.trunc);
  const __m256i invalid = _mm256_set1_epi8(static_cast<char>(r.invalid));
  for (int32_t j = 0; j < r.others; ++j) {
    const ValidSpan v = ValidColumns(r.shift_q8[j], w, c0, c1);
    const int32_t n = v.x_hi - v.x_lo;
    if (n >= 32) {
      const uint8_t *ref = r.ref + 3 * v.x_lo, *img = r.img[j] + 3 * (v.x_lo + v.off);
      const uint8_t *cref = r.cref + v.x_lo, *cimg = r.cimg[j] + v.x_lo + v.off;
      uint8_t* out = cost + v.x_lo;
      switch (FracKind(v.f)) {
        case kWhole:
          CostLoopAvx2<kWhole>(ref, img, cref, cimg, w, n, 0, lut, trunc8, out);
          break;
        case kHalf:
          CostLoopAvx2<kHalf>(ref, img, cref, cimg, w, n, v.f, lut, trunc8, out);
          break;
        case kQuarter:
          CostLoopAvx2<kQuarter>(ref, img, cref, cimg, w, n, v.f, lut, trunc8, out);
          break;
        case kThreeQuarters:
          CostLoopAvx2<kThreeQuarters>(ref, img, cref, cimg, w, n, v.f, lut, trunc8, out);
          break;
        default:
          CostLoopAvx2<kFraction>(ref, img, cref, cimg, w, n, v.f, lut, trunc8, out);
      }
    } else if (n > 0) {
      // Columns x .. x + 31 sample view pixels x + off .. x + off + 31 (+ 1 with a fraction).
      const int32_t right = w - v.off - (v.f > 0 ? 1 : 0);
      int32_t x = v.x_hi - 32;
      if (x < 0 || x + v.off < 0) x = v.x_lo + 32 <= w && v.x_lo + 32 <= right ? v.x_lo : -1;
      if (x >= 0) {
        const __m256i f128 = _mm256_set1_epi16(static_cast<int16_t>(v.f * 128));
        const uint8_t *ref = r.ref + 3 * x, *img = r.img[j] + 3 * (x + v.off);
        const uint8_t *cref = r.cref + x, *cimg = r.cimg[j] + x + v.off;
        // One step only: the general interpolation for every fraction.
        if (v.f == 0) {
          CostStep<kWhole>(ref, img, cref, cimg, w, f128, lut, trunc8, cost + x);
        } else {
          CostStep<kFraction>(ref, img, cref, cimg, w, f128, lut, trunc8, cost + x);
        }
      } else {
        CostRowCAvx2(r.ref + 3 * v.x_lo, r.img[j] + 3 * (v.x_lo + v.off), r.cref + v.x_lo,
                     r.cimg[j] + v.x_lo + v.off, w, n, v.f, r.trunc, r.cw, cost + v.x_lo);
      }
    }
    for (int32_t x = v.x_lo; x > c0; x -= 32) Store(cost + x - 32, invalid);
    for (int32_t x = v.x_hi; x < c1; x += 32) Store(cost + x, invalid);
    if (r.x0 == 0) cost[-1] = cost[0];
    if (r.x1 == w) cost[w] = cost[w - 1];
    HSumLoopAvx2(cost, r.x0, r.x1, r.hsum[j]);
  }
}

// Signed 16-bit lanes (window sums <= 2295). Only the SUM of the kKeep smallest is needed, not
// their order: the first kKeep windows (A) and the others (B, kB = others - kKeep of them: kKeep
// or kKeep - 1) are each sorted by a compare-exchange network, and the kKeep smallest of A and B
// together are min(A_i, B_(kKeep-1-i)) (the first half of a bitonic merge; B's missing entry is
// +inf, so A_0 alone). Kept sum <= 18360, then mulhrs by the Q15 reciprocal is
// (sum * recip + 2^14) >> 15, as in the reference.
LB_AVX2 inline __m256i Window(const uint16_t* view, ptrdiff_t stride) {
  return _mm256_add_epi16(_mm256_add_epi16(Load(view), Load(view + stride)),
                          Load(view + 2 * stride));
}

LB_AVX2 inline void Exchange(__m256i* v, int32_t i, int32_t j) {
  const __m256i lo = _mm256_min_epi16(v[i], v[j]);
  v[j] = _mm256_max_epi16(v[i], v[j]);
  v[i] = lo;
}

// Ascending sort of kN vectors lane by lane: the optimal 5 exchanges for 4, else insertion.
template <int32_t kN>
LB_AVX2 inline void SortNetwork(__m256i* v) {
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

// 16 columns: view j's rows at view[j], view[j] + stride, view[j] + 2 * stride. False, with
// nothing stored, when a lane has a view that does not see it (a window of `unseen`, the sorted
// maximum): those columns keep fewer windows, which SelectSeenStep counts lane by lane. Rare: a
// border strip as wide as the label's shift.
template <int32_t kKeep, int32_t kB>
LB_AVX2 inline __attribute__((always_inline)) bool SelectStep(const uint16_t* const* view,
                                                              ptrdiff_t at, ptrdiff_t stride,
                                                              __m256i recip, __m256i below_unseen,
                                                              uint16_t* out) {
  __m256i a[kKeep], b[kB + (kB == 0 ? 1 : 0)];  // no empty array when kKeep is 1
  for (int32_t j = 0; j < kKeep; ++j) a[j] = Window(view[j] + at, stride);
  for (int32_t j = 0; j < kB; ++j) b[j] = Window(view[kKeep + j] + at, stride);
  SortNetwork<kKeep>(a);
  SortNetwork<kB>(b);
  if constexpr (kKeep > 1) {  // one or two views keep one window whatever they see
    const __m256i most = kB > 0 ? _mm256_max_epi16(a[kKeep - 1], b[kB - 1]) : a[kKeep - 1];
    const __m256i over = _mm256_cmpgt_epi16(most, below_unseen);
    if (!_mm256_testz_si256(over, over)) return false;
  }
  __m256i sum = a[0];
  if constexpr (kB == kKeep) sum = _mm256_min_epi16(a[0], b[kKeep - 1]);
  for (int32_t i = 1; i < kKeep; ++i) {
    sum = _mm256_add_epi16(sum, _mm256_min_epi16(a[i], b[kKeep - 1 - i]));
  }
  Store(out, kKeep == 1 ? sum : _mm256_mulhrs_epi16(sum, recip));
  return true;
}

// The step SelectStep declines: every window sorted, so those of the views that do not see a lane
// (the largest) come last; the seen ones counted lane by lane, the first `keep` of the sorted
// windows summed under a mask, and each lane divided by its own keep.
template <int32_t kViews>
LB_AVX2 __attribute__((noinline)) void SelectSeenStep(const uint16_t* const* view, ptrdiff_t at,
                                                      ptrdiff_t stride, __m256i below_unseen,
                                                      uint16_t* out) {
  constexpr int32_t kMost = (kViews + 1) / 2;
  __m256i v[kViews];
  for (int32_t j = 0; j < kViews; ++j) v[j] = Window(view[j] + at, stride);
  SortNetwork<kViews>(v);
  __m256i unseen = _mm256_setzero_si256();  // lanes count -1 per view that does not see them
  for (int32_t j = 0; j < kViews; ++j) {
    unseen = _mm256_add_epi16(unseen, _mm256_cmpgt_epi16(v[j], below_unseen));
  }
  const __m256i seen = _mm256_add_epi16(_mm256_set1_epi16(kViews), unseen);
  const __m256i none = _mm256_cmpeq_epi16(seen, _mm256_setzero_si256());
  const __m256i keep =
      _mm256_blendv_epi8(_mm256_srli_epi16(_mm256_add_epi16(seen, _mm256_set1_epi16(1)), 1),
                         _mm256_set1_epi16(kMost), none);
  __m256i sum = v[0], recip = _mm256_setzero_si256();
  for (int32_t i = 1; i < kMost; ++i) {
    sum = _mm256_add_epi16(sum,
                           _mm256_and_si256(v[i], _mm256_cmpgt_epi16(keep, _mm256_set1_epi16(i))));
    const __m256i at_keep = _mm256_cmpeq_epi16(keep, _mm256_set1_epi16(i + 1));
    recip = _mm256_or_si256(
        recip, _mm256_and_si256(at_keep, _mm256_set1_epi16(static_cast<int16_t>(RecipQ15(i + 1)))));
  }
  const __m256i one = _mm256_cmpeq_epi16(keep, _mm256_set1_epi16(1));
  Store(out, _mm256_blendv_epi8(_mm256_mulhrs_epi16(sum, recip), sum, one));
}

// Columns x..x + 15: SelectStep, or SelectSeenStep where it declines.
template <int32_t kKeep, int32_t kB>
LB_AVX2 inline __attribute__((always_inline)) void Step(const uint16_t* const* view, ptrdiff_t at,
                                                        ptrdiff_t stride, __m256i recip,
                                                        __m256i below, uint16_t* out) {
  if (!SelectStep<kKeep, kB>(view, at, stride, recip, below, out)) {
    SelectSeenStep<kKeep + kB>(view, at, stride, below, out);
  }
}

// Whole steps with each view's pointer moved along (no address arithmetic per view and step),
// then one step overlapping the one before.
template <int32_t kKeep, int32_t kB>
LB_AVX2 void SelectRowAvx2T(const uint16_t* ring, ptrdiff_t stride, int32_t unseen, int32_t x0,
                            int32_t x1, uint16_t* out) {
  constexpr int32_t kViews = kKeep + kB;
  const __m256i recip = _mm256_set1_epi16(static_cast<int16_t>(RecipQ15(kKeep)));
  const __m256i below = _mm256_set1_epi16(static_cast<int16_t>(unseen - 1));
  const uint16_t* view[kViews];
  for (int32_t j = 0; j < kViews; ++j) view[j] = ring + 3 * j * stride + x0;
  int32_t x = x0;
  for (; x + 32 <= x1; x += 32) {  // two steps a turn: the pointers move half as often
    Step<kKeep, kB>(view, 0, stride, recip, below, out + x);
    Step<kKeep, kB>(view, 16, stride, recip, below, out + x + 16);
    for (int32_t j = 0; j < kViews; ++j) view[j] += 32;
  }
  if (x + 16 <= x1) {
    Step<kKeep, kB>(view, 0, stride, recip, below, out + x);
    x += 16;
  }
  if (x < x1) {
    for (int32_t j = 0; j < kViews; ++j) view[j] = ring + 3 * j * stride + x1 - 16;
    Step<kKeep, kB>(view, 0, stride, recip, below, out + x1 - 16);
  }
}

template <int32_t kKeep>
LB_AVX2 void SelectRowAvx2T(const uint16_t* ring, ptrdiff_t stride, int32_t others, int32_t unseen,
                            int32_t x0, int32_t x1, uint16_t* out) {
  if (x1 - x0 < 16) return SelectRowC(ring, stride, others, unseen, x0, x1, out);
  if (others == 2 * kKeep) {
    return SelectRowAvx2T<kKeep, kKeep>(ring, stride, unseen, x0, x1, out);
  }
  SelectRowAvx2T<kKeep, kKeep - 1>(ring, stride, unseen, x0, x1, out);
}

// The instance for each kept count (others + 1) / 2 = 1 .. kMaxBest.
constexpr SelectRowFn kAvx2ByKeep[kMaxBest] = {
    SelectRowAvx2T<1>, SelectRowAvx2T<2>, SelectRowAvx2T<3>, SelectRowAvx2T<4>,
    SelectRowAvx2T<5>, SelectRowAvx2T<6>, SelectRowAvx2T<7>, SelectRowAvx2T<8>};

}  // namespace

const DataTerm::Kernels* Avx2Kernels() {
  static constexpr DataTerm::Kernels kAvx2 = {
      CensusRowAvx2, CostRowAvx2,    HSumRowAvx2,    SelectByKeep<kAvx2ByKeep>,
      RectRowAvx2,   PlaneSpansAvx2, PlaneLanesAvx2, PlaneAnchorsAvx2};
  return __builtin_cpu_supports("avx2") ? &kAvx2 : nullptr;
}

}  // namespace lb::dtk
#else
namespace lb::dtk {
const DataTerm::Kernels* Avx2Kernels() { return nullptr; }
}  // namespace lb::dtk
#endif
