// What the plane sweep's AVX2 kernels share (warp_cost_avx2.cc: the span steps;
// warp_cost_prep_avx2.cc: the reference lanes and the anchors): their constant tables and lane
// helpers; and the band tests of a run's spans, 8 at a time, which the span kernel inlines.
// Internal to those two files; x86-64 only.
#pragma once

#if defined(__x86_64__)
#include <immintrin.h>

#include <cstdint>

#include "algo/depth/data_term_kernels.h"
#include "algo/depth/warp_cost.h"

#define LB_AVX2 __attribute__((target("avx2")))

namespace lb::dtk::plane_avx2 {

inline constexpr int32_t kLanes = 8;

// Byte shuffles, per 32-bit lane: `pair` puts bytes 0 and 3 of a loaded RGBR / BRGB word in the
// two 16-bit halves (the same channel of two neighbouring pixels); `pair_g` does so for bytes 1
// and 2 (the green pair, after a blend of the two words). ref[c] picks channel c of pixels 0-3
// from the low half of 24 reference bytes loaded as bytes 0-15 and 8-23 (pixels 4-7 from the
// high half). nibble_bits: the bit count of each nibble.
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
inline constexpr Masks kMasks;

// Broadcast constants as tables, so the loop reads them as memory operands instead of rebuilding
// them in registers it has too few of.
struct Dup {
  alignas(32) int32_t v[8];
  constexpr explicit Dup(uint32_t x) : v() {
    for (int32_t& e : v) e = static_cast<int32_t>(x);
  }
};
struct Constants {
  Dup q8_half{128}, near{127}, one{256}, half{32768}, max_cost{255};
  Dup bytes15{0x0f0f0f0fu}, ones8{0x01010101u}, ones16{0x00010001u};
  // Pair indices per channel: bytes [c, zero, c + 3, zero] (added to 3 x - start in both
  // halves); census indices per plane: the byte in place, the others zero.
  Dup pair_idx[3] = {Dup{0x80038000u}, Dup{0x80048001u}, Dup{0x80058002u}};
  Dup census_idx[3] = {Dup{0x80008080u}, Dup{0x80800080u}, Dup{0x80808000u}};
};
inline constexpr Constants kC;

LB_AVX2 inline __m256i Load(const void* p) {
  return _mm256_load_si256(static_cast<const __m256i*>(p));
}

// 8 bytes of a plane, one per 32-bit lane.
LB_AVX2 inline __m256i Widen8(const uint8_t* p) {
  return _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)));
}

// The reference's census of pixels x..x+7, 24 bits a lane.
LB_AVX2 inline __m256i RefCensus(const WarpRow& r, int32_t x) {
  return _mm256_or_si256(_mm256_or_si256(_mm256_slli_epi32(Widen8(r.cref + x), 16),
                                         _mm256_slli_epi32(Widen8(r.cref + r.width + x), 8)),
                         Widen8(r.cref + 2 * r.width + x));
}

// Unsigned v <= max per lane (AVX2 compares only signed).
LB_AVX2 inline __m256i AtMost(__m256i v, __m256i max) {
  return _mm256_cmpeq_epi32(_mm256_min_epu32(v, max), v);
}

// What the run's band spans need, 8 spans at once (BandOf's tests, lane by lane): a span of
// kAnchorStep pixels (the row's short last span is not one), both anchors inside the view, its
// tap rows and census rows each within two neighbouring rows, and the positions advancing at
// most 9/8 px per pixel; not the row's last span when its end column is wanted, nor one the
// wanted columns cut (AnySpan steps only their wanted part). For each: its
// upper tap row and census row (and their offsets), its x and y change over the span (Q16), and
// kind bits (kInBand, kTwoRows, kTwoCensus, kRising).
enum : int32_t { kInBand = 1, kTwoRows = 2, kTwoCensus = 4, kRising = 8 };
struct RunBands {
  alignas(32) int32_t y[kRunSpans], cy[kRunSpans], dx[kRunSpans], dy[kRunSpans], kind[kRunSpans];
  alignas(32) int32_t row[kRunSpans], crow[kRunSpans];  // y * stride, cy * 3 * width
};

// Spans first .. end - 1 (end - first <= kRunSpans) into b, indexed from `first`. Lanes past
// `end` load nothing (masked loads: the anchors may end there). Inline: the span kernel's loop
// over a run's chunks keeps its constants.
LB_AVX2 inline void BandsOfRun(const WarpRow& r, const WarpRun& run, int32_t first, int32_t end,
                               RunBands* b) {
  const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i xmax = _mm256_set1_epi32((r.width - 1) * 256);
  const __m256i ymax = _mm256_set1_epi32((r.height - 1) * 256);
  const __m256i hm2 = _mm256_set1_epi32(r.height - 2);
  const __m256i q8_half = _mm256_set1_epi32(128), one = _mm256_set1_epi32(1);
  const __m256i reach = _mm256_set1_epi32(kAnchorStep * 73728);
  // The row's last span, when its end anchor's column is wanted too (a 17th), is not stepped
  // as one of the band, nor is a span the wanted columns lo..hi-1 cut.
  const __m256i last = _mm256_set1_epi32(run.hi > run.last ? run.last - 1 : run.last);
  const __m256i lo = _mm256_set1_epi32(run.lo), hi = _mm256_set1_epi32(run.hi);
  const __m256i stride = _mm256_set1_epi32(static_cast<int32_t>(r.stride));
  const __m256i census_row = _mm256_set1_epi32(3 * r.width);
  for (int32_t g = first; g < end; g += kLanes) {
    const __m256i lanes = _mm256_cmpgt_epi32(_mm256_set1_epi32(end - g), iota);
    const __m256i ax = _mm256_maskload_epi32(run.x_q16 + g, lanes);
    const __m256i bx = _mm256_maskload_epi32(run.x_q16 + g + 1, lanes);
    const __m256i ay = _mm256_maskload_epi32(run.y_q16 + g, lanes);
    const __m256i by = _mm256_maskload_epi32(run.y_q16 + g + 1, lanes);
    // The span's end column x0 + kAnchorStep (k + 1) must be an anchor: not past `last`.
    const __m256i span_end = _mm256_add_epi32(_mm256_set1_epi32(run.x0 + kAnchorStep * (g + 1)),
                                              _mm256_slli_epi32(iota, 4));  // kAnchorStep = 16
    __m256i bad =
        _mm256_or_si256(_mm256_cmpgt_epi32(span_end, last), _mm256_cmpgt_epi32(span_end, hi));
    bad = _mm256_or_si256(
        bad, _mm256_cmpgt_epi32(lo, _mm256_sub_epi32(span_end, _mm256_set1_epi32(kAnchorStep))));
    const __m256i dx = _mm256_sub_epi32(bx, ax), dy = _mm256_sub_epi32(by, ay);
    bad = _mm256_or_si256(bad, _mm256_cmpgt_epi32(_mm256_abs_epi32(dx), reach));
    const __m256i xa = _mm256_srai_epi32(_mm256_add_epi32(ax, q8_half), 8);
    const __m256i xb = _mm256_srai_epi32(_mm256_add_epi32(bx, q8_half), 8);
    const __m256i ya = _mm256_srai_epi32(_mm256_add_epi32(ay, q8_half), 8);
    const __m256i yb = _mm256_srai_epi32(_mm256_add_epi32(by, q8_half), 8);
    const __m256i inside = _mm256_and_si256(_mm256_and_si256(AtMost(xa, xmax), AtMost(xb, xmax)),
                                            _mm256_and_si256(AtMost(ya, ymax), AtMost(yb, ymax)));
    const __m256i row_a = _mm256_min_epi32(_mm256_srai_epi32(ya, 8), hm2);
    const __m256i row_b = _mm256_min_epi32(_mm256_srai_epi32(yb, 8), hm2);
    const __m256i near_a = _mm256_srai_epi32(_mm256_add_epi32(ya, q8_half), 8);
    const __m256i near_b = _mm256_srai_epi32(_mm256_add_epi32(yb, q8_half), 8);
    const __m256i row_d = _mm256_sub_epi32(row_a, row_b), near_d = _mm256_sub_epi32(near_a, near_b);
    bad = _mm256_or_si256(bad, _mm256_cmpgt_epi32(_mm256_abs_epi32(row_d), one));
    bad = _mm256_or_si256(bad, _mm256_cmpgt_epi32(_mm256_abs_epi32(near_d), one));
    const __m256i in_band = _mm256_andnot_si256(bad, _mm256_and_si256(inside, lanes));
    const __m256i zero = _mm256_setzero_si256();
    __m256i kind = _mm256_and_si256(in_band, _mm256_set1_epi32(kInBand));
    kind = _mm256_or_si256(
        kind, _mm256_andnot_si256(_mm256_cmpeq_epi32(row_d, zero), _mm256_set1_epi32(kTwoRows)));
    kind = _mm256_or_si256(
        kind, _mm256_andnot_si256(_mm256_cmpeq_epi32(near_d, zero), _mm256_set1_epi32(kTwoCensus)));
    kind = _mm256_or_si256(
        kind, _mm256_andnot_si256(_mm256_cmpgt_epi32(zero, dx), _mm256_set1_epi32(kRising)));
    const int32_t i = g - first;
    const __m256i y = _mm256_min_epi32(row_a, row_b), cy = _mm256_min_epi32(near_a, near_b);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(b->y + i), y);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(b->cy + i), cy);
    // Offsets of lanes in the band only (the view's bytes are below 2^31).
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(b->row + i),
                        _mm256_and_si256(in_band, _mm256_mullo_epi32(y, stride)));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(b->crow + i),
                        _mm256_and_si256(in_band, _mm256_mullo_epi32(cy, census_row)));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(b->dx + i), dx);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(b->dy + i), dy);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(b->kind + i), kind);
  }
}

}  // namespace lb::dtk::plane_avx2
#endif
