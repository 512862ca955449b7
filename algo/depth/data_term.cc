#include "algo/depth/data_term.h"

#include <cstring>

#include "algo/depth/warp_cost.h"

namespace lb {
namespace {

constexpr int32_t kMaxBest = 8;  // best half of up to 15 other views

// Bit count by halving sums (no popcount instruction on baseline x86-64; vectorises).
inline uint32_t BitCount(uint32_t v) {
  v = v - ((v >> 1) & 0x55555555u);
  v = (v & 0x33333333u) + ((v >> 2) & 0x33333333u);
  v = (v + (v >> 4)) & 0x0f0f0f0fu;
  v = v + (v >> 8);  // shifts, not a multiply: SSE2 has no 32-bit vector multiply
  v = v + (v >> 16);
  return v & 0x3fu;
}

inline int32_t Clamp(int32_t v, int32_t lo, int32_t hi) { return v < lo ? lo : (v > hi ? hi : v); }

// 5x5 census of a luma image (borders replicated): bit i set when neighbour i is darker than
// the centre, neighbours in raster order without the centre.
void Census(const uint8_t* luma, int32_t w, int32_t h, uint32_t* out) {
  for (int32_t y = 0; y < h; ++y) {
    const uint8_t* rows[5];
    for (int32_t dy = -2; dy <= 2; ++dy) rows[dy + 2] = luma + Clamp(y + dy, 0, h - 1) * w;
    for (int32_t x = 0; x < w; ++x) {
      const int32_t c = rows[2][x];
      uint32_t bits = 0;
      for (int32_t dy = 0; dy < 5; ++dy) {
        for (int32_t dx = -2; dx <= 2; ++dx) {
          if (dy == 2 && dx == 0) continue;
          bits = (bits << 1) | (rows[dy][Clamp(x + dx, 0, w - 1)] < c ? 1u : 0u);
        }
      }
      out[y * w + x] = bits;
    }
  }
}

}  // namespace

void DataTerm::Carve(Arena& arena, int32_t width, int32_t height, int32_t views) {
  width_ = width;
  height_ = height;
  views_ = views;
  const size_t n = static_cast<size_t>(width) * height;
  for (int32_t v = 0; v < views; ++v) census_[v] = arena.Allocate<uint32_t>(n);
  luma_ = arena.Allocate<uint8_t>(n);
  pixel_ = arena.Allocate<uint16_t>(static_cast<size_t>(width));
  hsum_ = arena.Allocate<uint16_t>(static_cast<size_t>(width) * 3 * views);
  best_ = arena.Allocate<uint16_t>(static_cast<size_t>(width) * kMaxBest);
}

void DataTerm::SetParams(const DataTermParams& params, int32_t reference) {
  params_ = params;
  reference_ = reference;
  const int32_t c = params.color_trunc + kCensusBits * params.census_weight;
  invalid_cost_ = c > 255 ? 255 : c;
}

void DataTerm::Prepare(const ConstImageU8* views) {
  images_ = views;
  for (int32_t v = 0; v < views_; ++v) {
    for (int32_t y = 0; y < height_; ++y) {
      const uint8_t* rgb = views[v].Row(y);
      uint8_t* l = luma_ + y * width_;
      for (int32_t x = 0; x < width_; ++x) {
        // BT.601 luma, Q8 weights summing to 256, rounded.
        l[x] = static_cast<uint8_t>(
            (77 * rgb[3 * x] + 150 * rgb[3 * x + 1] + 29 * rgb[3 * x + 2] + 128) >> 8);
      }
    }
    Census(luma_, width_, height_, census_[v]);
  }
}

// The per-pixel kernel over n valid pixels: ref/img are RGB8 rows already aligned so that pixel
// i of ref pairs with samples i and i + 1 of img (weights 256 - f and f, Q8).
// Cloned for SSSE3/AVX2 on x86-64 where the stride-3 colour loads need byte shuffles that
// baseline SSE2 lacks; the arithmetic is integer, so every clone gives the same bits.
#if defined(__x86_64__)
__attribute__((target_clones("avx2", "ssse3", "default")))
#endif
static void
CostKernel(const uint8_t* ref, const uint8_t* img, const uint32_t* cref, const uint32_t* cimg,
           int32_t n, int32_t f, int32_t trunc, int32_t cw, uint16_t* out) {
  const int32_t g = 256 - f;
  if (f == 0) {
    for (int32_t x = 0; x < n; ++x) {
      const int32_t dr = ref[3 * x] - img[3 * x];
      const int32_t dg = ref[3 * x + 1] - img[3 * x + 1];
      const int32_t db = ref[3 * x + 2] - img[3 * x + 2];
      int32_t ad = (dr < 0 ? -dr : dr) + (dg < 0 ? -dg : dg) + (db < 0 ? -db : db);
      ad = ad < trunc ? ad : trunc;
      const int32_t cost = ad + static_cast<int32_t>(BitCount(cref[x] ^ cimg[x])) * cw;
      out[x] = static_cast<uint16_t>(cost > 255 ? 255 : cost);
    }
    return;
  }
  // 16-bit lanes: s0 * g + s1 * f + 128 <= 65408, (h0 * g + h1 * f) * cw + 128 <= 61568.
  const uint16_t g16 = static_cast<uint16_t>(g), f16 = static_cast<uint16_t>(f);
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
    const uint16_t h0 = static_cast<uint16_t>(BitCount(cref[x] ^ cimg[x]));
    const uint16_t h1 = static_cast<uint16_t>(BitCount(cref[x] ^ cimg[x + 1]));
    const uint16_t ham = static_cast<uint16_t>(
        static_cast<uint16_t>(static_cast<uint16_t>(h0 * g16 + h1 * f16) * cw16 + 128) >> 8);
    const uint16_t cost = static_cast<uint16_t>(ad + ham);
    out[x] = cost > 255 ? 255 : cost;
  }
}

void DataTerm::PixelCostRow(int32_t view, int32_t y, int32_t disp_q8, uint16_t* out) const {
  if (planes_ != nullptr) {
    const WarpSource src{images_[reference_], images_[view], census_[reference_], census_[view]};
    PlaneCostRow(planes_[view], src, y, params_, invalid_cost_, out);
    return;
  }
  const int32_t w = width_;
  // Sample position in the view: x * 256 + shift_q8, the same fraction for every pixel.
  const int32_t shift_q8 = -(view - reference_) * disp_q8;
  const int32_t off = shift_q8 >> 8;  // floor
  const int32_t f = shift_q8 & 255;   // Q8 weight of the right-hand sample
  const int32_t x_lo = Clamp(-off, 0, w);
  const int32_t x_hi = Clamp(w - (f > 0 ? 1 : 0) - off, x_lo, w);
  const uint16_t invalid = static_cast<uint16_t>(invalid_cost_);
  for (int32_t x = 0; x < x_lo; ++x) out[x] = invalid;
  for (int32_t x = x_hi; x < w; ++x) out[x] = invalid;
  if (x_hi <= x_lo) return;
  CostKernel(images_[reference_].Row(y) + 3 * x_lo, images_[view].Row(y) + 3 * (x_lo + off),
             census_[reference_] + y * w + x_lo, census_[view] + y * w + x_lo + off, x_hi - x_lo, f,
             params_.color_trunc, params_.census_weight, out + x_lo);
}

// Horizontal 3-sum of the pixel costs of row y (borders replicated): 0..765.
void DataTerm::WindowRow(int32_t view, int32_t y, int32_t disp_q8, uint16_t* hsum) {
  const int32_t w = width_;
  PixelCostRow(view, Clamp(y, 0, height_ - 1), disp_q8, pixel_);
  hsum[0] = static_cast<uint16_t>(2 * pixel_[0] + pixel_[w > 1 ? 1 : 0]);
  for (int32_t x = 1; x < w - 1; ++x) {
    hsum[x] = static_cast<uint16_t>(pixel_[x - 1] + pixel_[x] + pixel_[x + 1]);
  }
  if (w > 1) hsum[w - 1] = static_cast<uint16_t>(pixel_[w - 2] + 2 * pixel_[w - 1]);
}

void DataTerm::ComputeRows(int32_t disp_q8, int32_t y0, int32_t y1, uint16_t* out,
                           ptrdiff_t stride) {
  const int32_t w = width_;
  const int32_t others = views_ - 1;
  const int32_t keep = (others + 1) / 2;
  // Q15 reciprocal of `keep`: the mean of the kept sums, rounded (error < 1 for D <= 2295).
  const uint32_t recip_q15 =
      (32768u + static_cast<uint32_t>(keep) / 2) / static_cast<uint32_t>(keep);
  auto ring = [&](int32_t v, int32_t row) {
    return hsum_ + (static_cast<size_t>(v) * 3 + static_cast<size_t>((row - y0 + 1) % 3)) * w;
  };
  for (int32_t v = 0; v < views_; ++v) {
    if (v == reference_) continue;
    WindowRow(v, y0 - 1, disp_q8, ring(v, y0 - 1));
    WindowRow(v, y0, disp_q8, ring(v, y0));
  }
  // Signed 16-bit lanes (sums <= 2295) so the min/max below are SSE2's pminsw/pmaxsw.
  int16_t* best = reinterpret_cast<int16_t*>(best_);
  int16_t* a = reinterpret_cast<int16_t*>(pixel_);
  for (int32_t y = y0; y < y1; ++y) {
    for (int32_t i = 0; i < keep * w; ++i) best[i] = INT16_MAX;
    for (int32_t v = 0; v < views_; ++v) {
      if (v == reference_) continue;
      uint16_t* next = ring(v, y + 1);
      WindowRow(v, y + 1, disp_q8, next);
      const uint16_t* prev = ring(v, y - 1);
      const uint16_t* cur = ring(v, y);
      // Window sum, then insertion into the sorted list of the `keep` smallest sums.
      for (int32_t x = 0; x < w; ++x) a[x] = static_cast<int16_t>(prev[x] + cur[x] + next[x]);
      for (int32_t j = 0; j < keep; ++j) {
        int16_t* b = best + j * w;
        for (int32_t x = 0; x < w; ++x) {
          const int16_t lo = b[x] < a[x] ? b[x] : a[x];
          const int16_t hi = b[x] < a[x] ? a[x] : b[x];
          b[x] = lo;
          a[x] = hi;
        }
      }
    }
    uint16_t* o = out + (y - y0) * stride;
    // Sum of the kept rows (<= 8 * 2295, fits 16 bits unsigned), then the mean in Q15.
    for (int32_t x = 0; x < w; ++x) o[x] = static_cast<uint16_t>(best[x]);
    for (int32_t j = 1; j < keep; ++j) {
      const int16_t* b = best + j * w;
      for (int32_t x = 0; x < w; ++x) o[x] = static_cast<uint16_t>(o[x] + b[x]);
    }
    for (int32_t x = 0; x < w; ++x) {
      o[x] = static_cast<uint16_t>((o[x] * recip_q15 + (1u << 14)) >> 15);
    }
  }
}

}  // namespace lb
