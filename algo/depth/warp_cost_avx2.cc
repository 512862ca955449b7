// The plane sweep's span kernel for AVX2 (warp_cost.h; the C reference is dtk::PlaneSpanC in
// warp_cost.cc): 8 pixels a step in 32-bit lanes, the view's taps fetched with gathers. Ranges
// shorter than a step, and views too small or too large for its 32-bit offsets, take the
// reference.
#include "algo/depth/data_term_kernels.h"

#if defined(__x86_64__)
#include <immintrin.h>

#include <cstring>
#define LB_AVX2 __attribute__((target("avx2")))

namespace lb::dtk {
namespace {

constexpr int32_t kLanes = 8;

// Byte shuffles, per 32-bit lane: kPair puts bytes 0 and 3 of a gathered RGBR / BRGB word in the
// two 16-bit halves (the same channel of two neighbouring pixels); kPairG does so for bytes 1
// and 2 (the green pair, after a blend of the two words). kRef[c] picks channel c of pixels 0-3
// from the low half of 24 reference bytes loaded as bytes 0-15 and 8-23.
struct Masks {
  alignas(32) int8_t pair[32], pair_g[32], ref[3][32], nibble_bits[32];
  constexpr Masks() : pair(), pair_g(), ref(), nibble_bits() {
    for (int32_t i = 0; i < 32; ++i) {
      const int32_t k = i % 4, dword = (i % 16) & ~3;  // shuffles index within 128-bit halves
      pair[i] = static_cast<int8_t>(k == 0 ? dword : k == 2 ? dword + 3 : -128);
      pair_g[i] = static_cast<int8_t>(k == 0 ? dword + 1 : k == 2 ? dword + 2 : -128);
      for (int32_t c = 0; c < 3; ++c) {
        const int32_t pixel = (i % 16) / 4, first = i < 16 ? 0 : 4;  // high half: bytes 8-23
        ref[c][i] = static_cast<int8_t>(k == 0 ? first + 3 * pixel + c : -128);
      }
      nibble_bits[i] = static_cast<int8_t>(__builtin_popcount(i % 16));
    }
  }
};
constexpr Masks kMasks;

LB_AVX2 inline __m256i Load(const void* p) {
  return _mm256_load_si256(static_cast<const __m256i*>(p));
}

LB_AVX2 inline __m256i Gather(const uint8_t* base, __m256i offset) {
  return _mm256_i32gather_epi32(reinterpret_cast<const int*>(base), offset, 1);
}

// 8 bytes of a plane, one per 32-bit lane.
LB_AVX2 inline __m256i Widen8(const uint8_t* p) {
  return _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)));
}

// Per 32-bit lane, bytes [c0 c1 c2 c3] of the RGB taps a (x, y) and b (x + 1, y) gathered as
// ab0 = [aR aG aB bR] and ab2 = [aB bR bG bB]: channel c of a times gx plus channel c of b times
// fx, all <= 256, so 16-bit pairs multiply-add exactly into <= 65280.
struct Row3 {
  __m256i c[3];
};
LB_AVX2 inline Row3 Horizontal(__m256i ab0, __m256i ab2, __m256i wx) {
  const __m256i pair = Load(kMasks.pair);
  const __m256i green =
      _mm256_shuffle_epi8(_mm256_blend_epi16(ab0, ab2, 0xaa), Load(kMasks.pair_g));
  return {{_mm256_madd_epi16(_mm256_shuffle_epi8(ab0, pair), wx), _mm256_madd_epi16(green, wx),
           _mm256_madd_epi16(_mm256_shuffle_epi8(ab2, pair), wx)}};
}

// Format of each step (per lane, as dtk::PlaneSpanC): positions Q16 (|.| < 2^30), rounded to Q8
// and clamped to the view so every gather stays inside it (lanes outside take `invalid` at the
// end). The tap pair's left column is at most width - 2 with a weight of up to 256 on the right
// one (and likewise for rows): (w-1, f 0) becomes (w-2, f 256), the same sum. Colour:
// top * (256 - fy) + bottom * fy = 256 top + (bottom - top) fy <= 255 * 65536 (int32), rounded
// half up to Q0. Census: the nearest tap's 24 bits against the reference's, counted by nibble
// lookups (<= 24), times the weight (<= 10 in DataTermParams). Cost min(min(|dRGB|, trunc) +
// bits * weight, 255).
struct Consts {
  __m256i xmax, ymax, wm2, hm2, stride, census_row, plane, cw, trunc, invalid, lut;
};

LB_AVX2 void Step(const WarpRow& r, const Consts& k, int32_t x, __m256i xq, __m256i yq,
                  uint8_t* out) {
  const __m256i zero = _mm256_setzero_si256();
  const __m256i xs = _mm256_srai_epi32(_mm256_add_epi32(xq, _mm256_set1_epi32(128)), 8);
  const __m256i ys = _mm256_srai_epi32(_mm256_add_epi32(yq, _mm256_set1_epi32(128)), 8);
  const __m256i bad = _mm256_or_si256(
      _mm256_or_si256(_mm256_cmpgt_epi32(zero, xs), _mm256_cmpgt_epi32(xs, k.xmax)),
      _mm256_or_si256(_mm256_cmpgt_epi32(zero, ys), _mm256_cmpgt_epi32(ys, k.ymax)));
  const __m256i xc = _mm256_min_epi32(_mm256_max_epi32(xs, zero), k.xmax);
  const __m256i yc = _mm256_min_epi32(_mm256_max_epi32(ys, zero), k.ymax);
  const __m256i xb = _mm256_min_epi32(_mm256_srai_epi32(xc, 8), k.wm2);
  const __m256i yb = _mm256_min_epi32(_mm256_srai_epi32(yc, 8), k.hm2);
  const __m256i fx = _mm256_sub_epi32(xc, _mm256_slli_epi32(xb, 8));
  const __m256i fy = _mm256_sub_epi32(yc, _mm256_slli_epi32(yb, 8));
  const __m256i wx =
      _mm256_add_epi32(_mm256_sub_epi32(_mm256_set1_epi32(256), fx), _mm256_slli_epi32(fx, 16));
  const __m256i off = _mm256_add_epi32(_mm256_mullo_epi32(yb, k.stride),
                                       _mm256_add_epi32(xb, _mm256_add_epi32(xb, xb)));
  const __m256i two = _mm256_set1_epi32(2);
  const __m256i off1 = _mm256_add_epi32(off, k.stride);
  const Row3 top = Horizontal(Gather(r.view, off), Gather(r.view, _mm256_add_epi32(off, two)), wx);
  const Row3 bottom =
      Horizontal(Gather(r.view, off1), Gather(r.view, _mm256_add_epi32(off1, two)), wx);
  const __m128i ref_lo = _mm_loadu_si128(reinterpret_cast<const __m128i*>(r.ref + 3 * x));
  const __m128i ref_hi = _mm_loadu_si128(reinterpret_cast<const __m128i*>(r.ref + 3 * x + 8));
  const __m256i ref = _mm256_inserti128_si256(_mm256_castsi128_si256(ref_lo), ref_hi, 1);
  __m256i ad = zero;
  for (int32_t c = 0; c < 3; ++c) {
    const __m256i s =
        _mm256_add_epi32(_mm256_slli_epi32(top.c[c], 8),
                         _mm256_mullo_epi32(_mm256_sub_epi32(bottom.c[c], top.c[c]), fy));
    const __m256i v = _mm256_srai_epi32(_mm256_add_epi32(s, _mm256_set1_epi32(32768)), 16);
    const __m256i rc = _mm256_shuffle_epi8(ref, Load(kMasks.ref[c]));
    ad = _mm256_add_epi32(ad, _mm256_abs_epi32(_mm256_sub_epi32(rc, v)));
  }
  ad = _mm256_min_epi32(ad, k.trunc);
  // The nearest tap: the right (lower) one from a fraction of 128 on.
  const __m256i c127 = _mm256_set1_epi32(127);
  const __m256i nx = _mm256_sub_epi32(xb, _mm256_cmpgt_epi32(fx, c127));
  const __m256i ny = _mm256_sub_epi32(yb, _mm256_cmpgt_epi32(fy, c127));
  const __m256i coff = _mm256_add_epi32(_mm256_mullo_epi32(ny, k.census_row), nx);
  // Planes 0 and 1 read 4 bytes forward, plane 2 backward (its byte at the top), so no read
  // leaves the census row.
  const __m256i low = _mm256_set1_epi32(0xff);
  const __m256i v0 = _mm256_and_si256(Gather(r.census_view, coff), low);
  const __m256i v1 = _mm256_and_si256(Gather(r.census_view, _mm256_add_epi32(coff, k.plane)), low);
  const __m256i back = _mm256_sub_epi32(_mm256_add_epi32(k.plane, k.plane), _mm256_set1_epi32(3));
  const __m256i v2 = _mm256_srli_epi32(Gather(r.census_view, _mm256_add_epi32(coff, back)), 24);
  const __m256i view_bits =
      _mm256_or_si256(_mm256_or_si256(_mm256_slli_epi32(v0, 16), _mm256_slli_epi32(v1, 8)), v2);
  const __m256i ref_bits =
      _mm256_or_si256(_mm256_or_si256(_mm256_slli_epi32(Widen8(r.cref + x), 16),
                                      _mm256_slli_epi32(Widen8(r.cref + r.width + x), 8)),
                      Widen8(r.cref + 2 * r.width + x));
  const __m256i bits = _mm256_xor_si256(view_bits, ref_bits);
  const __m256i nib = _mm256_set1_epi8(0x0f);
  const __m256i count8 = _mm256_add_epi8(
      _mm256_shuffle_epi8(k.lut, _mm256_and_si256(bits, nib)),
      _mm256_shuffle_epi8(k.lut, _mm256_and_si256(_mm256_srli_epi16(bits, 4), nib)));
  const __m256i count =
      _mm256_madd_epi16(_mm256_maddubs_epi16(count8, _mm256_set1_epi8(1)), _mm256_set1_epi16(1));
  __m256i cost = _mm256_add_epi32(ad, _mm256_mullo_epi32(count, k.cw));
  cost = _mm256_min_epi32(cost, _mm256_set1_epi32(255));
  cost = _mm256_blendv_epi8(cost, k.invalid, bad);
  // 0..255 per lane: two packs leave pixels 0-3 in dword 0 and 4-7 in dword 4.
  const __m256i packed = _mm256_packus_epi16(_mm256_packus_epi32(cost, cost), zero);
  const uint32_t lo = static_cast<uint32_t>(_mm256_extract_epi32(packed, 0));
  const uint32_t hi = static_cast<uint32_t>(_mm256_extract_epi32(packed, 4));
  std::memcpy(out + x, &lo, 4);
  std::memcpy(out + x + 4, &hi, 4);
}

}  // namespace

// Positions as WarpSpan's Q32 accumulators, split so that 32-bit lanes give the same bits: with
// the step s = q 2^16 + r (0 <= r < 2^16), (a 2^16 + 2^15 + i s) >> 16 = a + i q +
// ((2^15 + i r) >> 16); i <= 16 keeps 2^15 + i r below 2^21, and a + i q wraps only where the
// exact result (a Q16 position, |.| < 2^30) does not.
LB_AVX2 void PlaneSpanAvx2(const WarpRow& r, const WarpSpanJob& job, uint8_t* out) {
  const int64_t bytes = int64_t{r.height} * r.stride;
  if (job.hi - job.lo < kLanes || r.width < 4 || r.height < 2 || r.stride <= 0 ||
      bytes >= (int64_t{1} << 31)) {
    return PlaneSpanC(r, job, out);
  }
  const int32_t n = job.n;
  const int64_t sx = n > 0 ? (int64_t{job.bx} - job.ax) * 65536 / n : 0;
  const int64_t sy = n > 0 ? (int64_t{job.by} - job.ay) * 65536 / n : 0;
  const __m256i qx = _mm256_set1_epi32(static_cast<int32_t>(sx >> 16));
  const __m256i qy = _mm256_set1_epi32(static_cast<int32_t>(sy >> 16));
  const __m256i rx = _mm256_set1_epi32(static_cast<int32_t>(sx & 0xffff));
  const __m256i ry = _mm256_set1_epi32(static_cast<int32_t>(sy & 0xffff));
  const __m256i half = _mm256_set1_epi32(32768);
  const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const Consts k{_mm256_set1_epi32((r.width - 1) * 256),
                 _mm256_set1_epi32((r.height - 1) * 256),
                 _mm256_set1_epi32(r.width - 2),
                 _mm256_set1_epi32(r.height - 2),
                 _mm256_set1_epi32(static_cast<int32_t>(r.stride)),
                 _mm256_set1_epi32(3 * r.width),
                 _mm256_set1_epi32(r.width),
                 _mm256_set1_epi32(r.cw),
                 _mm256_set1_epi32(r.trunc),
                 _mm256_set1_epi32(r.invalid),
                 Load(kMasks.nibble_bits)};
  for (int32_t step = job.lo; step < job.hi; step += kLanes) {
    // The last step overlaps the one before: the same bytes again.
    const int32_t x = step + kLanes <= job.hi ? step : job.hi - kLanes;
    const __m256i i = _mm256_add_epi32(_mm256_set1_epi32(x - job.x0), iota);
    const __m256i at_end = _mm256_cmpeq_epi32(i, _mm256_set1_epi32(n));
    __m256i xq =
        _mm256_add_epi32(_mm256_add_epi32(_mm256_set1_epi32(job.ax), _mm256_mullo_epi32(i, qx)),
                         _mm256_srli_epi32(_mm256_add_epi32(half, _mm256_mullo_epi32(i, rx)), 16));
    __m256i yq =
        _mm256_add_epi32(_mm256_add_epi32(_mm256_set1_epi32(job.ay), _mm256_mullo_epi32(i, qy)),
                         _mm256_srli_epi32(_mm256_add_epi32(half, _mm256_mullo_epi32(i, ry)), 16));
    xq = _mm256_blendv_epi8(xq, _mm256_set1_epi32(job.bx), at_end);
    yq = _mm256_blendv_epi8(yq, _mm256_set1_epi32(job.by), at_end);
    Step(r, k, x, xq, yq, out);
  }
}

}  // namespace lb::dtk
#endif
