// The tracker's window kernels for AVX2 (tracker_kernels.h; the reference is tk::kReference):
// eight samples a step from 8-byte loads of each row at x and x + 1, paired into 16-bit lanes
// for one multiply-add by (256 - fx, fx), then the rows mixed in 32 bits; the columns past the
// last whole step one by one. A lane takes at most 4 products of < 2^24 a row (two steps of 17
// columns, two halves on NEON), so over 17 rows its sum stays in int32.
#include "algo/motion/tracker_kernels.h"

#if defined(__x86_64__)
#include <immintrin.h>

#define LB_AVX2 __attribute__((target("avx2")))

namespace lb::tk {
namespace {

// The horizontal mix of 8 samples' left and right bytes: a[i] (256 - fx) + a[i + 1] fx.
LB_AVX2 inline __m256i RowMix(const uint8_t* a, __m256i weights) {
  const __m128i left = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(a));
  const __m128i right = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(a + 1));
  return _mm256_madd_epi16(_mm256_cvtepu8_epi16(_mm_unpacklo_epi8(left, right)), weights);
}

struct Weights {
  __m256i x, fy, gy, round;
};

LB_AVX2 inline Weights MakeWeights(int32_t fx, int32_t fy) {
  return {_mm256_set1_epi32(static_cast<int32_t>((static_cast<uint32_t>(fx) << 16) |
                                                 static_cast<uint32_t>(256 - fx))),
          _mm256_set1_epi32(fy), _mm256_set1_epi32(256 - fy), _mm256_set1_epi32(2048)};
}

// Samples i..i+7 of the row at a (rows `stride` apart).
LB_AVX2 inline __m256i Step(const uint8_t* a, ptrdiff_t stride, const Weights& w) {
  const __m256i top = RowMix(a, w.x), bot = RowMix(a + stride, w.x);
  const __m256i sum =
      _mm256_add_epi32(_mm256_mullo_epi32(top, w.gy), _mm256_mullo_epi32(bot, w.fy));
  return _mm256_srai_epi32(_mm256_add_epi32(sum, w.round), 12);
}

LB_AVX2 void SampleAvx2(const uint8_t* p, ptrdiff_t stride, int32_t fx, int32_t fy, int32_t n,
                        int32_t* out) {
  const Weights w = MakeWeights(fx, fy);
  for (int32_t j = 0; j < n; ++j) {
    const uint8_t* a = p + j * stride;
    int32_t* o = out + j * n;
    int32_t i = 0;
    for (; i + 8 <= n; i += 8) {
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(o + i), Step(a + i, stride, w));
    }
    for (; i < n; ++i) o[i] = SampleQ4(a + i, stride, fx, fy);
  }
}

LB_AVX2 int64_t LaneSum(__m256i v) {
  alignas(32) int32_t lanes[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(lanes), v);
  int64_t s = 0;
  for (const int32_t l : lanes) s += l;
  return s;
}

LB_AVX2 WindowSums SumsAvx2(const uint8_t* p, ptrdiff_t stride, int32_t fx, int32_t fy, int32_t n,
                            const int32_t* tmpl, const int32_t* gx, const int32_t* gy) {
  const Weights w = MakeWeights(fx, fy);
  __m256i bx = _mm256_setzero_si256(), by = bx, ae = bx;
  WindowSums s;
  for (int32_t j = 0; j < n; ++j) {
    const uint8_t* a = p + j * stride;
    const int32_t k0 = j * n;
    int32_t i = 0;
    for (; i + 8 <= n; i += 8) {
      const int32_t k = k0 + i;
      const __m256i e = _mm256_sub_epi32(
          Step(a + i, stride, w), _mm256_loadu_si256(reinterpret_cast<const __m256i*>(tmpl + k)));
      bx = _mm256_add_epi32(
          bx, _mm256_mullo_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(gx + k)), e));
      by = _mm256_add_epi32(
          by, _mm256_mullo_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(gy + k)), e));
      ae = _mm256_add_epi32(ae, _mm256_abs_epi32(e));
    }
    for (; i < n; ++i) {
      const int32_t k = k0 + i;
      AddError(SampleQ4(a + i, stride, fx, fy) - tmpl[k], gx[k], gy[k], &s);
    }
  }
  s.bx += LaneSum(bx);
  s.by += LaneSum(by);
  s.abs_err += LaneSum(ae);
  return s;
}

}  // namespace

const Kernels* Avx2Kernels() {
  static constexpr Kernels kAvx2 = {SampleAvx2, SumsAvx2};
  return &kAvx2;
}

}  // namespace lb::tk
#else
namespace lb::tk {
const Kernels* Avx2Kernels() { return nullptr; }
}  // namespace lb::tk
#endif
