// The plane sweep's AVX2 kernels that prepare a row for the span steps (warp_cost_avx2.cc): the
// reference row's lanes (PlaneLanesAvx2), and the anchors' exact divisions, four at a time
// (PlaneAnchorsAvx2; the C reference is dtk::PlaneAnchorsC).
#include "algo/depth/warp_cost_avx2.h"

#if defined(__x86_64__)
#include "algo/core/int_math.h"

namespace lb::dtk {

using plane_avx2::kLanes;
using plane_avx2::kMasks;
using plane_avx2::Load;
using plane_avx2::RefCensus;

// RefLanes (warp_cost.h) of columns x0..x1-1: 8 columns a step from 24 bytes of the row and 8 of
// each census plane (inside the row while x + 8 <= width), the rest one by one.
LB_AVX2 void PlaneLanesAvx2(const uint8_t* ref, const uint8_t* cref, int32_t width, int32_t x0,
                            int32_t x1, int32_t* lanes, ptrdiff_t stride) {
  int32_t x = x0;
  WarpRow r;
  r.cref = cref;
  r.width = width;
  for (; x + kLanes <= x1 && x + kLanes <= width; x += kLanes) {
    const __m128i lo = _mm_loadu_si128(reinterpret_cast<const __m128i*>(ref + 3 * x));
    const __m128i hi = _mm_loadu_si128(reinterpret_cast<const __m128i*>(ref + 3 * x + 8));
    const __m256i rgb = _mm256_inserti128_si256(_mm256_castsi128_si256(lo), hi, 1);
    int32_t* const out = lanes + (x - x0);
    for (int32_t c = 0; c < 3; ++c) {
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + c * stride),
                          _mm256_shuffle_epi8(rgb, Load(kMasks.ref[c])));
    }
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + 3 * stride), RefCensus(r, x));
  }
  for (; x < x1; ++x) {
    int32_t* const out = lanes + (x - x0);
    for (int32_t c = 0; c < 3; ++c) out[c * stride] = ref[3 * x + c];
    out[3 * stride] = static_cast<int32_t>((uint32_t{cref[x]} << 16) |
                                           (uint32_t{cref[width + x]} << 8) | cref[2 * width + x]);
  }
}

// Four anchors a step in 64-bit lanes, PlaneRowMap::FromSums's checks and exact quotients: |n|
// < den 2^14 < 2^46 and den < 2^32 convert to double exactly (a value v < 2^52 ORed into 2^52's
// bits is 2^52 + v), the quotient of num = |n| 2^16 + den / 2 is estimated through den's
// reciprocal (three roundings: relative error under 2^-51, so within 1 of the floor for q <=
// 2^30 + 1) and corrected by its remainder, which mul_epu32 gives exactly (q < 2^31, den <
// 2^32). Lanes that fail a check take 0s, whatever their arithmetic gave.
namespace {

LB_AVX2 inline __m256d ExactDouble(__m256i v) {  // 0 <= v < 2^52
  const __m256i bits = _mm256_set1_epi64x(0x4330000000000000);
  return _mm256_sub_pd(_mm256_castsi256_pd(_mm256_or_si256(v, bits)), _mm256_castsi256_pd(bits));
}

// The rounded Q16 quotient n / den of 4 lanes (as PlaneRowMap's), given den's reciprocal.
LB_AVX2 inline __m256i Quotient(__m256i n, __m256i den, __m256d den_half, __m256d inv) {
  const __m256i zero = _mm256_setzero_si256();
  const __m256i sign = _mm256_cmpgt_epi64(zero, n);
  const __m256i a = _mm256_sub_epi64(_mm256_xor_si256(n, sign), sign);
  const __m256i num = _mm256_add_epi64(_mm256_slli_epi64(a, 16), _mm256_srli_epi64(den, 1));
  const __m256d num_d =
      _mm256_add_pd(_mm256_mul_pd(ExactDouble(a), _mm256_set1_pd(65536.0)), den_half);
  __m256i q = _mm256_cvtepi32_epi64(_mm256_cvttpd_epi32(_mm256_mul_pd(num_d, inv)));
  const __m256i r = _mm256_sub_epi64(num, _mm256_mul_epu32(q, den));
  q = _mm256_add_epi64(q, _mm256_cmpgt_epi64(zero, r));  // r < 0: one less
  q = _mm256_sub_epi64(q, _mm256_cmpgt_epi64(r, _mm256_sub_epi64(den, _mm256_set1_epi64x(1))));
  return _mm256_sub_epi64(_mm256_xor_si256(q, sign), sign);
}

// |n| < lim per lane (n = INT64_MIN fails: its |n| wraps negative).
LB_AVX2 inline __m256i Within(__m256i n, __m256i lim) {
  const __m256i sign = _mm256_cmpgt_epi64(_mm256_setzero_si256(), n);
  const __m256i a = _mm256_sub_epi64(_mm256_xor_si256(n, sign), sign);
  return _mm256_andnot_si256(_mm256_cmpgt_epi64(_mm256_setzero_si256(), a),
                             _mm256_cmpgt_epi64(lim, a));
}

}  // namespace

LB_AVX2 bool PlaneAnchorsAvx2(const int64_t* sums, const int64_t* changes, int32_t count,
                              int32_t* x_q16, int32_t* y_q16, bool* ok) {
  // Lane i holds anchor k + i: the sums at anchors 1..4, then 4 changes a step (the same
  // integers as the reference's one change a step).
  const __m256i step_den = _mm256_set1_epi64x(4 * changes[0]);
  const __m256i step_nx = _mm256_set1_epi64x(4 * changes[1]);
  const __m256i step_ny = _mm256_set1_epi64x(4 * changes[2]);
  __m256i den = _mm256_setr_epi64x(sums[0] + changes[0], sums[0] + 2 * changes[0],
                                   sums[0] + 3 * changes[0], sums[0] + 4 * changes[0]);
  __m256i nx = _mm256_setr_epi64x(sums[1] + changes[1], sums[1] + 2 * changes[1],
                                  sums[1] + 3 * changes[1], sums[1] + 4 * changes[1]);
  __m256i ny = _mm256_setr_epi64x(sums[2] + changes[2], sums[2] + 2 * changes[2],
                                  sums[2] + 3 * changes[2], sums[2] + 4 * changes[2]);
  const __m256i min_den = _mm256_set1_epi64x((int64_t{1} << 20) - 1);
  const __m256i max_den = _mm256_set1_epi64x(int64_t{1} << 32);
  const __m256i low_dwords = _mm256_setr_epi32(0, 2, 4, 6, 0, 0, 0, 0);
  int32_t bad = 0;
  for (int32_t k = 0; k < count; k += 4) {
    const __m256i lim = _mm256_slli_epi64(den, 14);
    const __m256i valid = _mm256_and_si256(
        _mm256_and_si256(_mm256_cmpgt_epi64(den, min_den), _mm256_cmpgt_epi64(max_den, den)),
        _mm256_and_si256(Within(nx, lim), Within(ny, lim)));
    // Invalid lanes' den may be anything: their quotients are dropped.
    const __m256d den_d = ExactDouble(_mm256_and_si256(valid, den));
    const __m256d inv = _mm256_div_pd(_mm256_set1_pd(1.0), den_d);
    const __m256d den_half = ExactDouble(_mm256_and_si256(valid, _mm256_srli_epi64(den, 1)));
    const __m256i qx = _mm256_and_si256(valid, Quotient(nx, den, den_half, inv));
    const __m256i qy = _mm256_and_si256(valid, Quotient(ny, den, den_half, inv));
    alignas(16) int32_t xs[4], ys[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(xs),
                    _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(qx, low_dwords)));
    _mm_store_si128(reinterpret_cast<__m128i*>(ys),
                    _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(qy, low_dwords)));
    const int32_t mask = _mm256_movemask_pd(_mm256_castsi256_pd(valid));
    const int32_t n = Min(4, count - k);
    for (int32_t i = 0; i < n; ++i) {
      x_q16[k + i] = xs[i];
      y_q16[k + i] = ys[i];
      ok[k + i] = ((mask >> i) & 1) != 0;
    }
    bad |= ~mask & ((1 << n) - 1);
    den = _mm256_add_epi64(den, step_den);
    nx = _mm256_add_epi64(nx, step_nx);
    ny = _mm256_add_epi64(ny, step_ny);
  }
  return bad == 0;
}

}  // namespace lb::dtk
#endif
