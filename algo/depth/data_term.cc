#include "algo/depth/data_term.h"

#if defined(__x86_64__)
#include <immintrin.h>
#define LB_AVX2 __attribute__((target("avx2")))
#elif defined(__ARM_NEON)
#include <arm_neon.h>
#endif

#include "algo/depth/warp_cost.h"

namespace lb {
namespace {

constexpr int32_t kMaxBest = 8;   // best half of up to 15 other views
constexpr int32_t kLumaPad = 2;   // the census reaches 2 pixels left and right
constexpr int32_t kLumaRows = 5;  // and 2 rows up and down

// Bit count by halving sums (no popcount instruction on baseline x86-64; vectorises).
inline uint32_t BitCount(uint32_t v) {
  v = v - ((v >> 1) & 0x55555555u);
  v = (v & 0x33333333u) + ((v >> 2) & 0x33333333u);
  v = (v + (v >> 4)) & 0x0f0f0f0fu;
  v = v + (v >> 8);  // shifts, not a multiply: SSE2 has no 32-bit vector multiply
  v = v + (v >> 16);
  return v & 0x3fu;
}

inline void Prefetch(const uint8_t* p, size_t bytes) {
  for (size_t i = 0; i < bytes; i += 64) __builtin_prefetch(p + i);
}

inline int32_t Clamp(int32_t v, int32_t lo, int32_t hi) { return v < lo ? lo : (v > hi ? hi : v); }

// BT.601 luma, Q8 weights summing to 256, rounded; stored +/-128 (xor 0x80) so signed byte
// compares order it; borders replicated into the padding.
void LumaRow(const uint8_t* rgb, int32_t w, uint8_t* out) {
  for (int32_t x = 0; x < w; ++x) {
    const int32_t l = (77 * rgb[3 * x] + 150 * rgb[3 * x + 1] + 29 * rgb[3 * x + 2] + 128) >> 8;
    out[x] = static_cast<uint8_t>(l ^ 0x80);
  }
  for (int32_t i = 1; i <= kLumaPad; ++i) {
    out[-i] = out[0];
    out[w - 1 + i] = out[w - 1];
  }
}

// ---- C reference kernels ----

// 5x5 census of pixels x0..x1-1 from 5 padded luma rows: bit set when the neighbour is darker
// than the centre; neighbours in raster order without the centre, 8 per output plane.
void CensusRowC(const uint8_t* const* rows, int32_t x0, int32_t x1, int32_t w, uint8_t* out) {
  for (int32_t x = x0; x < x1; ++x) {
    const int8_t c = static_cast<int8_t>(rows[2][x]);
    uint32_t bits = 0;
    for (int32_t dy = 0; dy < 5; ++dy) {
      for (int32_t dx = -2; dx <= 2; ++dx) {
        if (dy == 2 && dx == 0) continue;
        bits = (bits << 1) | (static_cast<int8_t>(rows[dy][x + dx]) < c ? 1u : 0u);
      }
    }
    out[x] = static_cast<uint8_t>(bits >> 16);
    out[w + x] = static_cast<uint8_t>(bits >> 8);
    out[2 * w + x] = static_cast<uint8_t>(bits);
  }
}

inline uint32_t CensusAt(const uint8_t* c, ptrdiff_t plane, int32_t x) {
  return (uint32_t{c[x]} << 16) | (uint32_t{c[plane + x]} << 8) | c[2 * plane + x];
}

// The per-pixel cost over n valid pixels: ref/img are RGB8 rows already aligned so that pixel
// i of ref pairs with samples i and i + 1 of img (weights 256 - f and f, Q8); cref/cimg are
// census planes `plane` bytes apart.
// Cloned for SSSE3/AVX2 on x86-64 (the fallback when the AVX2 kernel is off); the arithmetic is
// integer, so every clone gives the same bits.
#if defined(__x86_64__)
__attribute__((target_clones("avx2", "ssse3", "default")))
#endif
void CostRowC(const uint8_t* ref, const uint8_t* img, const uint8_t* cref, const uint8_t* cimg,
              ptrdiff_t plane, int32_t n, int32_t f, int32_t trunc, int32_t cw, uint8_t* out) {
  if (f == 0) {
    for (int32_t x = 0; x < n; ++x) {
      const int32_t dr = ref[3 * x] - img[3 * x];
      const int32_t dg = ref[3 * x + 1] - img[3 * x + 1];
      const int32_t db = ref[3 * x + 2] - img[3 * x + 2];
      int32_t ad = (dr < 0 ? -dr : dr) + (dg < 0 ? -dg : dg) + (db < 0 ? -db : db);
      ad = ad < trunc ? ad : trunc;
      const uint32_t bits = CensusAt(cref, plane, x) ^ CensusAt(cimg, plane, x);
      const int32_t cost = ad + static_cast<int32_t>(BitCount(bits)) * cw;
      out[x] = static_cast<uint8_t>(cost > 255 ? 255 : cost);
    }
    return;
  }
  // 16-bit lanes: s0 * g + s1 * f + 128 <= 65408, (h0 * g + h1 * f) * cw + 128 <= 61568.
  const uint16_t g16 = static_cast<uint16_t>(256 - f), f16 = static_cast<uint16_t>(f);
  const uint16_t cw16 = static_cast<uint16_t>(cw), trunc16 = static_cast<uint16_t>(trunc);
  for (int32_t x = 0; x < n; ++x) {
    // Linear interpolation in Q8, rounded half up: 0..255 per channel.
    const uint8_t* s = img + 3 * x;
    const uint16_t r =
        static_cast<uint16_t>(static_cast<uint16_t>(s[0] * g16 + s[3] * f16 + 128) >> 8);
    const uint16_t gg =
        static_cast<uint16_t>(static_cast<uint16_t>(s[1] * g16 + s[4] * f16 + 128) >> 8);
    const uint16_t b =
        static_cast<uint16_t>(static_cast<uint16_t>(s[2] * g16 + s[5] * f16 + 128) >> 8);
    const uint16_t r0 = ref[3 * x], g0 = ref[3 * x + 1], b0 = ref[3 * x + 2];
    uint16_t ad = static_cast<uint16_t>((r0 > r ? r0 - r : r - r0) + (g0 > gg ? g0 - gg : gg - g0) +
                                        (b0 > b ? b0 - b : b - b0));
    ad = ad < trunc16 ? ad : trunc16;
    // Hamming distances to the two samples, interpolated with the same weights (Q8 -> Q0).
    const uint32_t c = CensusAt(cref, plane, x);
    const uint16_t h0 = static_cast<uint16_t>(BitCount(c ^ CensusAt(cimg, plane, x)));
    const uint16_t h1 = static_cast<uint16_t>(BitCount(c ^ CensusAt(cimg, plane, x + 1)));
    const uint16_t ham = static_cast<uint16_t>(
        static_cast<uint16_t>(static_cast<uint16_t>(h0 * g16 + h1 * f16) * cw16 + 128) >> 8);
    const uint16_t cost = static_cast<uint16_t>(ad + ham);
    out[x] = static_cast<uint8_t>(cost > 255 ? 255 : cost);
  }
}

// Horizontal 3-sum (0..765) of a cost row whose pixels -1 and w replicate the borders.
void HSumRowC(const uint8_t* cost, int32_t x0, int32_t x1, uint16_t* hsum) {
  for (int32_t x = x0; x < x1; ++x) {
    hsum[x] = static_cast<uint16_t>(cost[x - 1] + cost[x] + cost[x + 1]);
  }
}

// Q15 reciprocal of `keep`: the mean of the kept sums, rounded (error < 1 for D <= 2295).
inline uint32_t RecipQ15(int32_t keep) {
  return (32768u + static_cast<uint32_t>(keep) / 2) / static_cast<uint32_t>(keep);
}

// Per pixel: window sums (3 ring rows per other view, <= 2295), the mean of the smallest
// (others + 1) / 2 of them. The kept sum is <= 8 * 2295, so 32-bit products are exact.
// Chunks of 16 pixels so that the sorted-list insertion (a min/max chain) vectorises.
void SelectRowC(const uint16_t* const* rows, int32_t others, int32_t x0, int32_t x1,
                uint16_t* out) {
  constexpr int32_t kChunk = 16;
  const int32_t keep = (others + 1) / 2;
  const uint32_t recip_q15 = RecipQ15(keep);
  for (int32_t xs = x0; xs < x1; xs += kChunk) {
    const int32_t n = x1 - xs < kChunk ? x1 - xs : kChunk;
    uint16_t best[kMaxBest][kChunk] = {};  // sorted, ascending
    for (int32_t i = 0; i < keep; ++i)
      for (int32_t l = 0; l < kChunk; ++l) best[i][l] = UINT16_MAX;
    for (int32_t j = 0; j < others; ++j) {
      uint16_t a[kChunk] = {};
      const uint16_t *r0 = rows[3 * j] + xs, *r1 = rows[3 * j + 1] + xs, *r2 = rows[3 * j + 2] + xs;
      for (int32_t l = 0; l < n; ++l) a[l] = static_cast<uint16_t>(r0[l] + r1[l] + r2[l]);
      for (int32_t i = 0; i < keep; ++i) {
        for (int32_t l = 0; l < kChunk; ++l) {
          const uint16_t lo = best[i][l] < a[l] ? best[i][l] : a[l];
          a[l] = best[i][l] < a[l] ? a[l] : best[i][l];
          best[i][l] = lo;
        }
      }
    }
    for (int32_t l = 0; l < n; ++l) {
      uint32_t sum = 0;
      for (int32_t i = 0; i < keep; ++i) sum += best[i][l];
      out[xs + l] = static_cast<uint16_t>((sum * recip_q15 + (1u << 14)) >> 15);
    }
  }
}

}  // namespace

struct DataTerm::Kernels {
  void (*census)(const uint8_t* const* rows, int32_t x0, int32_t x1, int32_t w, uint8_t* out);
  void (*cost)(const uint8_t* ref, const uint8_t* img, const uint8_t* cref, const uint8_t* cimg,
               ptrdiff_t plane, int32_t n, int32_t f, int32_t trunc, int32_t cw, uint8_t* out);
  void (*hsum)(const uint8_t* cost, int32_t x0, int32_t x1, uint16_t* hsum);
  void (*select)(const uint16_t* const* rows, int32_t others, int32_t x0, int32_t x1,
                 uint16_t* out);
};

namespace {

constexpr DataTerm::Kernels kReference = {CensusRowC, CostRowC, HSumRowC, SelectRowC};

#if defined(__x86_64__)
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
    for (int32_t dy = 0; dy < 5; ++dy) {
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

// Three census planes: cw * Hamming distance <= 240.
LB_AVX2 inline __m256i WeightedHamming(const uint8_t* a, const uint8_t* b, ptrdiff_t plane,
                                       __m256i lut) {
  __m256i h = WeightedBits(_mm256_xor_si256(Load(a), Load(b)), lut);
  h = _mm256_add_epi8(h, WeightedBits(_mm256_xor_si256(Load(a + plane), Load(b + plane)), lut));
  return _mm256_add_epi8(
      h, WeightedBits(_mm256_xor_si256(Load(a + 2 * plane), Load(b + 2 * plane)), lut));
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

// 32 pixels per step, all in bytes: the interpolated Hamming cost is Lerp of cw * h0 and cw * h1
// ((h0 * g + h1 * f) * cw = (cw h0) g + (cw h1) f exactly).
template <bool kFrac>
LB_AVX2 void CostRowAvx2T(const uint8_t* ref, const uint8_t* img, const uint8_t* cref,
                          const uint8_t* cimg, ptrdiff_t plane, int32_t n, int32_t f, int32_t trunc,
                          int32_t cw, uint8_t* out) {
  int8_t table[16];
  for (int32_t i = 0; i < 16; ++i) table[i] = static_cast<int8_t>(cw * __builtin_popcount(i));
  const __m256i lut =
      _mm256_broadcastsi128_si256(_mm_loadu_si128(reinterpret_cast<const __m128i*>(table)));
  const __m256i f128 = _mm256_set1_epi16(static_cast<int16_t>(f * 128));
  const __m256i trunc8 = _mm256_set1_epi8(static_cast<char>(trunc < 255 ? trunc : 255));
  if (n < 32) return CostRowC(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
  for (int32_t step = 0; step < n; step += 32) {
    const int32_t x = step + 32 <= n ? step : n - 32;
    const Rgb32 r = LoadRgb32(ref + 3 * x);
    const Rgb32 a = LoadRgb32(img + 3 * x);
    __m256i d[3];
    __m256i ham = WeightedHamming(cref + x, cimg + x, plane, lut);
    if (kFrac) {
      const Rgb32 b = LoadRgb32(img + 3 * x + 3);
      for (int32_t k = 0; k < 3; ++k) d[k] = AbsDiff(r.v[k], Lerp(a.v[k], b.v[k], f128));
      ham = Lerp(ham, WeightedHamming(cref + x, cimg + x + 1, plane, lut), f128);
    } else {
      for (int32_t k = 0; k < 3; ++k) d[k] = AbsDiff(r.v[k], a.v[k]);
    }
    const __m256i ad = _mm256_min_epu8(ChannelSum(d), trunc8);
    Store(out + x, _mm256_adds_epu8(ad, ham));
  }
}

LB_AVX2 void CostRowAvx2(const uint8_t* ref, const uint8_t* img, const uint8_t* cref,
                         const uint8_t* cimg, ptrdiff_t plane, int32_t n, int32_t f, int32_t trunc,
                         int32_t cw, uint8_t* out) {
  if (f == 0) {
    CostRowAvx2T<false>(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
  } else {
    CostRowAvx2T<true>(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
  }
}

LB_AVX2 inline __m256i Widen16(const uint8_t* p) {
  return _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
}

LB_AVX2 void HSumRowAvx2(const uint8_t* cost, int32_t x0, int32_t x1, uint16_t* hsum) {
  if (x1 - x0 < 16) return HSumRowC(cost, x0, x1, hsum);
  for (int32_t step = x0; step < x1; step += 16) {
    const int32_t x = step + 16 <= x1 ? step : x1 - 16;
    const __m256i s = _mm256_add_epi16(Widen16(cost + x - 1), Widen16(cost + x));
    Store(hsum + x, _mm256_add_epi16(s, Widen16(cost + x + 1)));
  }
}

// Signed 16-bit lanes (window sums <= 2295): a sorted list of the kKeep smallest in registers,
// one insertion (min/max chain) per view; kept sum <= 18360, then mulhrs by the Q15 reciprocal
// is (sum * recip + 2^14) >> 15, as in the reference.
LB_AVX2 inline __m256i Window(const uint16_t* const* rows, int32_t j, int32_t x) {
  return _mm256_add_epi16(_mm256_add_epi16(Load(rows[3 * j] + x), Load(rows[3 * j + 1] + x)),
                          Load(rows[3 * j + 2] + x));
}

template <int32_t kKeep>
LB_AVX2 void SelectRowAvx2T(const uint16_t* const* rows, int32_t others, int32_t x0, int32_t x1,
                            uint16_t* out) {
  const __m256i recip = _mm256_set1_epi16(static_cast<int16_t>(RecipQ15(kKeep)));
  if (x1 - x0 < 16) return SelectRowC(rows, others, x0, x1, out);
  for (int32_t step = x0; step < x1; step += 16) {
    const int32_t x = step + 16 <= x1 ? step : x1 - 16;
    __m256i best[kKeep];
    for (int32_t j = 0; j < kKeep; ++j) {
      __m256i a = Window(rows, j, x);
      for (int32_t i = 0; i < j; ++i) {
        const __m256i lo = _mm256_min_epi16(best[i], a);
        a = _mm256_max_epi16(best[i], a);
        best[i] = lo;
      }
      best[j] = a;
    }
    for (int32_t j = kKeep; j < others; ++j) {
      __m256i a = Window(rows, j, x);
      for (int32_t i = 0; i < kKeep - 1; ++i) {
        const __m256i lo = _mm256_min_epi16(best[i], a);
        a = _mm256_max_epi16(best[i], a);
        best[i] = lo;
      }
      best[kKeep - 1] = _mm256_min_epi16(best[kKeep - 1], a);
    }
    __m256i sum = best[0];
    for (int32_t i = 1; i < kKeep; ++i) sum = _mm256_add_epi16(sum, best[i]);
    Store(out + x, kKeep == 1 ? sum : _mm256_mulhrs_epi16(sum, recip));
  }
}

LB_AVX2 void SelectRowAvx2(const uint16_t* const* rows, int32_t others, int32_t x0, int32_t x1,
                           uint16_t* out) {
  switch ((others + 1) / 2) {
    case 1:
      return SelectRowAvx2T<1>(rows, others, x0, x1, out);
    case 2:
      return SelectRowAvx2T<2>(rows, others, x0, x1, out);
    case 3:
      return SelectRowAvx2T<3>(rows, others, x0, x1, out);
    case 4:
      return SelectRowAvx2T<4>(rows, others, x0, x1, out);
    case 5:
      return SelectRowAvx2T<5>(rows, others, x0, x1, out);
    case 6:
      return SelectRowAvx2T<6>(rows, others, x0, x1, out);
    case 7:
      return SelectRowAvx2T<7>(rows, others, x0, x1, out);
    default:
      return SelectRowAvx2T<8>(rows, others, x0, x1, out);
  }
}

constexpr DataTerm::Kernels kSimd = {CensusRowAvx2, CostRowAvx2, HSumRowAvx2, SelectRowAvx2};

bool SimdAvailable() { return __builtin_cpu_supports("avx2"); }
#elif defined(__ARM_NEON)
// ---- NEON kernels (aarch64; armhf when built with NEON), 16 pixels a step, the last step
// overlapping the one before (the same bytes again); ARMv7 intrinsics only ----

void CensusRowNeon(const uint8_t* const* rows, int32_t x0, int32_t x1, int32_t w, uint8_t* out) {
  if (x1 - x0 < 16) return CensusRowC(rows, x0, x1, w, out);
  for (int32_t step = x0; step < x1; step += 16) {
    const int32_t x = step + 16 <= x1 ? step : x1 - 16;
    const int8x16_t c = vreinterpretq_s8_u8(vld1q_u8(rows[2] + x));
    uint8x16_t plane = vdupq_n_u8(0);
    int32_t bit = 0;
    for (int32_t dy = 0; dy < 5; ++dy) {
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

// vld3 de-interleaves the colours; channel sums saturate at 255 as in the AVX2 kernel.
template <bool kFrac>
void CostRowNeonT(const uint8_t* ref, const uint8_t* img, const uint8_t* cref, const uint8_t* cimg,
                  ptrdiff_t plane, int32_t n, int32_t f, int32_t trunc, int32_t cw, uint8_t* out) {
  if (n < 16) return CostRowC(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
  const uint8x8_t g8 = vdup_n_u8(static_cast<uint8_t>(kFrac ? 256 - f : 0));
  const uint8x8_t f8 = vdup_n_u8(static_cast<uint8_t>(f));
  const uint16_t cw16 = static_cast<uint16_t>(cw);
  const uint8x16_t trunc8 = vdupq_n_u8(static_cast<uint8_t>(trunc < 255 ? trunc : 255));
  for (int32_t step = 0; step < n; step += 16) {
    const int32_t x = step + 16 <= n ? step : n - 16;
    const uint8x16x3_t r = vld3q_u8(ref + 3 * x);
    const uint8x16x3_t a = vld3q_u8(img + 3 * x);
    const uint8x16_t h0 = Hamming(cref + x, cimg + x, plane);
    uint8x16_t sum = vdupq_n_u8(0), ham;
    if (kFrac) {
      const uint8x16x3_t b = vld3q_u8(img + 3 * x + 3);
      for (int32_t c = 0; c < 3; ++c) {
        sum = vqaddq_u8(sum, vabdq_u8(r.val[c], Lerp(a.val[c], b.val[c], g8, f8)));
      }
      // ((h0 * g + h1 * f) * cw + 128) >> 8, <= 61568 before the shift.
      const uint8x16_t h1 = Hamming(cref + x, cimg + x + 1, plane);
      const uint16x8_t lo = vmulq_n_u16(Mix(vget_low_u8(h0), vget_low_u8(h1), g8, f8), cw16);
      const uint16x8_t hi = vmulq_n_u16(Mix(vget_high_u8(h0), vget_high_u8(h1), g8, f8), cw16);
      ham = vcombine_u8(vrshrn_n_u16(lo, 8), vrshrn_n_u16(hi, 8));
    } else {
      for (int32_t c = 0; c < 3; ++c) sum = vqaddq_u8(sum, vabdq_u8(r.val[c], a.val[c]));
      ham = vmulq_u8(h0, vdupq_n_u8(static_cast<uint8_t>(cw)));  // <= 240
    }
    vst1q_u8(out + x, vqaddq_u8(vminq_u8(sum, trunc8), ham));
  }
}

void CostRowNeon(const uint8_t* ref, const uint8_t* img, const uint8_t* cref, const uint8_t* cimg,
                 ptrdiff_t plane, int32_t n, int32_t f, int32_t trunc, int32_t cw, uint8_t* out) {
  if (f == 0) {
    CostRowNeonT<false>(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
  } else {
    CostRowNeonT<true>(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
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

inline int16x8_t Window(const uint16_t* const* rows, int32_t j, int32_t x) {
  return vreinterpretq_s16_u16(
      vaddq_u16(vaddq_u16(vld1q_u16(rows[3 * j] + x), vld1q_u16(rows[3 * j + 1] + x)),
                vld1q_u16(rows[3 * j + 2] + x)));
}

// As the AVX2 kernel; vqrdmulh is (2 * sum * recip + 2^15) >> 16 = (sum * recip + 2^14) >> 15.
template <int32_t kKeep>
void SelectRowNeonT(const uint16_t* const* rows, int32_t others, int32_t x0, int32_t x1,
                    uint16_t* out) {
  if (x1 - x0 < 8) return SelectRowC(rows, others, x0, x1, out);
  const int16x8_t recip = vdupq_n_s16(static_cast<int16_t>(kKeep == 1 ? 0 : RecipQ15(kKeep)));
  for (int32_t step = x0; step < x1; step += 8) {
    const int32_t x = step + 8 <= x1 ? step : x1 - 8;
    int16x8_t best[kKeep];
    for (int32_t j = 0; j < kKeep; ++j) {
      int16x8_t a = Window(rows, j, x);
      for (int32_t i = 0; i < j; ++i) {
        const int16x8_t lo = vminq_s16(best[i], a);
        a = vmaxq_s16(best[i], a);
        best[i] = lo;
      }
      best[j] = a;
    }
    for (int32_t j = kKeep; j < others; ++j) {
      int16x8_t a = Window(rows, j, x);
      for (int32_t i = 0; i < kKeep - 1; ++i) {
        const int16x8_t lo = vminq_s16(best[i], a);
        a = vmaxq_s16(best[i], a);
        best[i] = lo;
      }
      best[kKeep - 1] = vminq_s16(best[kKeep - 1], a);
    }
    int16x8_t sum = best[0];
    for (int32_t i = 1; i < kKeep; ++i) sum = vaddq_s16(sum, best[i]);
    vst1q_u16(out + x, vreinterpretq_u16_s16(kKeep == 1 ? sum : vqrdmulhq_s16(sum, recip)));
  }
}

void SelectRowNeon(const uint16_t* const* rows, int32_t others, int32_t x0, int32_t x1,
                   uint16_t* out) {
  switch ((others + 1) / 2) {
    case 1:
      return SelectRowNeonT<1>(rows, others, x0, x1, out);
    case 2:
      return SelectRowNeonT<2>(rows, others, x0, x1, out);
    case 3:
      return SelectRowNeonT<3>(rows, others, x0, x1, out);
    case 4:
      return SelectRowNeonT<4>(rows, others, x0, x1, out);
    case 5:
      return SelectRowNeonT<5>(rows, others, x0, x1, out);
    case 6:
      return SelectRowNeonT<6>(rows, others, x0, x1, out);
    case 7:
      return SelectRowNeonT<7>(rows, others, x0, x1, out);
    default:
      return SelectRowNeonT<8>(rows, others, x0, x1, out);
  }
}

constexpr DataTerm::Kernels kSimd = {CensusRowNeon, CostRowNeon, HSumRowNeon, SelectRowNeon};

bool SimdAvailable() { return true; }
#else
constexpr DataTerm::Kernels kSimd = kReference;
bool SimdAvailable() { return false; }
#endif

}  // namespace

bool DataTerm::UseSimd(bool on) {
  const bool simd = on && SimdAvailable();
  kernels_ = simd ? &kSimd : &kReference;
  return simd;
}

void DataTerm::Carve(Arena& arena, int32_t width, int32_t height, int32_t views) {
  width_ = width;
  height_ = height;
  views_ = views;
  const size_t n = static_cast<size_t>(width) * height;
  for (int32_t v = 0; v < views; ++v) census_[v] = arena.Allocate<uint8_t>(3 * n);
  luma_ = arena.Allocate<uint8_t>(static_cast<size_t>(width + 2 * kLumaPad) * kLumaRows);
  pixel_ = arena.Allocate<uint8_t>(static_cast<size_t>(width) + 2);
  hsum_ = arena.Allocate<uint16_t>(static_cast<size_t>(width) * 3 * (views - 1));
  UseSimd(true);
}

void DataTerm::SetParams(const DataTermParams& params, int32_t reference) {
  params_ = params;
  reference_ = reference;
  const int32_t c = params.color_trunc + kCensusBits * params.census_weight;
  invalid_cost_ = c > 255 ? 255 : c;
}

void DataTerm::Prepare(const ConstImageU8* views) {
  images_ = views;
  const int32_t w = width_, h = height_;
  const ptrdiff_t pitch = w + 2 * kLumaPad;
  // Luma row r lives in ring slot r % 5 (the census needs rows y - 2 .. y + 2, clamped).
  auto slot = [&](int32_t r) { return luma_ + (r % kLumaRows) * pitch + kLumaPad; };
  for (int32_t v = 0; v < views_; ++v) {
    for (int32_t r = 0; r < 2 && r < h; ++r) LumaRow(views[v].Row(r), w, slot(r));
    for (int32_t y = 0; y < h; ++y) {
      if (y + 2 < h) LumaRow(views[v].Row(y + 2), w, slot(y + 2));
      const uint8_t* rows[kLumaRows];
      for (int32_t k = 0; k < kLumaRows; ++k) rows[k] = slot(Clamp(y + k - 2, 0, h - 1));
      kernels_->census(rows, 0, w, w, census_[v] + static_cast<ptrdiff_t>(y) * 3 * w);
    }
  }
}

void DataTerm::PixelCostRow(int32_t view, int32_t y, int32_t disp_q8, uint8_t* out) const {
  const int32_t w = width_;
  if (planes_ != nullptr) {
    const WarpSource src{images_[reference_], images_[view], census_[reference_], census_[view]};
    PlaneCostRow(planes_[view], src, y, params_, invalid_cost_, out);
    return;
  }
  // Sample position in the view: x * 256 + shift_q8, the same fraction for every pixel.
  const int32_t shift_q8 = -(view - reference_) * disp_q8;
  const int32_t off = shift_q8 >> 8;  // floor
  const int32_t f = shift_q8 & 255;   // Q8 weight of the right-hand sample
  const int32_t x_lo = Clamp(-off, 0, w);
  const int32_t x_hi = Clamp(w - (f > 0 ? 1 : 0) - off, x_lo, w);
  const uint8_t invalid = static_cast<uint8_t>(invalid_cost_);
  for (int32_t x = 0; x < x_lo; ++x) out[x] = invalid;
  for (int32_t x = x_hi; x < w; ++x) out[x] = invalid;
  if (x_hi <= x_lo) return;
  const ptrdiff_t row = static_cast<ptrdiff_t>(y) * 3 * w;
  kernels_->cost(images_[reference_].Row(y) + 3 * x_lo, images_[view].Row(y) + 3 * (x_lo + off),
                 census_[reference_] + row + x_lo, census_[view] + row + x_lo + off, w, x_hi - x_lo,
                 f, params_.color_trunc, params_.census_weight, out + x_lo);
}

// Horizontal 3-sum of the pixel costs of row y (borders replicated): 0..765.
void DataTerm::WindowRow(int32_t view, int32_t y, int32_t disp_q8, uint16_t* hsum) {
  const int32_t w = width_;
  uint8_t* cost = pixel_ + 1;
  PixelCostRow(view, Clamp(y, 0, height_ - 1), disp_q8, cost);
  cost[-1] = cost[0];
  cost[w] = cost[w - 1];
  kernels_->hsum(cost, 0, w, hsum);
}

void DataTerm::ComputeRows(int32_t disp_q8, int32_t y0, int32_t y1, uint16_t* out,
                           ptrdiff_t stride) {
  const int32_t w = width_;
  const int32_t others = views_ - 1;
  auto ring = [&](int32_t j, int32_t row) {
    return hsum_ + (static_cast<size_t>(j) * 3 + static_cast<size_t>((row - y0 + 1) % 3)) * w;
  };
  auto view = [&](int32_t j) { return j < reference_ ? j : j + 1; };
  for (int32_t j = 0; j < others; ++j) {
    WindowRow(view(j), y0 - 1, disp_q8, ring(j, y0 - 1));
    WindowRow(view(j), y0, disp_q8, ring(j, y0));
  }
  const uint16_t* rows[3 * 15];
  const size_t row_bytes = static_cast<size_t>(3) * w;
  for (int32_t y = y0; y < y1; ++y) {
    for (int32_t j = 0; j < others; ++j) {
      WindowRow(view(j), y + 1, disp_q8, ring(j, y + 1));
      // The views' next rows are far apart (a whole view each), so the hardware prefetcher
      // misses their starts; asking early hides the cache misses behind the other views.
      const int32_t next = Clamp(y + 2, 0, height_ - 1);
      Prefetch(images_[view(j)].Row(next), row_bytes);
      Prefetch(census_[view(j)] + static_cast<ptrdiff_t>(next) * 3 * w, row_bytes);
      for (int32_t k = 0; k < 3; ++k) rows[3 * j + k] = ring(j, y - 1 + k);
    }
    kernels_->select(rows, others, 0, w, out + (y - y0) * stride);
  }
}

}  // namespace lb
