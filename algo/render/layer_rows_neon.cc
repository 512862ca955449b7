// NEON twins of the layer row kernels (layer_rows.h), 4 or 8 pixels a step, the tail of a row
// (and any row outside a twin's bounds) by the C reference; ARMv7 intrinsics only, so aarch64
// and armhf share them. armhf's baseline has no NEON: this file's functions alone are compiled
// for it (the pragma below, after every include, so no inline function of a shared header is
// built with NEON), and the caller must know the CPU has it. The products are split into
// 32-bit parts as the AVX2 twins do, or taken in 64-bit lanes (vmull); each kernel says why its
// result is the reference's.
#include "algo/render/layer_rows.h"

#if defined(__ARM_NEON) || defined(__arm__)
#include <arm_neon.h>

#if defined(__arm__)
#pragma GCC push_options
#pragma GCC target("fpu=neon")
#endif

namespace lb::layer_rows {
namespace {

// a + ((b - a) x f + 128) >> 8 (floor), f 0..255, |b - a| < 2^31: with d = 256 dh + dl that is
// a + dh x f + ((dl x f + 128) >> 8), each part in 32 bits (|dh x f| < 2^31, dl x f < 2^16).
inline int32x4_t Lerp(int32x4_t a, int32x4_t b, int32x4_t f) {
  const int32x4_t d = vsubq_s32(b, a);
  const int32x4_t low = vmulq_s32(vandq_s32(d, vdupq_n_s32(255)), f);
  return vaddq_s32(vmlaq_s32(a, vshrq_n_s32(d, 8), f), vrshrq_n_s32(low, 8));
}

// ((o x keep + 32768) >> 16) + colour, keep 0..65536: with o = 65536 oh + ol that is
// oh x keep + ((ol x keep + 32768) >> 16), the second part below 2^32 (unsigned), the first and
// the sum wrapping as the reference's cast to int32 does.
inline int32x4_t Over(int32x4_t o, int32x4_t keep, int32x4_t colour) {
  const uint32x4_t ol = vandq_u32(vreinterpretq_u32_s32(o), vdupq_n_u32(0xffff));
  const uint32x4_t low = vrshrq_n_u32(vmulq_u32(ol, vreinterpretq_u32_s32(keep)), 16);
  const int32x4_t high = vmulq_s32(vshrq_n_s32(o, 16), keep);
  return vaddq_s32(vaddq_s32(high, vreinterpretq_s32_u32(low)), colour);
}

void CompositeRowNeon(int32_t* out, const int32_t* colour, const int32_t* alpha, int32_t x0,
                      int32_t x1) {
  const int32x4_t unit = vdupq_n_s32(65536);
  int32_t x = x0;
  for (; x + 3 <= x1; x += 4) {
    const int32x4_t keep = vsubq_s32(unit, vld1q_s32(alpha + x));
    vst1q_s32(out + x, Over(vld1q_s32(out + x), keep, vld1q_s32(colour + x)));
  }
  CompositeRowC(out, colour, alpha, x, x1);
}

// The lanes of `row` picked by byte indices (4 per lane).
inline int32x4_t Pick(int32x4_t row, uint8x16_t bytes) {
#if defined(__aarch64__)
  return vreinterpretq_s32_u8(vqtbl1q_u8(vreinterpretq_u8_s32(row), bytes));
#else
  const uint8x16_t r = vreinterpretq_u8_s32(row);
  const uint8x8x2_t t = {{vget_low_u8(r), vget_high_u8(r)}};
  return vreinterpretq_s32_u8(
      vcombine_u8(vtbl2_u8(t, vget_low_u8(bytes)), vtbl2_u8(t, vget_high_u8(bytes))));
#endif
}

// Four output columns x .. x + 3 read taps q(x) .. q(x + 3) + 1, at most 4 (level >= 1): one
// load of the low-res row from q(x), where all four lie before the last tap of the row (else C),
// and two table lookups give each lane its left and right tap. Eight columns a step (one load
// of frac), as two halves.
template <int C>
void LerpCompositeNeon(const int32_t* col, ptrdiff_t stride, const uint8_t* frac, int32_t level,
                       int32_t x0, int32_t x1, int32_t* out, ptrdiff_t out_stride) {
  const int32_t half = (1 << level) / 2;
  const int32_t last = ((x1 - half) >> level) + 1;  // the last tap the row has
  const int32x4_t lanes = {0, 1, 2, 3}, down = vdupq_n_s32(-level);
  const uint32x4_t byte_of_lane = vdupq_n_u32(0x03020100);
  const int32x4_t unit = vdupq_n_s32(65536);
  int32_t x = x0;
  for (; x + 7 <= x1 && ((x + 4 - half) >> level) + 3 <= last; x += 8) {
    const uint16x8_t f8 = vmovl_u8(vld1_u8(frac + x));
    for (int32_t h = 0; h < 2; ++h) {
      const int32_t xs = x + 4 * h;
      const int32_t q = (xs - half) >> level;
      const int32x4_t left =
          vsubq_s32(vshlq_s32(vaddq_s32(vdupq_n_s32(xs - half), lanes), down), vdupq_n_s32(q));
      const uint32x4_t lb = vmlaq_n_u32(byte_of_lane, vreinterpretq_u32_s32(left), 0x04040404);
      const uint8x16_t lbytes = vreinterpretq_u8_u32(lb);
      const uint8x16_t rbytes = vreinterpretq_u8_u32(vaddq_u32(lb, vdupq_n_u32(0x04040404)));
      const int32x4_t f =
          vreinterpretq_s32_u32(vmovl_u16(h == 0 ? vget_low_u16(f8) : vget_high_u16(f8)));
      int32x4_t v[C + 1];
      for (int32_t c = 0; c <= C; ++c) {
        const int32x4_t row = vld1q_s32(col + c * stride + q);
        v[c] = Lerp(Pick(row, lbytes), Pick(row, rbytes), f);
      }
      const int32x4_t keep = vsubq_s32(unit, v[C]);
      for (int32_t c = 0; c <= C; ++c) {
        int32_t* o = out + c * out_stride + xs;
        vst1q_s32(o, Over(vld1q_s32(o), keep, v[c]));
      }
    }
  }
  LerpCompositeC<C>(col, stride, frac, level, x, x1, out, out_stride);
}

// Adds each group of 2^L lanes' sum, in order, to box[0 ..]: two pairs (L 1) or the whole
// vector (L >= 2: 4 columns, or 8 or 16 already added lane-wise). int32 wrapping adds, as the
// reference's (its sums stay below 2^27: layer_rows.h).
template <int L>
inline void AddGroups(int32x4_t c, int32_t* box) {
  const int32x2_t pairs = vpadd_s32(vget_low_s32(c), vget_high_s32(c));
  if constexpr (L == 1) {
    vst1_s32(box, vadd_s32(vld1_s32(box), pairs));
  } else {
    box[0] += vget_lane_s32(vpadd_s32(pairs, pairs), 0);
  }
}

// LayerWeightQ8 of layer k for 4 pixels: the table looked up one pixel at a time, the choice
// between 256 - frac, frac and 0 in-register.
inline int32x4_t Weights(const int16_t* s, const uint16_t* table, int32x4_t k) {
  const int32x4_t e = {table[s[0]], table[s[1]], table[s[2]], table[s[3]]};
  const int32x4_t first = vshrq_n_s32(e, 8), frac = vandq_s32(e, vdupq_n_s32(255));
  const int32x4_t in_first =
      vandq_s32(vreinterpretq_s32_u32(vceqq_s32(first, k)), vsubq_s32(vdupq_n_s32(256), frac));
  const int32x4_t in_next =
      vandq_s32(vreinterpretq_s32_u32(vceqq_s32(vaddq_s32(first, vdupq_n_s32(1)), k)), frac);
  return vorrq_s32(in_first, in_next);
}

// As WeightedPrefixRowC: the same increments as WeightedBoxNeonT's, their running sums over 4
// columns in-register (two shifts), plus the prefix before the step; wrapping uint32 adds, so
// the same bits.
template <int C>
void WeightedPrefixRowNeon(const int16_t* const* v, const int16_t* s, const uint16_t* layer_of,
                           int32_t offset, int32_t k, int32_t shift, int32_t x0, int32_t x1,
                           uint32_t* const* p) {
  const int32x4_t down = vdupq_n_s32(-shift), layer = vdupq_n_s32(k);
  const uint32x4_t zero = vdupq_n_u32(0);
  uint32x4_t before[C + 1];
  for (int32_t c = 0; c <= C; ++c) before[c] = vdupq_n_u32(p[c][x0]);
  int32_t x = x0;
  for (; x + 3 <= x1; x += 4) {
    const int32x4_t a = Weights(s + x, layer_of + offset, layer);
    for (int32_t c = 0; c <= C; ++c) {
      const uint32x4_t t = vreinterpretq_u32_s32(
          c == C ? a : vshlq_s32(vmulq_s32(vmovl_s16(vld1_s16(v[c] + x)), a), down));
      uint32x4_t u = vaddq_u32(t, vextq_u32(zero, t, 3));
      u = vaddq_u32(u, vextq_u32(zero, u, 2));
      const uint32x4_t out = vaddq_u32(u, before[c]);
      vst1q_u32(p[c] + x + 1, out);
      before[c] = vdupq_n_u32(vgetq_lane_u32(out, 3));
    }
  }
  WeightedPrefixRowC<C>(v, s, layer_of, offset, k, shift, x, x1, p);
}

// As WeightedBoxRowC: c = (v x a) >> shift per pixel (|v x a| <= 2^15 x 2^8, int32), the weight
// a itself in the last plane, each box's columns summed in-register. A step is a whole number
// of boxes (4 columns, 2^L from level 2), from x0 (a multiple of 2^L); the rest in C.
template <int C, int L>
void WeightedBoxNeonT(const int16_t* const* v, const int16_t* s, const uint16_t* layer_of,
                      int32_t offset, int32_t k, int32_t shift, int32_t x0, int32_t x1,
                      int32_t* const* box) {
  constexpr int32_t kStep = L <= 2 ? 4 : 1 << L;
  const int32x4_t down = vdupq_n_s32(-shift), layer = vdupq_n_s32(k);
  int32_t x = x0;
  for (; x + kStep - 1 <= x1; x += kStep) {
    int32x4_t sum[C + 1];
    for (int32_t i = 0; i < kStep; i += 4) {
      const int32x4_t a = Weights(s + x + i, layer_of + offset, layer);
      for (int32_t c = 0; c <= C; ++c) {
        const int32x4_t t =
            c == C ? a : vshlq_s32(vmulq_s32(vmovl_s16(vld1_s16(v[c] + x + i)), a), down);
        sum[c] = i == 0 ? t : vaddq_s32(sum[c], t);
      }
    }
    for (int32_t c = 0; c <= C; ++c) AddGroups<L>(sum[c], box[c] + (x >> L));
  }
  WeightedBoxRowC<C>(v, s, layer_of, offset, k, shift, L, x, x1, box);
}

// As PureBoxRowC: v << (8 - shift) summed per box (the sum of the shifted values equals the
// shifted sum, modulo 2^32 as the reference's int32), and the weight 256 per pixel.
template <int C, int L>
void PureBoxNeonT(const int16_t* const* v, int32_t shift, int32_t x0, int32_t x1,
                  int32_t* const* box) {
  constexpr int32_t kStep = L <= 2 ? 4 : 1 << L;
  const int32x4_t up = vdupq_n_s32(8 - shift), weights = vdupq_n_s32(256 * kStep / 4);
  int32_t x = x0;
  for (; x + kStep - 1 <= x1; x += kStep) {
    for (int32_t c = 0; c < C; ++c) {
      int32x4_t sum = vmovl_s16(vld1_s16(v[c] + x));
      for (int32_t i = 4; i < kStep; i += 4) sum = vaddw_s16(sum, vld1_s16(v[c] + x + i));
      AddGroups<L>(vshlq_s32(sum, up), box[c] + (x >> L));
    }
    AddGroups<L>(weights, box[C] + (x >> L));
  }
  PureBoxRowC<C>(v, shift, L, x, x1, box);
}

template <int C>
void WeightedBoxRowNeon(const int16_t* const* v, const int16_t* s, const uint16_t* layer_of,
                        int32_t offset, int32_t k, int32_t shift, int32_t level, int32_t x0,
                        int32_t x1, int32_t* const* box) {
  constexpr decltype(&WeightedBoxNeonT<C, 1>) kByLevel[] = {
      WeightedBoxNeonT<C, 1>, WeightedBoxNeonT<C, 2>, WeightedBoxNeonT<C, 3>,
      WeightedBoxNeonT<C, 4>};
  kByLevel[level - 1](v, s, layer_of, offset, k, shift, x0, x1, box);
}

template <int C>
void PureBoxRowNeon(const int16_t* const* v, int32_t shift, int32_t level, int32_t x0, int32_t x1,
                    int32_t* const* box) {
  constexpr decltype(&PureBoxNeonT<C, 1>) kByLevel[] = {PureBoxNeonT<C, 1>, PureBoxNeonT<C, 2>,
                                                        PureBoxNeonT<C, 3>, PureBoxNeonT<C, 4>};
  kByLevel[level - 1](v, shift, x0, x1, box);
}

// (acc x rec) >> 32 in 64-bit lanes for rec < 2^32 (then below 2^32: the narrowing shift keeps
// it), clamped to 65536; a larger rec (a kernel of total weight 256) takes C.
void NormaliseAlphaRowNeon(const uint32_t* acc, uint64_t rec, int32_t x0, int32_t x1,
                           int32_t* alpha) {
  int32_t x = x0;
  if (rec <= 0xffffffffu) {
    const uint32x2_t r = vdup_n_u32(static_cast<uint32_t>(rec));
    const uint32x4_t unit = vdupq_n_u32(65536);
    for (; x + 3 <= x1; x += 4) {
      const uint32x4_t a = vld1q_u32(acc + x);
      const uint32x4_t n = vcombine_u32(vshrn_n_u64(vmull_u32(vget_low_u32(a), r), 32),
                                        vshrn_n_u64(vmull_u32(vget_high_u32(a), r), 32));
      vst1q_s32(alpha + x, vreinterpretq_s32_u32(vminq_u32(n, unit)));
    }
  }
  NormaliseAlphaRowC(acc, rec, x, x1, alpha);
}

// int32(acc) x rec in signed 64-bit lanes (rec < 2^31; a kernel's total weight is then above
// 512, else C), shifted right arithmetically by 32 - shift, its low 32 bits kept: the
// reference's int64 expression and cast.
void NormaliseColourRowNeon(const uint32_t* acc, uint64_t rec, int32_t shift, int32_t x0,
                            int32_t x1, int32_t* colour) {
  int32_t x = x0;
  if (rec < 0x80000000u) {
    const int32x2_t r = vdup_n_s32(static_cast<int32_t>(rec));
    const int64x2_t down = vdupq_n_s64(shift - 32);
    for (; x + 3 <= x1; x += 4) {
      const int32x4_t s = vreinterpretq_s32_u32(vld1q_u32(acc + x));
      const int64x2_t lo = vshlq_s64(vmull_s32(vget_low_s32(s), r), down);
      const int64x2_t hi = vshlq_s64(vmull_s32(vget_high_s32(s), r), down);
      vst1q_s32(colour + x, vcombine_s32(vmovn_s64(lo), vmovn_s64(hi)));
    }
  }
  NormaliseColourRowC(acc, rec, shift, x, x1, colour);
}

// a + ((b - a) fy + 128) >> 8, the Lerp above (Q16 rows below 2^28, so b - a fits int32). Each
// output reads only its own column, so the last step overlaps the one before.
void BlendRowsNeon(const int32_t* a, const int32_t* b, int64_t fy, int32_t q0, int32_t q1,
                   int32_t* col) {
  if (q1 - q0 < 3) return BlendRowsC(a, b, fy, q0, q1, col);
  const int32x4_t f = vdupq_n_s32(static_cast<int32_t>(fy));
  for (int32_t step = q0; step <= q1; step += 4) {
    const int32_t q = step + 3 <= q1 ? step : q1 - 3;
    vst1q_s32(col + q, Lerp(vld1q_s32(a + q), vld1q_s32(b + q), f));
  }
  col[q0 - 1] = col[q0];
  col[q1 + 1] = col[q1];
}

// The rounded means (arithmetic shift, as the reference), their running sums in-register (two
// shifted adds), plus the running total p[q]; wrapping as the reference's uint32.
void BoxPrefixRowNeon(const int32_t* box, int32_t level, int32_t q0, int32_t q1, uint32_t* p) {
  const int32x4_t round = vdupq_n_s32(1 << (2 * level - 1)), down = vdupq_n_s32(-2 * level);
  const int32x4_t zero = vdupq_n_s32(0);
  int32x4_t total = vdupq_n_s32(static_cast<int32_t>(p[q0]));
  int32_t q = q0;
  for (; q + 3 <= q1; q += 4) {
    int32x4_t m = vshlq_s32(vaddq_s32(vld1q_s32(box + q), round), down);
    m = vaddq_s32(m, vextq_s32(zero, m, 3));
    m = vaddq_s32(m, vextq_s32(zero, m, 2));
    m = vaddq_s32(m, total);
    vst1q_u32(p + q + 1, vreinterpretq_u32_s32(m));
    total = vdupq_lane_s32(vget_high_s32(m), 1);
  }
  BoxPrefixRowC(box, level, q, q1, p);
}

// Fully covered runs (alpha exactly 65536, most of a photo) round the shift with the sign
// outside ((|out| + 32768) >> 16, |out| < 2^31 - 2^16), then the saturating narrows clamp to
// 0..255 as the reference (int16 saturation keeps every value's side of 0..255); a step with
// any other alpha divides in C.
void ResolveRowNeon(const int32_t* out, const int32_t* alpha, const int16_t* v, int32_t width,
                    int32_t bias, uint8_t* dst) {
  const int32x4_t unit = vdupq_n_s32(65536), b = vdupq_n_s32(bias);
  int32_t x = 0;
  for (; x + 7 < width; x += 8) {
    const uint32x4_t e =
        vandq_u32(vceqq_s32(vld1q_s32(alpha + x), unit), vceqq_s32(vld1q_s32(alpha + x + 4), unit));
    const uint32x2_t e2 = vand_u32(vget_low_u32(e), vget_high_u32(e));
    if ((vget_lane_u32(e2, 0) & vget_lane_u32(e2, 1)) != 0xffffffffu) {
      ResolveRowC(out + x, alpha + x, v + x, 8, bias, dst + x);
      continue;
    }
    int16x4_t words[2];
    for (int32_t h = 0; h < 2; ++h) {
      const int32x4_t o = vld1q_s32(out + x + 4 * h);
      const int32x4_t sign = vshrq_n_s32(o, 31);
      const int32x4_t r = vreinterpretq_s32_u32(
          vrshrq_n_u32(vreinterpretq_u32_s32(vabsq_s32(o)), 16));  // (|o| + 32768) >> 16
      words[h] = vqmovn_s32(vaddq_s32(vsubq_s32(veorq_s32(r, sign), sign), b));
    }
    vst1_u8(dst + x, vqmovun_s16(vcombine_s16(words[0], words[1])));
  }
  ResolveRowC(out + x, alpha + x, v + x, width - x, bias, dst + x);
}

}  // namespace

const Kernels* NeonKernels() {
  static constexpr Kernels kNeon = {GatherRowCNeon,
                                    CompositeRowNeon,
                                    {LerpCompositeNeon<1>, LerpCompositeNeon<2>},
                                    {WeightedBoxRowNeon<1>, WeightedBoxRowNeon<2>},
                                    {PureBoxRowNeon<1>, PureBoxRowNeon<2>},
                                    NormaliseAlphaRowNeon,
                                    NormaliseColourRowNeon,
                                    BlendRowsNeon,
                                    BoxPrefixRowNeon,
                                    ResolveRowNeon,
                                    {WeightedPrefixRowNeon<1>, WeightedPrefixRowNeon<2>}};
  return &kNeon;
}

}  // namespace lb::layer_rows

#if defined(__arm__)
#pragma GCC pop_options
#endif
#else
namespace lb::layer_rows {
const Kernels* NeonKernels() { return nullptr; }
}  // namespace lb::layer_rows
#endif
