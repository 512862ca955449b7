// The plane sweep's span kernel for AVX2 (warp_cost.h; the C reference is dtk::PlaneSpansC in
// warp_cost.cc): a run of spans a call, 8 pixels a step in 32-bit lanes. The run's spans are
// tested 8 at a time (BandsOfRun): those inside the view whose taps stay in one band of rows
// (most: the positions advance about one pixel per pixel) are stepped straight from their
// anchors, two steps each, inlined in the run's loop; each step reads each colour channel's tap
// pairs from one 16-byte window per 128-bit half and row, picked by one byte shuffle, the census
// taps from 16-byte windows of the census planes, and the reference pixels from 32-bit lanes
// prepared once per row (RefLanes: by the data term for every view, else here per run). Other
// spans go one by one (AnySpan): their steps take their taps from byte shuffles of 32-byte
// windows of the two rows when they share them, else from scalar loads (AVX2 gathers are slower
// than those on some cores). Views narrower than a step or too large for 32-bit offsets, and
// census weights over 31, take the reference. Also the anchors' exact divisions, four at a time
// (PlaneAnchorsAvx2; the C reference is dtk::PlaneAnchorsC).
#include "algo/depth/data_term_kernels.h"

#if defined(__x86_64__)
#include <immintrin.h>

#include <cstring>

#include "algo/core/int_math.h"
#define LB_AVX2 __attribute__((target("avx2")))

namespace lb::dtk {
namespace {

constexpr int32_t kLanes = 8;

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
constexpr Masks kMasks;

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
constexpr Constants kC;

LB_AVX2 inline __m256i Load(const void* p) {
  return _mm256_load_si256(static_cast<const __m256i*>(p));
}

// Dwords 0 and 2 (bits 0-31 and 16-47, or with shift 16 bits 16-47 and 32-63) of 8 quadwords,
// in order.
LB_AVX2 inline void Dwords(const uint64_t* q, int32_t shift, __m256i* d0, __m256i* d2) {
  const __m256i lo = _mm256_srli_epi64(Load(q), shift), hi = _mm256_srli_epi64(Load(q + 4), shift);
  const __m256i lo2 = _mm256_srli_epi64(lo, 16), hi2 = _mm256_srli_epi64(hi, 16);
  *d0 = _mm256_permute4x64_epi64(
      _mm256_castps_si256(_mm256_shuffle_ps(_mm256_castsi256_ps(lo), _mm256_castsi256_ps(hi),
                                            _MM_SHUFFLE(2, 0, 2, 0))),
      _MM_SHUFFLE(3, 1, 2, 0));
  *d2 = _mm256_permute4x64_epi64(
      _mm256_castps_si256(_mm256_shuffle_ps(_mm256_castsi256_ps(lo2), _mm256_castsi256_ps(hi2),
                                            _MM_SHUFFLE(2, 0, 2, 0))),
      _MM_SHUFFLE(3, 1, 2, 0));
}

// 8 bytes of a plane, one per 32-bit lane.
LB_AVX2 inline __m256i Widen8(const uint8_t* p) {
  return _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)));
}

// The taps of 8 pixels: per row and channel c, dwords [a_c 0 b_c 0] (the channel of the pair's
// left and right pixels as 16-bit halves, for one multiply-add by [256 - fx, fx]), and the
// nearest tap's census, 24 bits.
struct Taps {
  __m256i top[3], bottom[3], census;
};

// The pairs from dwords loaded as ab0 = [aR aG aB bR] and ab2 = [aB bR bG bB].
LB_AVX2 inline void Pairs(__m256i ab0, __m256i ab2, __m256i* pairs) {
  const __m256i pair = Load(kMasks.pair);
  pairs[0] = _mm256_shuffle_epi8(ab0, pair);
  pairs[1] = _mm256_shuffle_epi8(_mm256_blend_epi16(ab0, ab2, 0xaa), Load(kMasks.pair_g));
  pairs[2] = _mm256_shuffle_epi8(ab2, pair);
}

// Format of each step (per lane, as dtk::PlaneSpansC): positions Q16 (|.| < 2^30), rounded to Q8
// and clamped to the view so every load stays inside it (lanes outside take `invalid` at the
// end). The tap pair's left column is at most width - 2 with a weight of up to 256 on the right
// one (and likewise for rows): (w-1, f 0) becomes (w-2, f 256), the same sum. Colour:
// top * (256 - fy) + bottom * fy = 256 top + (bottom - top) fy <= 255 * 65536 (int32), rounded
// half up to Q0. Census: the nearest tap's 24 bits against the reference's, counted by nibble
// lookups of weight * bits (<= 31 * 4 per nibble, <= 248 per byte), summed in 16 then 32 bits.
// Cost min(min(|dRGB|, trunc) + weighted bits, 255).
// c and m point at kC and kMasks through an opaque copy (Laundered), so the compiler reads
// the broadcast constants as memory operands instead of rebuilding each from an immediate in
// every step (three instructions each).
struct Consts {
  __m256i xmax, ymax, wm2, hm2, stride, census_row, trunc, invalid, lut, last_window;
  const Constants* c;
  const Masks* m;
};

template <typename T>
inline const T* Laundered(const T* p) {
  asm("" : "+r"(p));
  return p;
}

// Scalar loads: 8 bytes per tap row, the top one read forward (its 2 extra bytes lie in the row
// below) and the bottom one from 2 bytes back (in the row above), so every read stays inside the
// view.
LB_AVX2 void ScalarTaps(const WarpRow& r, const Consts& k, __m256i xb, __m256i yb, __m256i nx,
                        __m256i ny, Taps* t) {
  alignas(32) int32_t tap[kLanes], near[kLanes];
  _mm256_store_si256(reinterpret_cast<__m256i*>(tap),
                     _mm256_add_epi32(_mm256_mullo_epi32(yb, k.stride),
                                      _mm256_add_epi32(xb, _mm256_add_epi32(xb, xb))));
  _mm256_store_si256(reinterpret_cast<__m256i*>(near),
                     _mm256_add_epi32(_mm256_mullo_epi32(ny, k.census_row), nx));
  alignas(32) uint64_t top8[kLanes], bottom8[kLanes];
  alignas(32) uint32_t census[kLanes];
  const ptrdiff_t below = r.stride - 2;
  for (int32_t j = 0; j < kLanes; ++j) {
    const uint8_t* p = r.view + tap[j];
    std::memcpy(&top8[j], p, 8);
    std::memcpy(&bottom8[j], p + below, 8);
    const uint8_t* c = r.census_view + near[j];
    census[j] = (uint32_t{c[0]} << 16) | (uint32_t{c[r.width]} << 8) | c[2 * r.width];
  }
  __m256i d0, d2;
  Dwords(top8, 0, &d0, &d2);
  Pairs(d0, d2, t->top);
  Dwords(bottom8, 16, &d0, &d2);
  Pairs(d0, d2, t->bottom);
  t->census = Load(census);
}

// Bytes idx (0..31; bit 7 set: zero) of the 32-byte table lo:hi.
LB_AVX2 inline __m256i Lookup32(__m256i lo, __m256i hi, __m256i idx) {
  const __m256i upper = _mm256_cmpgt_epi8(idx, Load(kC.bytes15.v));
  return _mm256_blendv_epi8(_mm256_shuffle_epi8(lo, idx), _mm256_shuffle_epi8(hi, idx), upper);
}

LB_AVX2 inline __m256i Broadcast16(const uint8_t* p) {
  return _mm256_broadcastsi128_si256(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
}

// The taps from windows: `row` is the top tap row and `crow` the census row of every lane, x_min
// the smallest pair column, the pairs within 8 columns of it (so within 32 bytes: 3 * 8 + 5).
// Windows start early enough not to leave their row (width >= 16): the last pair ends at byte
// 3 (w - 2) + 5 < 3 w, the last census tap within 15 of w - 16.
LB_AVX2 inline __attribute__((always_inline)) void WindowTaps(const WarpRow& r, const uint8_t* row,
                                                              const uint8_t* crow, int32_t x_min,
                                                              __m256i xb, __m256i nx, Taps* t) {
  const int32_t start = Min(3 * x_min, 3 * r.width - 32);
  const __m256i d =
      _mm256_sub_epi32(_mm256_add_epi32(xb, _mm256_add_epi32(xb, xb)), _mm256_set1_epi32(start));
  const __m256i d2 = _mm256_or_si256(d, _mm256_slli_epi32(d, 16));
  const uint8_t* top = row + start;
  const __m256i top_lo = Broadcast16(top), top_hi = Broadcast16(top + 16);
  const __m256i bottom_lo = Broadcast16(top + r.stride);
  const __m256i bottom_hi = Broadcast16(top + r.stride + 16);
  for (int32_t c = 0; c < 3; ++c) {
    // Bytes [d + c, zero, d + c + 3, zero].
    const __m256i idx = _mm256_add_epi32(d2, Load(kC.pair_idx[c].v));
    t->top[c] = Lookup32(top_lo, top_hi, idx);
    t->bottom[c] = Lookup32(bottom_lo, bottom_hi, idx);
  }
  const int32_t cstart = Min(x_min, r.width - 16);
  const __m256i e = _mm256_sub_epi32(nx, _mm256_set1_epi32(cstart));
  __m256i bits = _mm256_setzero_si256();
  for (int32_t p = 0; p < 3; ++p) {
    const int32_t shift = 8 * (2 - p);  // plane 0 holds the top byte
    const __m256i idx = _mm256_or_si256(_mm256_slli_epi32(e, shift), Load(kC.census_idx[p].v));
    bits =
        _mm256_or_si256(bits, _mm256_shuffle_epi8(Broadcast16(crow + p * r.width + cstart), idx));
  }
  t->census = bits;
}

// The costs of pixels x..x+7 from their truncated colour differences ad and their census taps.
// The reference's census of pixels x..x+7, 24 bits a lane.
LB_AVX2 inline __m256i RefCensus(const WarpRow& r, int32_t x) {
  return _mm256_or_si256(_mm256_or_si256(_mm256_slli_epi32(Widen8(r.cref + x), 16),
                                         _mm256_slli_epi32(Widen8(r.cref + r.width + x), 8)),
                         Widen8(r.cref + 2 * r.width + x));
}

LB_AVX2 inline __attribute__((always_inline)) __m256i CostFromTaps(const Consts& k, __m256i ad,
                                                                   __m256i census,
                                                                   __m256i ref_bits) {
  const __m256i bits = _mm256_xor_si256(census, ref_bits);
  const __m256i nib = Load(k.c->bytes15.v);
  const __m256i count8 = _mm256_add_epi8(
      _mm256_shuffle_epi8(k.lut, _mm256_and_si256(bits, nib)),
      _mm256_shuffle_epi8(k.lut, _mm256_and_si256(_mm256_srli_epi16(bits, 4), nib)));
  const __m256i ham =
      _mm256_madd_epi16(_mm256_maddubs_epi16(count8, Load(k.c->ones8.v)), Load(k.c->ones16.v));
  return _mm256_min_epi32(_mm256_add_epi32(ad, ham), Load(k.c->max_cost.v));
}

// The costs of pixels x..x+7 from their taps, weights [256 - fx, fx] and row fractions fy.
LB_AVX2 inline __attribute__((always_inline)) __m256i Cost(const WarpRow& r, const Consts& k,
                                                           int32_t x, const Taps& t, __m256i wx,
                                                           __m256i fy) {
  const __m128i ref_lo = _mm_loadu_si128(reinterpret_cast<const __m128i*>(r.ref + 3 * x));
  const __m128i ref_hi = _mm_loadu_si128(reinterpret_cast<const __m128i*>(r.ref + 3 * x + 8));
  const __m256i ref = _mm256_inserti128_si256(_mm256_castsi128_si256(ref_lo), ref_hi, 1);
  __m256i ad = _mm256_setzero_si256();
  for (int32_t c = 0; c < 3; ++c) {
    const __m256i top = _mm256_madd_epi16(t.top[c], wx);
    const __m256i bottom = _mm256_madd_epi16(t.bottom[c], wx);
    const __m256i s = _mm256_add_epi32(_mm256_slli_epi32(top, 8),
                                       _mm256_mullo_epi32(_mm256_sub_epi32(bottom, top), fy));
    const __m256i v = _mm256_srai_epi32(_mm256_add_epi32(s, Load(k.c->half.v)), 16);
    const __m256i rc = _mm256_shuffle_epi8(ref, Load(k.m->ref[c]));
    ad = _mm256_add_epi32(ad, _mm256_abs_epi32(_mm256_sub_epi32(rc, v)));
  }
  return CostFromTaps(k, _mm256_min_epi32(ad, k.trunc), t.census, RefCensus(r, x));
}

// 8 costs 0..255: two packs leave pixels 0-3 in dword 0 and 4-7 in dword 4, joined for one store.
LB_AVX2 inline void Store8(uint8_t* out, __m256i cost) {
  const __m256i packed =
      _mm256_packus_epi16(_mm256_packus_epi32(cost, cost), _mm256_setzero_si256());
  const __m128i both =
      _mm_unpacklo_epi32(_mm256_castsi256_si128(packed), _mm256_extracti128_si256(packed, 1));
  _mm_storel_epi64(reinterpret_cast<__m128i*>(out), both);
}

// Any step: lanes may leave the view, or need taps from different rows. The costs of pixels
// x..x+7 go to dst[0..7].
LB_AVX2 void Step(const WarpRow& r, const Consts& k, int32_t x, __m256i xq, __m256i yq,
                  uint8_t* dst) {
  const __m256i zero = _mm256_setzero_si256();
  const __m256i xs = _mm256_srai_epi32(_mm256_add_epi32(xq, Load(k.c->q8_half.v)), 8);
  const __m256i ys = _mm256_srai_epi32(_mm256_add_epi32(yq, Load(k.c->q8_half.v)), 8);
  const __m256i bad = _mm256_or_si256(
      _mm256_or_si256(_mm256_cmpgt_epi32(zero, xs), _mm256_cmpgt_epi32(xs, k.xmax)),
      _mm256_or_si256(_mm256_cmpgt_epi32(zero, ys), _mm256_cmpgt_epi32(ys, k.ymax)));
  const __m256i xc = _mm256_min_epi32(_mm256_max_epi32(xs, zero), k.xmax);
  const __m256i yc = _mm256_min_epi32(_mm256_max_epi32(ys, zero), k.ymax);
  const __m256i xb = _mm256_min_epi32(_mm256_srai_epi32(xc, 8), k.wm2);
  const __m256i yb = _mm256_min_epi32(_mm256_srai_epi32(yc, 8), k.hm2);
  const __m256i fx = _mm256_sub_epi32(xc, _mm256_slli_epi32(xb, 8));
  const __m256i fy = _mm256_sub_epi32(yc, _mm256_slli_epi32(yb, 8));
  // The nearest tap: the right (lower) one from a fraction of 128 on.
  const __m256i c127 = Load(k.c->near.v);
  const __m256i nx = _mm256_sub_epi32(xb, _mm256_cmpgt_epi32(fx, c127));
  const __m256i ny = _mm256_sub_epi32(yb, _mm256_cmpgt_epi32(fy, c127));
  // The positions are monotone along a step (WarpSpan's lie between its anchors), so the first
  // and last lanes bound the rest. Taps from two pairs of rows (or census rows) come from the
  // windows of both, chosen per lane.
  const int32_t y = _mm256_cvtsi256_si32(yb), cy = _mm256_cvtsi256_si32(ny);
  const int32_t y7 = _mm256_extract_epi32(yb, 7), cy7 = _mm256_extract_epi32(ny, 7);
  const int32_t x0 = _mm256_cvtsi256_si32(xb), x7 = _mm256_extract_epi32(xb, 7);
  Taps t;
  if (r.width >= 16 && x7 - x0 <= 8 && x0 - x7 <= 8 && y7 - y <= 1 && y - y7 <= 1 &&
      cy7 - cy <= 1 && cy - cy7 <= 1) {
    const ptrdiff_t census_row = static_cast<ptrdiff_t>(3) * r.width;
    WindowTaps(r, r.view + y * r.stride, r.census_view + cy * census_row, Min(x0, x7), xb, nx, &t);
    if (y7 != y || cy7 != cy) {
      Taps u;
      WindowTaps(r, r.view + y7 * r.stride, r.census_view + cy7 * census_row, Min(x0, x7), xb, nx,
                 &u);
      const __m256i second = _mm256_cmpeq_epi32(yb, _mm256_set1_epi32(y7));
      for (int32_t c = 0; c < 3; ++c) {
        t.top[c] = _mm256_blendv_epi8(t.top[c], u.top[c], second);
        t.bottom[c] = _mm256_blendv_epi8(t.bottom[c], u.bottom[c], second);
      }
      t.census =
          _mm256_blendv_epi8(t.census, u.census, _mm256_cmpeq_epi32(ny, _mm256_set1_epi32(cy7)));
    }
  } else {
    ScalarTaps(r, k, xb, yb, nx, ny, &t);
  }
  const __m256i wx =
      _mm256_add_epi32(_mm256_sub_epi32(Load(k.c->one.v), fx), _mm256_slli_epi32(fx, 16));
  Store8(dst, _mm256_blendv_epi8(Cost(r, k, x, t, wx, fy), k.invalid, bad));
}

// A span whose every tap lies inside the view, its tap rows in one pair of rows or two
// neighbouring ones (its census rows likewise), and whose positions advance at most 9/8 px per
// pixel, so that any 8 consecutive pixels' pairs lie within 8 columns (7 * 9/8 + 2/256 < 8):
// checked once at its anchors, since its positions lie between them and each test is monotone
// along it.
struct Band {
  const uint8_t* row;   // the upper top tap row
  const uint8_t* crow;  // the upper census row
  int32_t y, cy;        // their indices
  bool two_rows;        // some pixels' tap rows are one lower
  bool two_census;      // some pixels' census rows are one lower
  bool rising;          // positions rise along the span: a step's first lane has its least column
  ptrdiff_t lanes_stride;  // the reference lanes' (WarpRow::ref_lanes)
};

// The caller checks r.width >= 16 once. Positions |.| < 2^30, so differences fit 32 bits; a
// Q8 position v lies in 0..max exactly when unsigned(v) <= max. A Q8 row position y has its
// nearest row (y + 128) >> 8 whether or not its pair's upper row is clamped to h - 2.
inline bool BandOf(const WarpRow& r, const WarpSpanJob& job, Band* band) {
  const int32_t dx = job.bx - job.ax, reach = job.n * 73728;
  if (dx > reach || -dx > reach) return false;
  const uint32_t xmax = static_cast<uint32_t>(r.width - 1) * 256;
  const uint32_t ymax = static_cast<uint32_t>(r.height - 1) * 256;
  const int32_t xa = (job.ax + 128) >> 8, xb = (job.bx + 128) >> 8;
  const int32_t ya = (job.ay + 128) >> 8, yb = (job.by + 128) >> 8;
  if ((static_cast<uint32_t>(xa) > xmax) | (static_cast<uint32_t>(xb) > xmax) |
      (static_cast<uint32_t>(ya) > ymax) | (static_cast<uint32_t>(yb) > ymax)) {
    return false;
  }
  const int32_t row_a = Min(ya >> 8, r.height - 2), row_b = Min(yb >> 8, r.height - 2);
  const int32_t near_a = (ya + 128) >> 8, near_b = (yb + 128) >> 8;
  if ((static_cast<uint32_t>(row_a - row_b + 1) > 2) |
      (static_cast<uint32_t>(near_a - near_b + 1) > 2)) {
    return false;
  }
  band->y = Min(row_a, row_b);
  band->cy = Min(near_a, near_b);
  band->row = r.view + band->y * r.stride;
  band->crow = r.census_view + static_cast<ptrdiff_t>(band->cy) * 3 * r.width;
  band->two_rows = row_a != row_b;
  band->two_census = near_a != near_b;
  band->rising = dx >= 0;
  return true;
}

// Channel c's tap pairs of 8 pixels from one row: each 128-bit half (pixels 0-3, 4-7) reads the
// 16 bytes from its own start + c, start = 3 * (the half's least pair column) or 3 w - 18 if less,
// so the read ends inside the row. A span of the band advances at most 9/8 px per pixel, so a
// half's pair columns lie within 4 + 1 of its least: the pair's bytes d + c and d + c + 3 (d = 3 x
// - start <= 12) are in the window, and one byte shuffle per row and channel picks them.
LB_AVX2 inline __m256i ChannelPairs(const uint8_t* row, int32_t start_lo, int32_t start_hi,
                                    __m256i idx) {
  const __m128i lo = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + start_lo));
  const __m128i hi = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + start_hi));
  return _mm256_shuffle_epi8(_mm256_inserti128_si256(_mm256_castsi128_si256(lo), hi, 1), idx);
}

// A step of such a span: no clamps, no checks; the third row and the second census row only where
// the span reaches them (rows y + 2 <= h - 1 and cy + 1 <= h - 1, both some pixel's own). Channel
// by channel, so the taps need no more registers than one channel's.
// kTwoRows, kTwoCensus: the span's band.two_rows and two_census, fixed per instance so the
// step has no branch on them.
// kBiased: the positions come with the Q8 rounding's half (128) already added. Without
// kTwoRows every pixel's upper tap row is the band's (BandOf), so its row fraction is its Q8
// row less the band's.
template <bool kTwoRows, bool kTwoCensus, bool kBiased = false>
LB_AVX2 inline __attribute__((always_inline)) void BandStep(const WarpRow& r, const Consts& k,
                                                            const Band& band, const int32_t* lanes,
                                                            __m256i xq, __m256i yq, uint8_t* dst) {
  const __m256i half = Load(k.c->q8_half.v);
  const __m256i xs = _mm256_srai_epi32(kBiased ? xq : _mm256_add_epi32(xq, half), 8);
  const __m256i ys = _mm256_srai_epi32(kBiased ? yq : _mm256_add_epi32(yq, half), 8);
  const __m256i xb = _mm256_min_epi32(_mm256_srai_epi32(xs, 8), k.wm2);
  const __m256i yb =
      kTwoRows ? _mm256_min_epi32(_mm256_srai_epi32(ys, 8), k.hm2) : _mm256_set1_epi32(band.y);
  const __m256i fx = _mm256_sub_epi32(xs, _mm256_slli_epi32(xb, 8));
  const __m256i fy =
      _mm256_sub_epi32(ys, kTwoRows ? _mm256_slli_epi32(yb, 8) : _mm256_set1_epi32(band.y * 256));
  const __m256i nx = _mm256_sub_epi32(xb, _mm256_cmpgt_epi32(fx, Load(k.c->near.v)));
  // Each half's least pair column: its first lane when the positions rise, else its last.
  const __m256i least =
      band.rising ? _mm256_shuffle_epi32(xb, 0x00) : _mm256_shuffle_epi32(xb, 0xff);
  const __m256i start =
      _mm256_min_epi32(_mm256_add_epi32(least, _mm256_add_epi32(least, least)), k.last_window);
  const int32_t start_lo = _mm256_cvtsi256_si32(start), start_hi = _mm256_extract_epi32(start, 4);
  const __m256i d = _mm256_sub_epi32(_mm256_add_epi32(xb, _mm256_add_epi32(xb, xb)), start);
  const __m256i idx =
      _mm256_add_epi32(_mm256_add_epi32(d, _mm256_slli_epi32(d, 16)), Load(k.c->pair_idx[0].v));
  const __m256i wx =
      _mm256_add_epi32(_mm256_sub_epi32(Load(k.c->one.v), fx), _mm256_slli_epi32(fx, 16));
  const __m256i lower =
      kTwoRows ? _mm256_cmpeq_epi32(yb, _mm256_set1_epi32(band.y + 1)) : _mm256_setzero_si256();
  __m256i ad = _mm256_setzero_si256();
  for (int32_t c = 0; c < 3; ++c) {
    const uint8_t* row = band.row + c;
    __m256i top = ChannelPairs(row, start_lo, start_hi, idx);
    __m256i bottom = ChannelPairs(row + r.stride, start_lo, start_hi, idx);
    if (kTwoRows) {
      const __m256i third = ChannelPairs(row + 2 * r.stride, start_lo, start_hi, idx);
      top = _mm256_blendv_epi8(top, bottom, lower);
      bottom = _mm256_blendv_epi8(bottom, third, lower);
    }
    const __m256i t = _mm256_madd_epi16(top, wx), b = _mm256_madd_epi16(bottom, wx);
    const __m256i sum =
        _mm256_add_epi32(_mm256_slli_epi32(t, 8), _mm256_mullo_epi32(_mm256_sub_epi32(b, t), fy));
    const __m256i v = _mm256_srai_epi32(_mm256_add_epi32(sum, Load(k.c->half.v)), 16);
    const __m256i rc =
        _mm256_loadu_si256(reinterpret_cast<const __m256i*>(lanes + c * band.lanes_stride));
    ad = _mm256_add_epi32(ad, _mm256_abs_epi32(_mm256_sub_epi32(rc, v)));
  }
  ad = _mm256_min_epi32(ad, k.trunc);
  // The census taps: the 8 nearest columns lie within 16 of the least (7 * 9/8 + 2 < 16).
  const int32_t x_min = band.rising ? _mm256_cvtsi256_si32(xb) : _mm256_extract_epi32(xb, 7);
  const int32_t cstart = Min(x_min, r.width - 16);
  const __m256i e = _mm256_sub_epi32(nx, _mm256_set1_epi32(cstart));
  __m256i census = _mm256_setzero_si256();
  __m256i census2 = _mm256_setzero_si256();
  const ptrdiff_t census_row = static_cast<ptrdiff_t>(3) * r.width;
  for (int32_t p = 0; p < 3; ++p) {
    const int32_t shift = 8 * (2 - p);  // plane 0 holds the top byte
    const __m256i pidx = _mm256_or_si256(_mm256_slli_epi32(e, shift), Load(k.c->census_idx[p].v));
    const uint8_t* plane = band.crow + p * r.width + cstart;
    census = _mm256_or_si256(census, _mm256_shuffle_epi8(Broadcast16(plane), pidx));
    if (kTwoCensus) {
      census2 =
          _mm256_or_si256(census2, _mm256_shuffle_epi8(Broadcast16(plane + census_row), pidx));
    }
  }
  if (kTwoCensus) {
    const __m256i ny = _mm256_sub_epi32(yb, _mm256_cmpgt_epi32(fy, Load(k.c->near.v)));
    census =
        _mm256_blendv_epi8(census, census2, _mm256_cmpeq_epi32(ny, _mm256_set1_epi32(band.cy + 1)));
  }
  const __m256i ref_bits =
      _mm256_loadu_si256(reinterpret_cast<const __m256i*>(lanes + 3 * band.lanes_stride));
  Store8(dst, CostFromTaps(k, ad, census, ref_bits));
}

// A step of a span of the band, its instance chosen at run time (partial and short spans).
LB_AVX2 inline void AnyBandStep(const WarpRow& r, const Consts& k, const Band& band, int32_t x,
                                __m256i xq, __m256i yq, uint8_t* dst) {
  const int32_t* lanes = r.ref_lanes + (x - r.lanes_x0);
  if (band.two_rows) {
    if (band.two_census) return BandStep<true, true>(r, k, band, lanes, xq, yq, dst);
    return BandStep<true, false>(r, k, band, lanes, xq, yq, dst);
  }
  if (band.two_census) return BandStep<false, true>(r, k, band, lanes, xq, yq, dst);
  BandStep<false, false>(r, k, band, lanes, xq, yq, dst);
}

// The two steps of a whole span of the band: pixels x..x+7 at (q[0], q[1]), x+8..x+15 at (q[2],
// q[3]) (Q16 positions plus 128), their costs into dst[0..15]. Inlined in the run's loop, one copy
// per band kind, so a span pays no call and the constants stay put.
template <bool kTwoRows, bool kTwoCensus>
LB_AVX2 inline __attribute__((always_inline)) void BandSpan(const WarpRow& r, const Consts& k,
                                                            const Band& band, int32_t x,
                                                            const __m256i* q, uint8_t* dst) {
  const int32_t* lanes = r.ref_lanes + (x - r.lanes_x0);
  BandStep<kTwoRows, kTwoCensus, true>(r, k, band, lanes, q[0], q[1], dst);
  BandStep<kTwoRows, kTwoCensus, true>(r, k, band, lanes + kLanes, q[2], q[3], dst + kLanes);
}

// One span, any: outside the view, partly outside, beyond the band's reach, short or cut by the
// wanted columns. Positions as WarpSpan's Q32 accumulators, split so that 32-bit lanes give the
// same bits: with the step s = q 2^16 + r (0 <= r < 2^16), (a 2^16 + 2^15 + i s) >> 16 = a + i q +
// ((2^15 + i r) >> 16); i <= 16 keeps 2^15 + i r below 2^21, and a + i q wraps only where the
// exact result (a Q16 position, |.| < 2^30) does not.
LB_AVX2 void AnySpan(const WarpRow& r, const Consts& k, const WarpSpanJob* job, uint8_t* out) {
  const __m256i half = _mm256_set1_epi32(32768);
  const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  // A whole span divides exactly (2^16 / kAnchorStep is whole): no division.
  const int32_t n = job->n;
  const int64_t dx = int64_t{job->bx} - job->ax, dy = int64_t{job->by} - job->ay;
  const int64_t sx = n == kAnchorStep ? dx * (65536 / kAnchorStep) : n > 0 ? dx * 65536 / n : 0;
  const int64_t sy = n == kAnchorStep ? dy * (65536 / kAnchorStep) : n > 0 ? dy * 65536 / n : 0;
  const __m256i qx = _mm256_set1_epi32(static_cast<int32_t>(sx >> 16));
  const __m256i qy = _mm256_set1_epi32(static_cast<int32_t>(sy >> 16));
  const __m256i rx = _mm256_set1_epi32(static_cast<int32_t>(sx & 0xffff));
  const __m256i ry = _mm256_set1_epi32(static_cast<int32_t>(sy & 0xffff));
  // Lanes off the span (short ranges only) repeat its end pixels, so a step stays monotone;
  // only a step reaching the span's end needs its end anchor put in.
  auto positions = [&](int32_t x, __m256i* xq, __m256i* yq) LB_AVX2 {
    __m256i i = _mm256_add_epi32(_mm256_set1_epi32(x - job->x0), iota);
    const bool at_ends = x < job->x0 || x + kLanes > job->x0 + n;
    if (at_ends) {
      i = _mm256_min_epi32(_mm256_max_epi32(i, _mm256_setzero_si256()), _mm256_set1_epi32(n));
    }
    *xq =
        _mm256_add_epi32(_mm256_add_epi32(_mm256_set1_epi32(job->ax), _mm256_mullo_epi32(i, qx)),
                         _mm256_srli_epi32(_mm256_add_epi32(half, _mm256_mullo_epi32(i, rx)), 16));
    *yq =
        _mm256_add_epi32(_mm256_add_epi32(_mm256_set1_epi32(job->ay), _mm256_mullo_epi32(i, qy)),
                         _mm256_srli_epi32(_mm256_add_epi32(half, _mm256_mullo_epi32(i, ry)), 16));
    if (at_ends) {
      const __m256i at_end = _mm256_cmpeq_epi32(i, _mm256_set1_epi32(n));
      *xq = _mm256_blendv_epi8(*xq, _mm256_set1_epi32(job->bx), at_end);
      *yq = _mm256_blendv_epi8(*yq, _mm256_set1_epi32(job->by), at_end);
    }
  };
  __m256i xq, yq;
  Band band{};
  band.lanes_stride = r.lanes_stride;
  const bool in_band = r.width >= 16 && BandOf(r, *job, &band);
  if (!in_band && SpanOutsideView(r, *job)) {
    FillInvalid(r, *job, out);
    return;
  }
  if (job->hi - job->lo < kLanes) {
    // A short range: one step over 8 pixels of the row that hold it, into a buffer.
    const int32_t x = Min(job->lo, r.width - kLanes);
    positions(x, &xq, &yq);
    uint8_t costs[kLanes];
    if (in_band) {
      AnyBandStep(r, k, band, x, xq, yq, costs);
    } else {
      Step(r, k, x, xq, yq, costs);
    }
    std::memcpy(out + job->lo, costs + (job->lo - x), static_cast<size_t>(job->hi - job->lo));
    return;
  }
  for (int32_t step = job->lo; step < job->hi; step += kLanes) {
    // The last step overlaps the one before: the same bytes again.
    const int32_t x = step + kLanes <= job->hi ? step : job->hi - kLanes;
    positions(x, &xq, &yq);
    if (in_band) {
      AnyBandStep(r, k, band, x, xq, yq, out + x);
    } else {
      Step(r, k, x, xq, yq, out + x);
    }
  }
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
// `end` load nothing (masked loads: the anchors may end there).
LB_AVX2 void BandsOfRun(const WarpRow& r, const WarpRun& run, int32_t first, int32_t end,
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

}  // namespace

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

// A run at once: its spans' band tests 8 at a time (BandsOfRun), then each span of the band two
// steps from its anchors, the rest (outside the view, partly, short, steep) one by one
// (AnySpan). The positions of a whole span: (a 2^16 + 2^15 + i dx 2^12) >> 16 = a +
// ((i dx + 8) >> 4), with |i dx| <= 15 * 16 * 73728 < 2^25 in the band.
LB_AVX2 void PlaneSpansAvx2(const WarpRow& r, const WarpRun& run, uint8_t* out) {
  const int64_t bytes = int64_t{r.height} * r.stride;
  if (r.width < kLanes || r.height < 2 || r.stride <= 0 || bytes >= (int64_t{1} << 31) ||
      r.cw < 0 || r.cw > 31) {
    return PlaneSpansC(r, run, out);
  }
  alignas(32) int8_t lut[32];
  for (int32_t i = 0; i < 32; ++i) lut[i] = static_cast<int8_t>(r.cw * kMasks.nibble_bits[i]);
  const Consts k{_mm256_set1_epi32((r.width - 1) * 256),
                 _mm256_set1_epi32((r.height - 1) * 256),
                 _mm256_set1_epi32(r.width - 2),
                 _mm256_set1_epi32(r.height - 2),
                 _mm256_set1_epi32(static_cast<int32_t>(r.stride)),
                 _mm256_set1_epi32(3 * r.width),
                 _mm256_set1_epi32(r.trunc),
                 _mm256_set1_epi32(r.invalid),
                 Load(lut),
                 _mm256_set1_epi32(3 * r.width - 18),
                 Laundered(&kC),
                 Laundered(&kMasks)};
  const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i eight = _mm256_set1_epi32(8);
  int32_t first = 0, end = 0;
  RunSpans(run, &first, &end);
  RunBands bands;
  // Without the caller's reference lanes, this kernel makes its own for each chunk of spans
  // (RefLanes' columns of at most kRunSpans spans: 16 kRunSpans + 1 + 16 + 39 < kLocalLanes).
  constexpr int32_t kLocalLanes = 16 * kRunSpans + 64;
  alignas(32) int32_t local[4 * kLocalLanes];
  WarpRow rl = r;
  for (int32_t base = first; base < end; base += kRunSpans) {
    const int32_t stop = Min(end, base + kRunSpans);
    if (r.width >= 16) {
      BandsOfRun(r, run, base, stop, &bands);
    } else {
      for (int32_t i = 0; i < stop - base; ++i) bands.kind[i] = 0;
    }
    if (r.ref_lanes == nullptr) {
      const int32_t lo = Max(run.lo, run.x0 + kAnchorStep * base);
      const int32_t hi = Min(run.hi, run.x0 + kAnchorStep * stop + 1);
      rl.lanes_x0 = RefLanesBegin(r.width, lo);
      rl.lanes_stride = kLocalLanes;
      rl.ref_lanes = local;
      PlaneLanesAvx2(r.ref, r.cref, r.width, rl.lanes_x0, RefLanesEnd(r.width, hi), local,
                     kLocalLanes);
    }
    // Locals: the stores through `out` may alias the structs' fields, which would be read again
    // for every span.
    const int32_t* const xs = run.x_q16;
    const int32_t* const ys = run.y_q16;
    const int32_t x0 = run.x0;
    const uint8_t* const view = r.view;
    const uint8_t* const census_view = r.census_view;
    const ptrdiff_t lanes_stride = rl.lanes_stride;
    for (int32_t s = base; s < stop; ++s) {
      const int32_t i = s - base, kind = bands.kind[i];
      if ((kind & kInBand) == 0) {
        const WarpSpanJob job = RunSpan(run, s);
        if (job.lo < job.hi) AnySpan(rl, k, &job, out);
        continue;
      }
      const int32_t x = x0 + kAnchorStep * s;
      const Band band{view + bands.row[i],
                      census_view + bands.crow[i],
                      bands.y[i],
                      bands.cy[i],
                      (kind & kTwoRows) != 0,
                      (kind & kTwoCensus) != 0,
                      (kind & kRising) != 0,
                      lanes_stride};
      const __m256i dx = _mm256_set1_epi32(bands.dx[i]), dy = _mm256_set1_epi32(bands.dy[i]);
      const __m256i tx = _mm256_add_epi32(_mm256_mullo_epi32(iota, dx), eight);
      const __m256i ty = _mm256_add_epi32(_mm256_mullo_epi32(iota, dy), eight);
      // Plus BandStep's rounding half: (a + 128) + t for a + t + 128, exact in int32.
      const __m256i ax = _mm256_set1_epi32(xs[s] + 128);
      const __m256i ay = _mm256_set1_epi32(ys[s] + 128);
      const __m256i q[4] = {
          _mm256_add_epi32(ax, _mm256_srai_epi32(tx, 4)),
          _mm256_add_epi32(ay, _mm256_srai_epi32(ty, 4)),
          _mm256_add_epi32(ax,
                           _mm256_srai_epi32(_mm256_add_epi32(tx, _mm256_slli_epi32(dx, 3)), 4)),
          _mm256_add_epi32(ay,
                           _mm256_srai_epi32(_mm256_add_epi32(ty, _mm256_slli_epi32(dy, 3)), 4))};
      uint8_t* const dst = out + x;
      switch (kind & (kTwoRows | kTwoCensus)) {
        case 0:
          BandSpan<false, false>(rl, k, band, x, q, dst);
          break;
        case kTwoRows:
          BandSpan<true, false>(rl, k, band, x, q, dst);
          break;
        case kTwoCensus:
          BandSpan<false, true>(rl, k, band, x, q, dst);
          break;
        default:
          BandSpan<true, true>(rl, k, band, x, q, dst);
          break;
      }
    }
  }
}

}  // namespace lb::dtk
#endif
