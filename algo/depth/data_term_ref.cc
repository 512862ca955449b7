// The C reference kernels of the data term: the definition the SIMD twins are tested against.
#include "algo/depth/data_term_kernels.h"

#include <initializer_list>

#include "algo/core/cpu.h"

namespace lb::dtk {
namespace {

// Bit count by halving sums (no popcount instruction on baseline x86-64; vectorises).
inline uint32_t BitCount(uint32_t v) {
  v = v - ((v >> 1) & 0x55555555u);
  v = (v & 0x33333333u) + ((v >> 2) & 0x33333333u);
  v = (v + (v >> 4)) & 0x0f0f0f0fu;
  v = v + (v >> 8);  // shifts, not a multiply: SSE2 has no 32-bit vector multiply
  v = v + (v >> 16);
  return v & 0x3fu;
}

}  // namespace

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

namespace {

// The per-pixel cost over n valid pixels: ref/img are RGB8 rows already aligned so that pixel
// i of ref pairs with samples i and i + 1 of img (weights 256 - f and f, Q8); cref/cimg are
// census planes `plane` bytes apart.
// One source for CostRowC and its x86-64 builds for SSSE3 and AVX2 (below): always inlined, so
// each wrapper compiles it for its own target; integer arithmetic, so all give the same bits.
inline __attribute__((always_inline)) void CostBody(const uint8_t* ref, const uint8_t* img,
                                                    const uint8_t* cref, const uint8_t* cimg,
                                                    ptrdiff_t plane, int32_t n, int32_t f,
                                                    int32_t trunc, int32_t cw, uint8_t* out) {
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

}  // namespace

void CostRowC(const uint8_t* ref, const uint8_t* img, const uint8_t* cref, const uint8_t* cimg,
              ptrdiff_t plane, int32_t n, int32_t f, int32_t trunc, int32_t cw, uint8_t* out) {
  CostBody(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
}

#if defined(__x86_64__)
__attribute__((target("ssse3"))) void CostRowCSsse3(const uint8_t* ref, const uint8_t* img,
                                                    const uint8_t* cref, const uint8_t* cimg,
                                                    ptrdiff_t plane, int32_t n, int32_t f,
                                                    int32_t trunc, int32_t cw, uint8_t* out) {
  CostBody(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
}

__attribute__((target("avx2"))) void CostRowCAvx2(const uint8_t* ref, const uint8_t* img,
                                                  const uint8_t* cref, const uint8_t* cimg,
                                                  ptrdiff_t plane, int32_t n, int32_t f,
                                                  int32_t trunc, int32_t cw, uint8_t* out) {
  CostBody(ref, img, cref, cimg, plane, n, f, trunc, cw, out);
}
#endif

// Horizontal 3-sum (0..765) of a cost row whose pixels -1 and w replicate the borders.
void HSumRowC(const uint8_t* cost, int32_t x0, int32_t x1, uint16_t* hsum) {
  for (int32_t x = x0; x < x1; ++x) {
    hsum[x] = static_cast<uint16_t>(cost[x - 1] + cost[x] + cost[x + 1]);
  }
}

// Per pixel: window sums (3 ring rows per other view, <= 2295), the mean of the smallest
// (n + 1) / 2 of them, n the views that see the pixel (whose window is below `unseen`; all
// `others` when none does). The kept sum is <= 8 * 2295, so 32-bit products are exact. Chunks of
// 16 pixels so that the sorted-list insertion (a min/max chain) vectorises.
void SelectRowC(const uint16_t* ring, ptrdiff_t stride, int32_t others, int32_t unseen, int32_t x0,
                int32_t x1, uint16_t* out) {
  constexpr int32_t kChunk = 16;
  const int32_t most = (others + 1) / 2;
  for (int32_t xs = x0; xs < x1; xs += kChunk) {
    const int32_t n = x1 - xs < kChunk ? x1 - xs : kChunk;
    uint16_t best[kMaxBest][kChunk] = {};  // sorted, ascending
    int32_t seen[kChunk] = {};
    for (int32_t i = 0; i < most; ++i)
      for (int32_t l = 0; l < kChunk; ++l) best[i][l] = UINT16_MAX;
    for (int32_t j = 0; j < others; ++j) {
      uint16_t a[kChunk] = {};
      const uint16_t* r0 = ring + 3 * j * stride + xs;
      const uint16_t *r1 = r0 + stride, *r2 = r0 + 2 * stride;
      for (int32_t l = 0; l < n; ++l) a[l] = static_cast<uint16_t>(r0[l] + r1[l] + r2[l]);
      for (int32_t l = 0; l < kChunk; ++l) seen[l] += a[l] < unseen ? 1 : 0;
      for (int32_t i = 0; i < most; ++i) {
        for (int32_t l = 0; l < kChunk; ++l) {
          const uint16_t lo = best[i][l] < a[l] ? best[i][l] : a[l];
          a[l] = best[i][l] < a[l] ? a[l] : best[i][l];
          best[i][l] = lo;
        }
      }
    }
    for (int32_t l = 0; l < n; ++l) {
      const int32_t keep = seen[l] > 0 ? (seen[l] + 1) / 2 : most;
      uint32_t sum = 0;
      for (int32_t i = 0; i < keep; ++i) sum += best[i][l];
      out[xs + l] = static_cast<uint16_t>((sum * RecipQ15(keep) + (1u << 14)) >> 15);
    }
  }
}

const DataTerm::Kernels kReference = {
    CensusRowC,  CostRowC, HSumRowC,     SelectRowC, RectRowWith<CostRowC, HSumRowC>,
    PlaneSpansC, nullptr,  PlaneAnchorsC};

const DataTerm::Kernels* Ssse3Kernels() {
#if defined(__x86_64__)
  static constexpr DataTerm::Kernels kSsse3 = {
      CensusRowC,  CostRowCSsse3, HSumRowC,     SelectRowC, RectRowWith<CostRowCSsse3, HSumRowC>,
      PlaneSpansC, nullptr,       PlaneAnchorsC};
  return __builtin_cpu_supports("ssse3") ? &kSsse3 : nullptr;
#else
  return nullptr;
#endif
}

const DataTerm::Kernels* SimdKernels() {
  // What the firmware read of this processor (algo/core/cpu.h): armhf's NEON only where the
  // kernel says the core has it.
  const CpuFeatures cpu = CurrentCpu();
  if (const DataTerm::Kernels* k = cpu.avx2 ? Avx2Kernels() : nullptr) return k;
  if (const DataTerm::Kernels* k = cpu.neon ? NeonKernels() : nullptr) return k;
  return cpu.ssse3 ? Ssse3Kernels() : nullptr;
}

int32_t Variants(Variant* out) {
  int32_t n = 0;
  out[n++] = {"C", &kReference};
  if (const DataTerm::Kernels* k = Ssse3Kernels()) out[n++] = {"C for SSSE3", k};
  if (const DataTerm::Kernels* k = Avx2Kernels()) out[n++] = {"AVX2", k};
  if (const DataTerm::Kernels* k = CurrentCpu().neon ? NeonKernels() : nullptr) {
    out[n++] = {"NEON", k};
  }
  return n;
}

}  // namespace lb::dtk
