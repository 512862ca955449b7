// AVX2 twins of the layer row kernels (layer_rows.h), 8 pixels a step, the tail of a row (and
// any row outside a twin's bounds) by the C reference. The references multiply in int64; AVX2
// has no 64-bit shift right that keeps the sign and only even-lane 32 x 32 -> 64 products, so
// these split each product into 32-bit parts whose sum is exact for the formats' ranges (each
// kernel says why).
#include "algo/render/layer_rows.h"

#if defined(__x86_64__)
#include <immintrin.h>

#define LB_AVX2 __attribute__((target("avx2")))

namespace lb::layer_rows {
namespace {

LB_AVX2 inline __m256i Load(const void* p) {
  return _mm256_loadu_si256(static_cast<const __m256i*>(p));
}
LB_AVX2 inline void Store(void* p, __m256i v) { _mm256_storeu_si256(static_cast<__m256i*>(p), v); }

// a + ((b - a) x f + 128) >> 8 (floor), f 0..255, |b - a| < 2^31: with d = 256 dh + dl (dh =
// d >> 8, dl = d & 255) that is a + dh x f + ((dl x f + 128) >> 8), every part in 32 bits
// (|dh x f| < 2^31, dl x f + 128 < 2^16: a 16-bit product of the low halves).
LB_AVX2 inline __m256i Lerp(__m256i a, __m256i b, __m256i f) {
  const __m256i d = _mm256_sub_epi32(b, a);
  const __m256i dl = _mm256_and_si256(d, _mm256_set1_epi32(255));
  const __m256i low = _mm256_mullo_epi16(dl, f);
  const __m256i round = _mm256_srli_epi32(_mm256_add_epi32(low, _mm256_set1_epi32(128)), 8);
  return _mm256_add_epi32(_mm256_add_epi32(a, _mm256_mullo_epi32(_mm256_srai_epi32(d, 8), f)),
                          round);
}

// ((o x keep + 32768) >> 16) + colour, keep 0..65536: with o = 65536 oh + ol (ol 0..65535) that
// is oh x keep + ((ol x keep + 32768) >> 16), the second part below 2^32 (unsigned), the first
// and the sum wrapping as the reference's cast to int32 does.
LB_AVX2 inline __m256i Over(__m256i o, __m256i keep, __m256i colour) {
  const __m256i ol = _mm256_and_si256(o, _mm256_set1_epi32(0xffff));
  const __m256i low = _mm256_srli_epi32(
      _mm256_add_epi32(_mm256_mullo_epi32(ol, keep), _mm256_set1_epi32(32768)), 16);
  const __m256i high = _mm256_mullo_epi32(_mm256_srai_epi32(o, 16), keep);
  return _mm256_add_epi32(_mm256_add_epi32(high, low), colour);
}

LB_AVX2 void CompositeRowAvx2(int32_t* out, const int32_t* colour, const int32_t* alpha, int32_t x0,
                              int32_t x1) {
  const __m256i unit = _mm256_set1_epi32(65536);
  int32_t x = x0;
  for (; x + 7 <= x1; x += 8) {
    const __m256i keep = _mm256_sub_epi32(unit, Load(alpha + x));
    Store(out + x, Over(Load(out + x), keep, Load(colour + x)));
  }
  CompositeRowC(out, colour, alpha, x, x1);
}

// Eight output columns x .. x + 7 read taps q(x) .. q(x + 7) + 1, at most 6 apart (level >= 1):
// one masked load of the low-res row from q(x) (nothing read beyond the last tap) and two
// in-register permutes give each lane its left and right tap.
template <int C>
LB_AVX2 void LerpCompositeAvx2(const int32_t* col, ptrdiff_t stride, const uint8_t* frac,
                               int32_t level, int32_t x0, int32_t x1, int32_t* out,
                               ptrdiff_t out_stride) {
  const int32_t half = (1 << level) / 2;
  const __m128i count = _mm_cvtsi32_si128(level);
  const __m256i lanes = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i one = _mm256_set1_epi32(1), unit = _mm256_set1_epi32(65536);
  int32_t x = x0;
  for (; x + 7 <= x1; x += 8) {
    const int32_t q = (x - half) >> level;
    const int32_t taps = ((x + 7 - half) >> level) - q + 2;
    const __m256i mask = _mm256_cmpgt_epi32(_mm256_set1_epi32(taps), lanes);
    const __m256i left = _mm256_sub_epi32(
        _mm256_sra_epi32(_mm256_add_epi32(_mm256_set1_epi32(x - half), lanes), count),
        _mm256_set1_epi32(q));
    const __m256i right = _mm256_add_epi32(left, one);
    const __m256i f =
        _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(frac + x)));
    __m256i v[C + 1];
    for (int32_t c = 0; c <= C; ++c) {
      const __m256i row = _mm256_maskload_epi32(col + c * stride + q, mask);
      v[c] =
          Lerp(_mm256_permutevar8x32_epi32(row, left), _mm256_permutevar8x32_epi32(row, right), f);
    }
    const __m256i keep = _mm256_sub_epi32(unit, v[C]);
    for (int32_t c = 0; c <= C; ++c) {
      int32_t* o = out + c * out_stride + x;
      Store(o, Over(Load(o), keep, v[c]));
    }
  }
  LerpCompositeC<C>(col, stride, frac, level, x, x1, out, out_stride);
}

// Adds each group of 2^L lanes' sum, in order, to box[0 ..]: four pairs (L 1), two quads (L 2)
// or the whole vector (L >= 3: 8 columns, or 16 already added lane-wise). int32 wrapping adds,
// as the reference's (its sums stay below 2^27: layer_rows.h).
template <int L>
LB_AVX2 inline void AddGroups(__m256i c, int32_t* box) {
  if constexpr (L == 1) {
    const __m256i h = _mm256_permute4x64_epi64(_mm256_hadd_epi32(c, c), _MM_SHUFFLE(3, 1, 2, 0));
    __m128i* b = reinterpret_cast<__m128i*>(box);
    _mm_storeu_si128(b, _mm_add_epi32(_mm_loadu_si128(b), _mm256_castsi256_si128(h)));
  } else if constexpr (L == 2) {
    const __m256i h = _mm256_hadd_epi32(c, c);
    const __m256i h2 = _mm256_hadd_epi32(h, h);
    box[0] += _mm256_cvtsi256_si32(h2);
    box[1] += _mm_cvtsi128_si32(_mm256_extracti128_si256(h2, 1));
  } else {
    __m128i h = _mm_add_epi32(_mm256_castsi256_si128(c), _mm256_extracti128_si256(c, 1));
    h = _mm_hadd_epi32(h, h);
    box[0] += _mm_cvtsi128_si32(_mm_hadd_epi32(h, h));
  }
}

// LayerWeightQ8 of layer k for 8 pixels: the table looked up one pixel at a time (there is no
// 16-bit gather), the choice between 256 - frac, frac and 0 in-register.
LB_AVX2 inline __m256i Weights(const int16_t* s, const uint16_t* table, __m256i k) {
  const __m256i e = _mm256_setr_epi32(table[s[0]], table[s[1]], table[s[2]], table[s[3]],
                                      table[s[4]], table[s[5]], table[s[6]], table[s[7]]);
  const __m256i first = _mm256_srli_epi32(e, 8), frac = _mm256_and_si256(e, _mm256_set1_epi32(255));
  const __m256i in_first = _mm256_and_si256(_mm256_cmpeq_epi32(first, k),
                                            _mm256_sub_epi32(_mm256_set1_epi32(256), frac));
  const __m256i in_next =
      _mm256_and_si256(_mm256_cmpeq_epi32(_mm256_add_epi32(first, _mm256_set1_epi32(1)), k), frac);
  return _mm256_or_si256(in_first, in_next);
}

LB_AVX2 inline __m256i Widen(const int16_t* v) {
  return _mm256_cvtepi16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(v)));
}

// As WeightedBoxRowC: c = (v x a) >> shift per pixel (|v x a| <= 2^15 x 2^8, int32), the weight
// a itself in the last plane, each box's columns summed in-register. A step is a whole number
// of boxes (8 columns, 16 at level 4), from x0 (a multiple of 2^L); the rest in C.
template <int C, int L>
LB_AVX2 void WeightedBoxAvx2T(const int16_t* const* v, const int16_t* s, const uint16_t* layer_of,
                              int32_t offset, int32_t k, int32_t shift, int32_t x0, int32_t x1,
                              int32_t* const* box) {
  constexpr int32_t kStep = L <= 3 ? 8 : 16;
  const __m128i count = _mm_cvtsi32_si128(shift);
  const __m256i layer = _mm256_set1_epi32(k);
  int32_t x = x0;
  for (; x + kStep - 1 <= x1; x += kStep) {
    __m256i sum[C + 1];
    for (int32_t i = 0; i < kStep; i += 8) {
      const __m256i a = Weights(s + x + i, layer_of + offset, layer);
      for (int32_t c = 0; c <= C; ++c) {
        const __m256i t =
            c == C ? a : _mm256_sra_epi32(_mm256_mullo_epi32(Widen(v[c] + x + i), a), count);
        sum[c] = i == 0 ? t : _mm256_add_epi32(sum[c], t);
      }
    }
    for (int32_t c = 0; c <= C; ++c) AddGroups<L>(sum[c], box[c] + (x >> L));
  }
  WeightedBoxRowC<C>(v, s, layer_of, offset, k, shift, L, x, x1, box);
}

// As WeightedPrefixRowC: the same increments as WeightedBoxAvx2T's, their running sums over
// 8 columns in-register (each 128-bit half's own by two shifts, then the low half's total into
// the high one), plus the prefix before the step; wrapping uint32 adds, so the same bits.
template <int C>
LB_AVX2 void WeightedPrefixRowAvx2(const int16_t* const* v, const int16_t* s,
                                   const uint16_t* layer_of, int32_t offset, int32_t k,
                                   int32_t shift, int32_t x0, int32_t x1, uint32_t* const* p) {
  const __m128i count = _mm_cvtsi32_si128(shift);
  const __m256i layer = _mm256_set1_epi32(k), last = _mm256_set1_epi32(7);
  const __m256i third = _mm256_set1_epi32(3);
  __m256i before[C + 1];
  for (int32_t c = 0; c <= C; ++c) before[c] = _mm256_set1_epi32(static_cast<int32_t>(p[c][x0]));
  int32_t x = x0;
  for (; x + 7 <= x1; x += 8) {
    const __m256i a = Weights(s + x, layer_of + offset, layer);
    for (int32_t c = 0; c <= C; ++c) {
      const __m256i t =
          c == C ? a : _mm256_sra_epi32(_mm256_mullo_epi32(Widen(v[c] + x), a), count);
      __m256i u = _mm256_add_epi32(t, _mm256_slli_si256(t, 4));
      u = _mm256_add_epi32(u, _mm256_slli_si256(u, 8));
      const __m256i low = _mm256_permutevar8x32_epi32(u, third);
      u = _mm256_add_epi32(u, _mm256_blend_epi32(_mm256_setzero_si256(), low, 0xf0));
      const __m256i out = _mm256_add_epi32(u, before[c]);
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(p[c] + x + 1), out);
      before[c] = _mm256_permutevar8x32_epi32(out, last);
    }
  }
  WeightedPrefixRowC<C>(v, s, layer_of, offset, k, shift, x, x1, p);
}

// As PureBoxRowC: v << (8 - shift) summed per box (the sum of the shifted values equals the
// shifted sum, modulo 2^32 as the reference's int32), and the weight 256 per pixel.
template <int C, int L>
LB_AVX2 void PureBoxAvx2T(const int16_t* const* v, int32_t shift, int32_t x0, int32_t x1,
                          int32_t* const* box) {
  constexpr int32_t kStep = L <= 3 ? 8 : 16;
  const __m128i up = _mm_cvtsi32_si128(8 - shift);
  const __m256i weights = _mm256_set1_epi32(256 * kStep / 8);
  int32_t x = x0;
  for (; x + kStep - 1 <= x1; x += kStep) {
    for (int32_t c = 0; c < C; ++c) {
      __m256i sum = Widen(v[c] + x);
      if (kStep == 16) sum = _mm256_add_epi32(sum, Widen(v[c] + x + 8));
      AddGroups<L>(_mm256_sll_epi32(sum, up), box[c] + (x >> L));
    }
    AddGroups<L>(weights, box[C] + (x >> L));
  }
  PureBoxRowC<C>(v, shift, L, x, x1, box);
}

template <int C>
LB_AVX2 void WeightedBoxRowAvx2(const int16_t* const* v, const int16_t* s, const uint16_t* layer_of,
                                int32_t offset, int32_t k, int32_t shift, int32_t level, int32_t x0,
                                int32_t x1, int32_t* const* box) {
  constexpr decltype(&WeightedBoxAvx2T<C, 1>) kByLevel[] = {
      WeightedBoxAvx2T<C, 1>, WeightedBoxAvx2T<C, 2>, WeightedBoxAvx2T<C, 3>,
      WeightedBoxAvx2T<C, 4>};
  kByLevel[level - 1](v, s, layer_of, offset, k, shift, x0, x1, box);
}

template <int C>
LB_AVX2 void PureBoxRowAvx2(const int16_t* const* v, int32_t shift, int32_t level, int32_t x0,
                            int32_t x1, int32_t* const* box) {
  constexpr decltype(&PureBoxAvx2T<C, 1>) kByLevel[] = {PureBoxAvx2T<C, 1>, PureBoxAvx2T<C, 2>,
                                                        PureBoxAvx2T<C, 3>, PureBoxAvx2T<C, 4>};
  kByLevel[level - 1](v, shift, x0, x1, box);
}

// 32 x 32 -> 64-bit products of every lane with r (below 2^32 unsigned, 2^31 signed): the even
// lanes' in `even`, the odd lanes' in `odd`.
template <bool kSigned>
LB_AVX2 inline void Products(__m256i v, __m256i r, __m256i* even, __m256i* odd) {
  const __m256i v_odd = _mm256_srli_epi64(v, 32);
  *even = kSigned ? _mm256_mul_epi32(v, r) : _mm256_mul_epu32(v, r);
  *odd = kSigned ? _mm256_mul_epi32(v_odd, r) : _mm256_mul_epu32(v_odd, r);
}

// (acc x rec) >> 32 as the reference, for rec < 2^32 (then below 2^32 for any acc), then the
// clamp to 65536 (unsigned compare); a larger rec (a kernel of total weight 256) takes C.
LB_AVX2 void NormaliseAlphaRowAvx2(const uint32_t* acc, uint64_t rec, int32_t x0, int32_t x1,
                                   int32_t* alpha) {
  int32_t x = x0;
  if (rec <= 0xffffffffu) {
    const __m256i r = _mm256_set1_epi64x(static_cast<int64_t>(rec));
    const __m256i unit = _mm256_set1_epi32(65536);
    for (; x + 7 <= x1; x += 8) {
      __m256i even, odd;
      Products<false>(Load(acc + x), r, &even, &odd);
      const __m256i a = _mm256_blend_epi32(_mm256_srli_epi64(even, 32), odd, 0xaa);
      Store(alpha + x, _mm256_min_epu32(a, unit));
    }
  }
  NormaliseAlphaRowC(acc, rec, x, x1, alpha);
}

// The reference's int32 result is bits 32 - shift .. 63 - shift of the int64 product, whatever
// its sign: a logical shift of the even lanes' products right by 32 - shift and of the odd
// lanes' left by shift puts them in place. rec below 2^31 (a signed multiplier; a kernel's
// total weight is then above 512), else C.
LB_AVX2 void NormaliseColourRowAvx2(const uint32_t* acc, uint64_t rec, int32_t shift, int32_t x0,
                                    int32_t x1, int32_t* colour) {
  int32_t x = x0;
  if (rec < 0x80000000u) {
    const __m256i r = _mm256_set1_epi64x(static_cast<int64_t>(rec));
    const __m128i down = _mm_cvtsi32_si128(32 - shift), up = _mm_cvtsi32_si128(shift);
    for (; x + 7 <= x1; x += 8) {
      __m256i even, odd;
      Products<true>(Load(acc + x), r, &even, &odd);
      Store(colour + x,
            _mm256_blend_epi32(_mm256_srl_epi64(even, down), _mm256_sll_epi64(odd, up), 0xaa));
    }
  }
  NormaliseColourRowC(acc, rec, shift, x, x1, colour);
}

// (a (256 - fy) + b fy + 128) >> 8 = a + ((b - a) fy + 128) >> 8, the Lerp above (Q16 rows
// below 2^28, so b - a fits int32). Each output reads only its own column, so the last step
// overlaps the one before.
LB_AVX2 void BlendRowsAvx2(const int32_t* a, const int32_t* b, int64_t fy, int32_t q0, int32_t q1,
                           int32_t* col) {
  if (q1 - q0 < 7) return BlendRowsC(a, b, fy, q0, q1, col);
  const __m256i f = _mm256_set1_epi32(static_cast<int32_t>(fy));
  for (int32_t step = q0; step <= q1; step += 8) {
    const int32_t q = step + 7 <= q1 ? step : q1 - 7;
    Store(col + q, Lerp(Load(a + q), Load(b + q), f));
  }
  col[q0 - 1] = col[q0];
  col[q1 + 1] = col[q1];
}

// The rounded means (arithmetic shift, as the reference) summed in-register: two shifted adds
// give each 128-bit half's running sums, the low half's total is added to the high half, then
// the running total p[q] to all; wrapping as the reference's uint32.
LB_AVX2 void BoxPrefixRowAvx2(const int32_t* box, int32_t level, int32_t q0, int32_t q1,
                              uint32_t* p) {
  const __m256i round = _mm256_set1_epi32(1 << (2 * level - 1));
  const __m128i count = _mm_cvtsi32_si128(2 * level);
  const __m256i last = _mm256_set1_epi32(7);
  __m256i total = _mm256_set1_epi32(static_cast<int32_t>(p[q0]));
  int32_t q = q0;
  for (; q + 7 <= q1; q += 8) {
    __m256i m = _mm256_sra_epi32(_mm256_add_epi32(Load(box + q), round), count);
    m = _mm256_add_epi32(m, _mm256_slli_si256(m, 4));
    m = _mm256_add_epi32(m, _mm256_slli_si256(m, 8));
    const __m256i low_total = _mm256_permute2x128_si256(
        _mm256_shuffle_epi32(m, _MM_SHUFFLE(3, 3, 3, 3)), m, 0x08);  // high half only
    m = _mm256_add_epi32(_mm256_add_epi32(m, low_total), total);
    Store(p + q + 1, m);
    total = _mm256_permutevar8x32_epi32(m, last);
  }
  BoxPrefixRowC(box, level, q, q1, p);
}

// The reference's round(out / alpha), half away from zero, as sign x trunc((|out| + alpha / 2)
// / alpha) in double: the dividend is below 2^31 and the divisor at most 2^16, so a quotient
// that is not an integer lies at least 2^-16 from one, far more than the division's rounding
// error (2^31 x 2^-53), and truncating the rounded quotient gives the exact floor. Then the
// saturating packs clamp to 0..255 as the reference (int16 saturation keeps every value's side
// of 0..255). A step with an empty pixel (alpha 0: its own value) takes C.
LB_AVX2 inline __m128i Quotients(__m128i num, __m128i den) {
  return _mm256_cvttpd_epi32(_mm256_div_pd(_mm256_cvtepi32_pd(num), _mm256_cvtepi32_pd(den)));
}

LB_AVX2 void ResolveRowAvx2(const int32_t* out, const int32_t* alpha, const int16_t* v,
                            int32_t width, int32_t bias, uint8_t* dst) {
  const __m256i zero = _mm256_setzero_si256(), b = _mm256_set1_epi32(bias);
  int32_t x = 0;
  for (; x + 7 < width; x += 8) {
    const __m256i a = Load(alpha + x);
    if (_mm256_movemask_epi8(_mm256_cmpgt_epi32(a, zero)) != -1) {
      ResolveRowC(out + x, alpha + x, v + x, 8, bias, dst + x);
      continue;
    }
    const __m256i o = Load(out + x);
    const __m256i sign = _mm256_srai_epi32(o, 31);
    const __m256i n = _mm256_add_epi32(_mm256_abs_epi32(o), _mm256_srli_epi32(a, 1));
    const __m256i r = _mm256_setr_m128i(
        Quotients(_mm256_castsi256_si128(n), _mm256_castsi256_si128(a)),
        Quotients(_mm256_extracti128_si256(n, 1), _mm256_extracti128_si256(a, 1)));
    const __m256i value = _mm256_add_epi32(_mm256_sub_epi32(_mm256_xor_si256(r, sign), sign), b);
    const __m128i words =
        _mm_packs_epi32(_mm256_castsi256_si128(value), _mm256_extracti128_si256(value, 1));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(dst + x), _mm_packus_epi16(words, words));
  }
  ResolveRowC(out + x, alpha + x, v + x, width - x, bias, dst + x);
}

}  // namespace

const Kernels* Avx2Kernels() {
  static constexpr Kernels kAvx2 = {GatherRowCAvx2,
                                    CompositeRowAvx2,
                                    {LerpCompositeAvx2<1>, LerpCompositeAvx2<2>},
                                    {WeightedBoxRowAvx2<1>, WeightedBoxRowAvx2<2>},
                                    {PureBoxRowAvx2<1>, PureBoxRowAvx2<2>},
                                    NormaliseAlphaRowAvx2,
                                    NormaliseColourRowAvx2,
                                    BlendRowsAvx2,
                                    BoxPrefixRowAvx2,
                                    ResolveRowAvx2,
                                    {WeightedPrefixRowAvx2<1>, WeightedPrefixRowAvx2<2>}};
  return __builtin_cpu_supports("avx2") ? &kAvx2 : nullptr;
}

}  // namespace lb::layer_rows
#else
namespace lb::layer_rows {
const Kernels* Avx2Kernels() { return nullptr; }
}  // namespace lb::layer_rows
#endif
