// What the plane sweep's AVX2 kernels share (warp_cost_avx2.cc: the span steps;
// warp_cost_prep_avx2.cc: the band tests, the reference lanes and the anchors): their constant
// tables, lane helpers and the band tests' record. Internal to those two files; x86-64 only.
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

// Spans first .. end - 1 (end - first <= kRunSpans) into b, indexed from `first`
// (warp_cost_prep_avx2.cc).
LB_AVX2 void BandsOfRun(const WarpRow& r, const WarpRun& run, int32_t first, int32_t end,
                        RunBands* b);

}  // namespace lb::dtk::plane_avx2
#endif
