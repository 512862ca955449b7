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
// census weights over 31, take the reference. The band tests are in warp_cost_avx2.h with the
// pieces both files use, the reference lanes and the anchors' divisions in
// warp_cost_prep_avx2.cc.
#include "algo/depth/warp_cost_avx2.h"

#if defined(__x86_64__)
#include <immintrin.h>

#include <cstring>

#include "algo/core/int_math.h"

namespace lb::dtk {
namespace {

using plane_avx2::BandsOfRun;
using plane_avx2::kC;
using plane_avx2::kLanes;
using plane_avx2::kMasks;
using plane_avx2::kTwoCensus;
using plane_avx2::kTwoRows;
using plane_avx2::Load;

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
  const plane_avx2::Constants* c;
  const plane_avx2::Masks* m;
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
  return CostFromTaps(k, _mm256_min_epi32(ad, k.trunc), t.census, plane_avx2::RefCensus(r, x));
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

}  // namespace

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
  plane_avx2::RunBands bands;
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
      if ((kind & plane_avx2::kInBand) == 0) {
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
                      (kind & plane_avx2::kRising) != 0,
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
