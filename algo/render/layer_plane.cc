#include "algo/render/layer_plane.h"

#include "algo/core/int_math.h"
#include "algo/render/layer_rows.h"

namespace lb {
namespace {

struct KernelPlan {
  float radius;
  int32_t level, half;
};

KernelPlan PlanKernel(int32_t radius_q4, int32_t sub) {
  KernelPlan k;
  k.radius = static_cast<float>(radius_q4) / (16.0f * static_cast<float>(sub));
  k.level = 0;
  while (k.level < LayerPlane::kMaxLevel &&
         k.radius > LayerPlane::kLevelRadius * static_cast<float>(1 << k.level)) {
    ++k.level;
  }
  k.half = KernelHalf(k.radius / static_cast<float>(1 << k.level));
  return k;
}

// Rows a kernel reads beyond the rows it renders: its half, plus the bilinear tap and the box
// of a reduced level.
int32_t KernelReach(const KernelPlan& k) { return k.level == 0 ? k.half : (k.half + 2) << k.level; }

}  // namespace

int32_t LayerPlane::Reach(int32_t sub, const int32_t* radii_q4, int32_t radii) {
  int32_t reach = 0;
  for (int32_t i = 0; i < radii; ++i) reach = Max(reach, KernelReach(PlanKernel(radii_q4[i], sub)));
  return reach;
}

Status LayerPlane::Carve(Arena& arena, int32_t width, int32_t height, int32_t channels,
                         int32_t strip_rows, int32_t sub, const int32_t* radii_q4, int32_t radii,
                         int32_t layers, int32_t extra_rows, int32_t workers) {
  // radius_, level_, half_ and reciprocal_ hold kMaxKernels entries.
  if (radii < 1 || radii > kMaxKernels) {
    return Status(Code::kInvalidArgument, "layer plane: %d blur radii outside 1..%d", radii,
                  kMaxKernels);
  }
  if (layers < 1 || layers > 2 * kMaxKernels - 1) {
    return Status(Code::kInvalidArgument, "layer plane: %d depth layers outside 1..%d", layers,
                  2 * kMaxKernels - 1);
  }
  if (workers < 1 || workers > kMaxWorkers) {
    return Status(Code::kInvalidArgument, "layer plane: %d workers outside 1..%d", workers,
                  kMaxWorkers);
  }
  if (channels < 1 || channels > 2) {
    return Status(Code::kInvalidArgument, "layer plane: %d channels (1 or 2)", channels);
  }
  rows_ = &layer_rows::BestKernels();
  width_ = width, height_ = height, channels_ = channels, workers_ = workers;
  layers_ = layers, radii_ = radii;
  int32_t max_half = 0;
  window_rows_ = 1, low_rows_ = 1, reach_ = 0;
  for (int32_t i = 0; i < radii; ++i) {
    const KernelPlan k = PlanKernel(radii_q4[i], sub);
    radius_[i] = k.radius, level_[i] = k.level, half_[i] = k.half;
    max_half = Max(max_half, k.half);
    reach_ = Max(reach_, KernelReach(k));
    const int32_t rows = k.level == 0 ? strip_rows : (strip_rows >> k.level) + 3;
    window_rows_ = Max(window_rows_, rows + 2 * k.half);
    if (k.level > 0) low_rows_ = Max(low_rows_, rows);
  }
  kernel_rows_ = 2 * max_half + 1;
  // Rows [y0 - reach, y0 + workers strips + reach) plus the caller's look-ahead and slack.
  ring_rows_ = workers * strip_rows + 2 * reach_ + extra_rows + 4;
  pitch_ = static_cast<int32_t>(Arena::RoundUp((width + 2 * max_half + 8) * sizeof(uint32_t)) /
                                sizeof(uint32_t));
  const size_t ring = static_cast<size_t>(ring_rows_) * width;
  const size_t planes = static_cast<size_t>(channels) + 1;
  ring_s_ = arena.Allocate<int16_t>(ring);
  ring_v_ = arena.Allocate<int16_t>(ring * channels);
  tile_shift_ = 6;
  while ((width + (1 << tile_shift_) - 1) >> tile_shift_ > 64) ++tile_shift_;
  tiles_ = arena.Allocate<uint64_t>(static_cast<size_t>(ring_rows_) * layers);
  ring_tag_ = arena.Allocate<int32_t>(static_cast<size_t>(ring_rows_));
  pure_ = arena.Allocate<uint64_t>(static_cast<size_t>(ring_rows_) * layers);
  for (int32_t i = 0; i < workers; ++i) {
    Scratch& s = scratch_[i];
    s.prefix = arena.Allocate<uint32_t>(static_cast<size_t>(window_rows_) * planes * pitch_);
    s.active = arena.Allocate<uint8_t>(static_cast<size_t>(window_rows_));
    s.box = arena.Allocate<int32_t>(planes * pitch_);
    s.acc = arena.Allocate<uint32_t>(planes * pitch_);
    s.layer = arena.Allocate<int32_t>(static_cast<size_t>(low_rows_) * planes * pitch_);
    s.out = arena.Allocate<int32_t>(static_cast<size_t>(strip_rows) * planes * width);
  }
  kernels_ = arena.Allocate<KernelRow>(static_cast<size_t>(radii) * kernel_rows_);
  int32_t max_level = 0;
  for (int32_t i = 0; i < radii; ++i) max_level = Max(max_level, level_[i]);
  for (int32_t l = 0; l <= kMaxLevel; ++l) {
    frac_[l] =
        l >= 1 && l <= max_level ? arena.Allocate<uint8_t>(static_cast<size_t>(width)) : nullptr;
  }
  return Status::Ok();
}

void LayerPlane::Begin(const ApertureShape& shape, int32_t shift) {
  // Column l of a reduced level samples the low-res row at (2x + 1 - f) / 2f, Q8. Filled here,
  // not at Carve: the pipeline lends the render's memory to the depth stages between renders.
  for (int32_t l = 1; l <= kMaxLevel; ++l) {
    if (frac_[l] == nullptr) continue;
    for (int32_t x = 0; x < width_; ++x) {
      const int32_t u = ((2 * x + 1 - (1 << l)) * 128) >> l;
      frac_[l][x] = static_cast<uint8_t>(u & 255);
    }
  }
  for (int32_t i = 0; i < radii_; ++i) {
    const float r = radius_[i] / static_cast<float>(1 << level_[i]);
    const uint32_t total = BuildKernel(shape, r, half_[i], kernels_ + i * kernel_rows_);
    reciprocal_[i] = (uint64_t{1} << 40) / total;
  }
  shift_ = shift;
  next_row_ = 0;
  for (int32_t i = 0; i < workers_; ++i) scratch_[i].stale = false;
  for (int32_t i = 0; i < ring_rows_; ++i) ring_tag_[i] = -1;
}

bool LayerPlane::Holds(int32_t y) const { return ring_tag_[Slot(y)] == y; }

bool LayerPlane::stale() const {
  bool any = false;
  for (int32_t i = 0; i < workers_; ++i) any = any || scratch_[i].stale;
  return any;
}

void LayerPlane::CommitRow(int32_t y, const uint16_t* layer_of, int32_t offset) {
  CommitRowShared(y, layer_of, offset);
  next_row_ = y + 1;
}

void LayerPlane::CommitRowShared(int32_t y, const uint16_t* layer_of, int32_t offset) {
  ring_tag_[Slot(y)] = y;
  uint64_t* tiles = tiles_ + Slot(y) * layers_;
  uint64_t* pure = pure_ + Slot(y) * layers_;
  for (int32_t k = 0; k < layers_; ++k) tiles[k] = 0, pure[k] = 0;
  const int16_t* s = RadiusRow(y);
  for (int32_t x0 = 0, t = 0; x0 < width_; x0 += 1 << tile_shift_, ++t) {
    const int32_t x1 = Min(width_, x0 + (1 << tile_shift_));
    const uint64_t bit = uint64_t{1} << t;
    // The layers an entry marks: its first, and the next when it has weight there. Neighbouring
    // pixels mostly mark the same (their weights differ, their layers seldom), so only a change
    // marks again: marking every pixel made a chain of loads and stores on the same word.
    auto marks = [](uint16_t e) { return ((e >> 8) << 1) | ((e & 255) != 0 ? 1 : 0); };
    const uint16_t e0 = layer_of[s[x0] + offset];
    int32_t last = -1, runs = 0;
    for (int32_t x = x0; x < x1; ++x) {
      const uint16_t e = layer_of[s[x] + offset];
      const int32_t m = marks(e);
      if (m == last) continue;
      ++runs;
      last = m;
      tiles[e >> 8] |= bit;
      if (e & 255) tiles[(e >> 8) + 1] |= bit;
    }
    // Every pixel of the tile wholly in one layer: all mark e0's layer alone.
    if (runs == 1 && (e0 & 255) == 0) pure[e0 >> 8] |= bit;
  }
}

uint64_t LayerPlane::Tiles(Scratch& s, int32_t k, int32_t y0, int32_t y1) const {
  uint64_t t = 0;
  for (int32_t j = Max(0, y0); j < Min(height_, y1); ++j) {
    t |= tiles_[Slot(j) * layers_ + k];
    s.stale = s.stale || ring_tag_[Slot(j)] != j;
  }
  return t;
}

void LayerPlane::BuildPrefix(Scratch& s, int32_t k, int32_t level, int32_t h, int32_t jlo,
                             int32_t jhi, int32_t x0, int32_t x1, uint64_t run, int32_t base,
                             const uint16_t* layer_of, int32_t offset) const {
  if (channels_ == 1) {
    BuildPrefixT<1>(s, k, level, h, jlo, jhi, x0, x1, run, base, layer_of, offset);
  } else {
    BuildPrefixT<2>(s, k, level, h, jlo, jhi, x0, x1, run, base, layer_of, offset);
  }
}

template <int C>
void LayerPlane::BuildPrefixT(Scratch& sc, int32_t k, int32_t level, int32_t h, int32_t jlo,
                              int32_t jhi, int32_t x0, int32_t x1, uint64_t run, int32_t base,
                              const uint16_t* layer_of, int32_t offset) const {
  const int32_t pad = pitch_ - width_ - (pitch_ - width_) / 2;  // room for indices below 0
  const int32_t q0 = x0 >> level, q1 = x1 >> level;             // the run's columns at this level
  const int32_t shift = shift_;
  const int32_t tile = 1 << tile_shift_;
  for (int32_t m = jlo; m < jhi; ++m) {
    uint8_t& active = sc.active[m - base];
    active = (Tiles(sc, k, m << level, (m + 1) << level) & run) != 0;
    if (!active) continue;
    uint32_t* p[C + 1];
    for (int32_t c = 0; c <= C; ++c) {
      p[c] = sc.prefix + ((m - base) * (C + 1) + c) * static_cast<ptrdiff_t>(pitch_) + pad;
      for (int32_t x = q0 - h; x <= q0; ++x) p[c][x] = 0;
    }
    if (level == 0) {
      const int16_t* s = RadiusRow(m);
      const int16_t* v[C];
      for (int32_t c = 0; c < C; ++c) v[c] = ValueRow(m, c);
      const uint64_t any = tiles_[Slot(m) * layers_ + k], pure = pure_[Slot(m) * layers_ + k];
      for (int32_t t0 = x0; t0 <= x1; t0 += tile) {
        const int32_t t1 = Min(x1, t0 + tile - 1);
        const uint64_t bit = uint64_t{1} << (t0 >> tile_shift_);
        if (!(any & bit)) {  // the layer is absent from this tile: the prefix stays flat
          layer_rows::FlatPrefixRowC<C>(t0, t1, p);
        } else if (pure & bit) {  // wholly in the layer: weight 256 everywhere
          layer_rows::PurePrefixRowC<C>(v, shift, t0, t1, p);
        } else {
          rows_->weighted_prefix[C - 1](v, s, layer_of, offset, k, shift, t0, t1, p);
        }
      }
    } else {
      // Box means over 2^level x 2^level pixels of the layer's values and weights; each box's
      // row is summed in registers and added once.
      int32_t* box[C + 1];
      for (int32_t c = 0; c <= C; ++c) {
        box[c] = sc.box + c * static_cast<ptrdiff_t>(pitch_);
        for (int32_t i = q0; i <= q1; ++i) box[c][i] = 0;
      }
      const int32_t end = Min(height_, (m + 1) << level);
      for (int32_t j = m << level; j < end; ++j) {
        const uint64_t any = tiles_[Slot(j) * layers_ + k] & run;
        if (!any) continue;
        const uint64_t pure = pure_[Slot(j) * layers_ + k];
        const int16_t* s = RadiusRow(j);
        const int16_t* v[C];
        for (int32_t c = 0; c < C; ++c) v[c] = ValueRow(j, c);
        for (int32_t t0 = x0; t0 <= x1; t0 += tile) {
          const uint64_t bit = uint64_t{1} << (t0 >> tile_shift_);
          if (!(any & bit)) continue;
          const int32_t t1 = Min(x1, t0 + tile - 1);
          if ((pure & bit) && shift <= 8) {
            rows_->pure_box[C - 1](v, shift, level, t0, t1, box);
          } else {
            rows_->weighted_box[C - 1](v, s, layer_of, offset, k, shift, level, t0, t1, box);
          }
        }
      }
      for (int32_t c = 0; c <= C; ++c) rows_->box_prefix(box[c], level, q0, q1, p[c]);
    }
    // Beyond the run the prefix stays flat: the kernel reads up to `h` + 1 columns outside.
    for (int32_t c = 0; c <= C; ++c) {
      for (int32_t x = q1 + 2; x <= q1 + h + 1; ++x) p[c][x] = p[c][q1 + 1];
    }
  }
}

void LayerPlane::GatherNormalise(Scratch& s, int32_t kernel, int32_t m, int32_t jlo, int32_t jhi,
                                 int32_t base, int32_t x0, int32_t x1, int32_t* layer,
                                 ptrdiff_t stride) const {
  const int32_t planes = channels_ + 1;
  const int32_t pad = pitch_ - width_ - (pitch_ - width_) / 2;
  const int32_t h = half_[kernel];
  const KernelRow* rows = kernels_ + kernel * kernel_rows_;
  for (int32_t c = 0; c < planes; ++c) {
    uint32_t* acc = s.acc + c * static_cast<ptrdiff_t>(pitch_);
    for (int32_t x = x0; x <= x1; ++x) acc[x] = 0;
  }
  for (int32_t dy = -h; dy <= h; ++dy) {
    const int32_t j = m + dy;
    if (j < jlo || j >= jhi || !s.active[j - base]) continue;
    const KernelRow& kr = rows[dy + h];
    if (kr.w == 0 && kr.wl == 0 && kr.wr == 0) continue;
    for (int32_t c = 0; c < planes; ++c) {
      const uint32_t* p =
          s.prefix + ((j - base) * planes + c) * static_cast<ptrdiff_t>(pitch_) + pad;
      rows_->gather(p, kr, s.acc + c * static_cast<ptrdiff_t>(pitch_), x0, x1);
    }
  }
  // alpha = acc / (total * 256) in Q16 (rec = 2^40 / total); colour likewise, undoing the shift.
  const uint64_t rec = reciprocal_[kernel];
  rows_->normalise_alpha(s.acc + channels_ * static_cast<ptrdiff_t>(pitch_), rec, x0, x1,
                         layer + channels_ * stride);
  for (int32_t c = 0; c < channels_; ++c) {
    rows_->normalise_colour(s.acc + c * static_cast<ptrdiff_t>(pitch_), rec, shift_, x0, x1,
                            layer + c * stride);
  }
}

void LayerPlane::Composite(const int32_t* layer, ptrdiff_t stride, int32_t x0, int32_t x1,
                           int32_t* out) const {
  const int32_t* alpha = layer + channels_ * stride;
  for (int32_t c = 0; c <= channels_; ++c) {
    rows_->composite(out + c * static_cast<ptrdiff_t>(width_), layer + c * stride, alpha, x0, x1);
  }
}

void LayerPlane::RenderLayer(Scratch& s, int32_t k, int32_t y0, int32_t n, const uint16_t* layer_of,
                             int32_t offset, int32_t i) const {
  const int32_t level = level_[i];
  const int32_t reach = level == 0 ? half_[i] : (half_[i] + 2) << level;
  uint64_t tiles = Tiles(s, k, y0 - reach, y0 + n + reach);
  if (!tiles) return;  // no pixel of this layer reaches the strip
  // Grow by the reach: a run of grown tiles holds every source pixel its outputs depend on.
  const int32_t count = (width_ + (1 << tile_shift_) - 1) >> tile_shift_;
  const uint64_t all = count == 64 ? ~uint64_t{0} : (uint64_t{1} << count) - 1;
  for (int32_t d = 0; d < ((reach + (1 << tile_shift_) - 1) >> tile_shift_); ++d) {
    tiles |= (tiles << 1) | (tiles >> 1);
  }
  tiles &= all;
  for (int32_t t = 0; t < count;) {
    if (!((tiles >> t) & 1)) {
      ++t;
      continue;
    }
    int32_t e = t;
    while (e + 1 < count && ((tiles >> (e + 1)) & 1)) ++e;
    const uint64_t run = (e - t + 1 == 64) ? ~uint64_t{0} : ((uint64_t{1} << (e - t + 1)) - 1) << t;
    RenderRun(s, k, y0, n, layer_of, offset, i, t << tile_shift_,
              Min(width_, (e + 1) << tile_shift_) - 1, run);
    t = e + 1;
  }
}

void LayerPlane::RenderRun(Scratch& sc, int32_t k, int32_t y0, int32_t n, const uint16_t* layer_of,
                           int32_t offset, int32_t i, int32_t x0, int32_t x1, uint64_t run) const {
  const int32_t level = level_[i], h = half_[i];
  const int32_t planes = channels_ + 1;
  const ptrdiff_t row_stride = planes * static_cast<ptrdiff_t>(width_);
  if (h == 0 && reciprocal_[i] == uint64_t{1} << 32) {
    // The in-focus layer (the identity kernel): its weight and value are the layer itself;
    // the same numbers the general path gives for a kernel of one cell of weight 256.
    for (int32_t y = y0; y < y0 + n; ++y) {
      const int16_t* s = RadiusRow(y);
      int32_t* alpha = sc.layer + channels_ * static_cast<ptrdiff_t>(pitch_);
      for (int32_t x = x0; x <= x1; ++x) {
        alpha[x] = layer_rows::LayerWeightQ8(layer_of[s[x] + offset], k) << 8;
      }
      for (int32_t c = 0; c < channels_; ++c) {
        const int16_t* v = ValueRow(y, c);
        int32_t* colour = sc.layer + c * static_cast<ptrdiff_t>(pitch_);
        for (int32_t x = x0; x <= x1; ++x) {
          colour[x] = ((v[x] * (alpha[x] >> 8)) >> shift_) * (1 << (8 + shift_));
        }
      }
      Composite(sc.layer, pitch_, x0, x1, sc.out + (y - y0) * row_stride);
    }
    return;
  }
  if (level == 0) {
    const int32_t jlo = Max(0, y0 - h), jhi = Min(height_, y0 + n + h);
    const int32_t base = y0 - h;
    BuildPrefix(sc, k, 0, h, jlo, jhi, x0, x1, run, base, layer_of, offset);
    for (int32_t y = y0; y < y0 + n; ++y) {
      GatherNormalise(sc, i, y, jlo, jhi, base, x0, x1, sc.layer, pitch_);
      Composite(sc.layer, pitch_, x0, x1, sc.out + (y - y0) * row_stride);
    }
    return;
  }
  // Reduced level: low-res row m covers plane rows [m f, m f + f); plane row y samples the
  // low-res image at (2y + 1 - f) / 2f, Q8.
  const int32_t f = 1 << level;
  const int32_t low_h = (height_ + f - 1) >> level;
  auto coord_q8 = [level, f](int32_t v) { return ((2 * v + 1 - f) * 128) >> level; };
  const int32_t m_first = Max(0, coord_q8(y0) >> 8);
  const int32_t m_last = Min(low_h - 1, (coord_q8(y0 + n - 1) >> 8) + 1);
  const int32_t jlo = Max(0, m_first - h), jhi = Min(low_h, m_last + 1 + h);
  const int32_t base = m_first - h;
  const int32_t q_lo = x0 >> level, q_hi = x1 >> level;
  BuildPrefix(sc, k, level, h, jlo, jhi, x0, x1, run, base, layer_of, offset);
  const ptrdiff_t low_stride = planes * static_cast<ptrdiff_t>(pitch_);
  for (int32_t m = m_first; m <= m_last; ++m) {
    GatherNormalise(sc, i, m, jlo, jhi, base, q_lo, q_hi, sc.layer + (m - m_first) * low_stride,
                    pitch_);
  }
  for (int32_t y = y0; y < y0 + n; ++y) {
    const int32_t uy = coord_q8(y);
    const int32_t ma = Clamp(uy >> 8, m_first, m_last), mb = Clamp((uy >> 8) + 1, m_first, m_last);
    const int64_t fy = uy & 255;
    const int32_t* ra = sc.layer + (ma - m_first) * low_stride;
    const int32_t* rb = sc.layer + (mb - m_first) * low_stride;
    // Separable: blend the two low-res rows (into the box row, edges replicated), then interpolate
    // each output column between its two taps.
    for (int32_t c = 0; c < planes; ++c) {
      const int32_t* a = ra + c * static_cast<ptrdiff_t>(pitch_);
      const int32_t* b = rb + c * static_cast<ptrdiff_t>(pitch_);
      rows_->blend(a, b, fy, q_lo, q_hi, sc.box + c * static_cast<ptrdiff_t>(pitch_) + 1);
    }
    int32_t* out = sc.out + (y - y0) * row_stride;
    rows_->lerp_composite[channels_ - 1](sc.box + 1, pitch_, frac_[level], level, x0, x1, out,
                                         width_);
  }
}

void LayerPlane::RenderStrip(int32_t worker, int32_t y0, int32_t n, const uint16_t* layer_of,
                             int32_t offset, const int32_t* radius_of_layer, int32_t bias,
                             ImageU8* dst) {
  Scratch& s = scratch_[worker];
  const int32_t planes = channels_ + 1;
  for (size_t i = 0; i < static_cast<size_t>(n) * planes * width_; ++i) s.out[i] = 0;
  for (int32_t k = 0; k < layers_; ++k) {
    RenderLayer(s, k, y0, n, layer_of, offset, radius_of_layer[k]);
  }
  for (int32_t y = y0; y < y0 + n; ++y) {
    const int32_t* out = s.out + (y - y0) * planes * static_cast<ptrdiff_t>(width_);
    const int32_t* out_a = out + channels_ * static_cast<ptrdiff_t>(width_);
    for (int32_t c = 0; c < channels_; ++c) {
      // A pixel always covers itself, so alpha is positive (ResolveRowC keeps a fallback).
      rows_->resolve(out + c * static_cast<ptrdiff_t>(width_), out_a, ValueRow(y, c), width_, bias,
                     dst[c].Row(y - y0));
    }
  }
}

}  // namespace lb
