#include "algo/render/depth_upsample.h"

#include <cmath>
#include <initializer_list>

#include "algo/core/int_math.h"

namespace lb {
void DepthUpsampler::Carve(Arena& arena, int32_t width, int32_t height, int32_t scale,
                           int32_t working_width, int32_t working_height, int32_t workers) {
  width_ = width, height_ = height, scale_ = scale, ww_ = working_width, wh_ = working_height;
  workers_ = Clamp(workers, 1, kMaxWorkers);
  for (int32_t w = 0; w < workers_; ++w) {
    Cache& c = cache_[w];
    for (Guide& g : c.guide) g.yuv = arena.Allocate<uint8_t>(static_cast<size_t>(3) * ww_);
    c.uniform = arena.Allocate<uint8_t>(static_cast<size_t>(ww_));
    c.sums = arena.Allocate<uint32_t>(static_cast<size_t>(width) + 2 * ((width + 1) / 2));
  }
  spatial_q8_ = arena.Allocate<uint16_t>(static_cast<size_t>(3) * scale_);
  range_q8_ = arena.Allocate<uint16_t>(766);
}

// The tables are filled here, not at Carve: the pipeline lends the render's memory to the depth
// stages between renders.
void DepthUpsampler::Begin(const ConstPlanarU8& ref, ConstImageU16 disp_q8, ConstImageU8 confidence,
                           bool one_side) {
  one_side_ = one_side;
  ref_ = ref;
  disp_ = disp_q8;
  confidence_ = confidence;
  int32_t lo = 65535, hi = 0;
  for (int32_t y = 0; y < wh_; ++y) {
    const uint16_t* row = disp_q8.Row(y);
    for (int32_t x = 0; x < ww_; ++x) lo = Min(lo, row[x]), hi = Max(hi, row[x]);
  }
  smooth_q8_ = Max(kSmoothQ8, (hi - lo) / kSmoothShare);
  for (int32_t w = 0; w < workers_; ++w) {
    for (Guide& g : cache_[w].guide) g.tag = -1;
    cache_[w].uniform_tag = -1;
  }
  // Spatial term (1 - (d / 1.75)^2)^2 of the distance d in working px between a sub-position and
  // a neighbour's centre: every neighbour of the 3x3 keeps some weight, the near ones most.
  for (int32_t f = 0; f < scale_; ++f) {
    const double u = (f + 0.5) / scale_ - 0.5;
    for (int32_t o = 0; o < 3; ++o) {
      const double d = (u - (o - 1)) / 1.75;
      const double w = d * d >= 1.0 ? 0.0 : (1.0 - d * d) * (1.0 - d * d);
      spatial_q8_[f * 3 + o] = static_cast<uint16_t>(std::lround(w * 256.0));
    }
  }
  // Range term sigma^4 / (sigma^2 + D^2)^2, in integers.
  const int64_t s2 = int64_t{kRangeSigma} * kRangeSigma;
  for (int64_t d = 0; d <= 765; ++d) {
    const int64_t den = (s2 + d * d) * (s2 + d * d);
    range_q8_[d] = static_cast<uint16_t>((256 * s2 * s2 + den / 2) / den);
  }
}

const uint8_t* DepthUpsampler::GuideRow(Cache& c, int32_t wy) {
  Guide& g = c.guide[wy & 3];
  if (g.tag == wy) return g.yuv;
  g.tag = wy;
  const int32_t s = scale_;
  const int32_t cw = ref_.planes[1].width, ch = ref_.planes[1].height;
  // Each block's sum as the sum of its columns' sums: every row is added once, a whole row at
  // a time (the same integers as adding the block pixel by pixel).
  uint32_t* const col = c.sums;
  const int32_t used = ww_ * s;  // the columns the blocks cover: at most width_ (RenderStage)
  for (int32_t x = 0; x < used; ++x) col[x] = 0;
  for (int32_t y = wy * s; y < wy * s + s; ++y) {
    const uint8_t* row = ref_.planes[0].Row(y);
    for (int32_t x = 0; x < used; ++x) col[x] += row[x];
  }
  const int32_t cy0 = wy * s / 2, cy1 = Min((wy * s + s - 1) / 2, ch - 1);
  uint32_t* const ccol[2] = {col + width_, col + width_ + cw};
  for (int32_t p = 1; p < 3; ++p) {
    uint32_t* const sum = ccol[p - 1];
    for (int32_t x = 0; x < cw; ++x) sum[x] = 0;
    for (int32_t y = cy0; y <= cy1; ++y) {
      const uint8_t* row = ref_.planes[p].Row(y);
      for (int32_t x = 0; x < cw; ++x) sum[x] += row[x];
    }
  }
  for (int32_t wx = 0; wx < ww_; ++wx) {
    uint32_t sum = 0;
    for (int32_t x = wx * s; x < wx * s + s; ++x) sum += col[x];
    g.yuv[wx] = static_cast<uint8_t>((sum + s * s / 2) / (s * s));
    const int32_t cx0 = wx * s / 2, cx1 = Min((wx * s + s - 1) / 2, cw - 1);
    const uint32_t n = static_cast<uint32_t>((cx1 - cx0 + 1) * (cy1 - cy0 + 1));
    for (int32_t p = 1; p < 3; ++p) {
      uint32_t csum = 0;
      for (int32_t x = cx0; x <= cx1; ++x) csum += ccol[p - 1][x];
      g.yuv[p * ww_ + wx] = static_cast<uint8_t>((csum + n / 2) / n);
    }
  }
  return g.yuv;
}

// A pixel on a depth edge takes one side's depth, never a mix of both (a mix is a depth no
// surface has: a halo in the blur). The side is the group of neighbours within smooth_q8() of one
// another with the most weight; the pixel takes that group's weighted mean.
uint16_t DepthUpsampler::EdgeValue(const uint32_t* w, const int32_t* d, uint16_t fallback) const {
  uint32_t best_w = 0;
  int32_t best = -1;
  for (int32_t j = 0; j < 9; ++j) {
    uint32_t sum = 0;
    for (int32_t i = 0; i < 9; ++i) sum += Abs(d[i] - d[j]) <= smooth_q8_ ? w[i] : 0;
    if (sum > best_w) best_w = sum, best = j;
  }
  if (best < 0) return fallback;
  // Weights Q8 <= 256: at most 9 * 256 * 65535 < 2^32.
  uint32_t sum_wd = 0;
  for (int32_t i = 0; i < 9; ++i)
    if (Abs(d[i] - d[best]) <= smooth_q8_) sum_wd += w[i] * static_cast<uint32_t>(d[i]);
  return static_cast<uint16_t>((sum_wd + best_w / 2) / best_w);
}

uint16_t DepthUpsampler::MeanValue(const uint32_t* w, const int32_t* d, uint16_t fallback) {
  // Weights Q8 <= 256: at most 9 * 256 * 65535 < 2^32.
  uint32_t sum_w = 0, sum_wd = 0;
  for (int32_t i = 0; i < 9; ++i) sum_w += w[i], sum_wd += w[i] * static_cast<uint32_t>(d[i]);
  return sum_w ? static_cast<uint16_t>((sum_wd + sum_w / 2) / sum_w) : fallback;
}

const uint8_t* DepthUpsampler::UniformRow(Cache& c, int32_t wy) {
  uint8_t* uniform = c.uniform;
  if (c.uniform_tag == wy) return uniform;
  c.uniform_tag = wy;
  const uint16_t* rows[3] = {disp_.Row(Max(wy - 1, 0)), disp_.Row(wy),
                             disp_.Row(Min(wy + 1, wh_ - 1))};
  for (int32_t wx = 0; wx < ww_; ++wx) {
    const int32_t l = Max(wx - 1, 0), r = Min(wx + 1, ww_ - 1);
    int32_t lo = 65535, hi = 0;
    for (int32_t i = 0; i < 3; ++i) {
      for (int32_t q : {l, wx, r}) lo = Min(lo, rows[i][q]), hi = Max(hi, rows[i][q]);
    }
    uniform[wx] = hi == lo ? kFlat : (hi - lo <= smooth_q8_ ? kSmooth : kEdge);
  }
  return uniform;
}

void DepthUpsampler::Row(int32_t y, uint16_t* out, int32_t worker, int32_t step, int32_t phase) {
  Cache& c = cache_[worker];
  const int32_t s = scale_;
  const int32_t wy = Min(y / s, wh_ - 1);
  const int32_t fy = Min(y - wy * s, s - 1);
  const int32_t wys[3] = {Max(wy - 1, 0), wy, Min(wy + 1, wh_ - 1)};
  const uint8_t* guide[3] = {GuideRow(c, wys[0]), GuideRow(c, wys[1]), GuideRow(c, wys[2])};
  const uint16_t* disp[3] = {disp_.Row(wys[0]), disp_.Row(wys[1]), disp_.Row(wys[2])};
  const uint8_t* sure[3] = {nullptr, nullptr, nullptr};
  if (confidence_.data != nullptr) {
    for (int32_t i = 0; i < 3; ++i) sure[i] = confidence_.Row(wys[i]);
  }
  const uint8_t* uniform = UniformRow(c, wy);
  const uint8_t* luma = ref_.planes[0].Row(y);
  const uint8_t* cb = ref_.planes[1].Row(y / 2);
  const uint8_t* cr = ref_.planes[2].Row(y / 2);
  const uint16_t* wsy = spatial_q8_ + fy * 3;
  // Block by block: a block whose 3x3 neighbourhood agrees is a plain fill.
  for (int32_t wx = 0; wx < ww_; ++wx) {
    const int32_t x0 = wx * s, x1 = wx + 1 == ww_ ? width_ : x0 + s;
    // The block's first column on the lattice phase + k * step.
    const int32_t xs = x0 <= phase ? phase : phase + (x0 - phase + step - 1) / step * step;
    if (uniform[wx] == kFlat) {
      for (int32_t x = xs; x < x1; x += step) out[(x - phase) / step] = disp[1][wx];
      continue;
    }
    const int32_t qx[3] = {Max(wx - 1, 0), wx, Min(wx + 1, ww_ - 1)};
    if (uniform[wx] == kSmooth) {
      // A smooth surface (a slanted plane): spatial weights only, so image texture cannot
      // ripple its depth. Rows are combined once per block.
      uint32_t col[3] = {0, 0, 0}, wy_sum = 0;
      for (int32_t oy = 0; oy < 3; ++oy) {
        wy_sum += wsy[oy];
        for (int32_t ox = 0; ox < 3; ++ox) col[ox] += wsy[oy] * disp[oy][qx[ox]];
      }
      for (int32_t x = xs; x < x1; x += step) {
        const uint16_t* wsx = spatial_q8_ + Min(x - x0, s - 1) * 3;
        // col < 3 * 256 * 65535; times a Q8 weight it needs 64 bits.
        const uint64_t num =
            uint64_t{wsx[0]} * col[0] + uint64_t{wsx[1]} * col[1] + uint64_t{wsx[2]} * col[2];
        const uint64_t den = uint64_t{wy_sum} * (wsx[0] + wsx[1] + wsx[2]);
        out[(x - phase) / step] = static_cast<uint16_t>((num + den / 2) / den);
      }
      continue;
    }
    for (int32_t x = xs; x < x1; x += step) {
      const uint16_t* wsx = spatial_q8_ + Min(x - x0, s - 1) * 3;
      const int32_t py = luma[x], pb = cb[x / 2], pr = cr[x / 2];
      uint32_t w[9];
      int32_t d[9];
      for (int32_t oy = 0; oy < 3; ++oy) {
        const uint8_t* g = guide[oy];
        for (int32_t ox = 0; ox < 3; ++ox) {
          const int32_t q = qx[ox];
          const int32_t dist = Abs(py - g[q]) + Abs(pb - g[ww_ + q]) + Abs(pr - g[2 * ww_ + q]);
          w[oy * 3 + ox] = ((wsy[oy] * wsx[ox]) >> 8) * range_q8_[dist] >> 8;
          if (sure[oy] != nullptr)
            w[oy * 3 + ox] = w[oy * 3 + ox] * (sure[oy][q] + kConfidenceFloor) >> 8;
          d[oy * 3 + ox] = disp[oy][q];
        }
      }
      out[(x - phase) / step] =
          one_side_ ? EdgeValue(w, d, disp[1][wx]) : MeanValue(w, d, disp[1][wx]);
    }
  }
}

}  // namespace lb
