#include "algo/render/layer_plane.h"

namespace lb {
namespace {

int32_t Min(int32_t a, int32_t b) { return a < b ? a : b; }
int32_t Max(int32_t a, int32_t b) { return a > b ? a : b; }

// Rounded signed division, den > 0 (half away from zero; the same on every platform).
int64_t RoundDiv(int64_t num, int64_t den) {
  return num >= 0 ? (num + den / 2) / den : -((-num + den / 2) / den);
}

// Adds one kernel row's weighted sums to acc[x0..x1]. p[i] is the row prefix up to column i.
// The plain C reference loop; it is written so compilers vectorise it.
void GatherRow(const uint32_t* p, const KernelRow& k, int64_t* acc, int32_t x0, int32_t x1) {
  const uint32_t* pa = p + k.left - 1;
  const uint32_t* pb = p + k.left;
  const uint32_t* pc = p + k.right + 1;
  const uint32_t* pd = p + k.right + 2;
  const int32_t w = k.w, wl = k.wl, wr = k.wr;
  for (int32_t x = x0; x <= x1; ++x) {
    const int32_t span = static_cast<int32_t>(pc[x] - pb[x]);
    const int32_t left = static_cast<int32_t>(pb[x] - pa[x]);
    const int32_t right = static_cast<int32_t>(pd[x] - pc[x]);
    acc[x] += w * span + wl * left + wr * right;
  }
}

}  // namespace

void LayerPlane::Carve(Arena& arena, int32_t width, int32_t height, int32_t channels,
                       int32_t strip_rows, int32_t max_half, int32_t layers, int32_t radii) {
  width_ = width, height_ = height, channels_ = channels, strip_rows_ = strip_rows;
  max_half_ = max_half, layers_ = layers, radii_ = radii;
  // Rows [y0 - half, y0 + strip + half) plus two rows of look-ahead for the chroma of the next
  // strip, plus slack so a row is never overwritten while a strip reads it.
  ring_rows_ = strip_rows + 2 * max_half + 4;
  pitch_ = static_cast<int32_t>(Arena::RoundUp((width + 2 * max_half + 4) * sizeof(uint32_t)) /
                                sizeof(uint32_t));
  const size_t ring = static_cast<size_t>(ring_rows_) * width;
  const size_t window = static_cast<size_t>(strip_rows + 2 * max_half);
  const size_t planes = static_cast<size_t>(channels + 1);
  ring_s_ = arena.Allocate<int16_t>(ring);
  ring_v_ = arena.Allocate<int16_t>(ring * channels);
  ranges_ = arena.Allocate<int16_t>(static_cast<size_t>(ring_rows_) * layers * 2);
  prefix_ = arena.Allocate<uint32_t>(window * planes * pitch_);
  active_ = arena.Allocate<uint8_t>(window);
  acc_ = arena.Allocate<int64_t>(planes * width);
  out_ = arena.Allocate<int32_t>(static_cast<size_t>(strip_rows) * planes * width);
  kernels_ = arena.Allocate<KernelRow>(static_cast<size_t>(radii) * (2 * max_half + 1));
  halves_ = arena.Allocate<int32_t>(static_cast<size_t>(radii));
  reciprocal_ = arena.Allocate<uint64_t>(static_cast<size_t>(radii));
}

void LayerPlane::SetKernel(int32_t i, const ApertureShape& shape, float radius_px) {
  int32_t half = KernelHalf(radius_px);
  half = half > max_half_ ? max_half_ : half;
  halves_[i] = half;
  const uint32_t total = BuildKernel(shape, radius_px, half, kernels_ + i * (2 * max_half_ + 1));
  reciprocal_[i] = (uint64_t{1} << 40) / total;
}

void LayerPlane::CommitRow(int32_t y, const uint16_t* layer_of, int32_t offset) {
  int16_t* range = ranges_ + Slot(y) * layers_ * 2;
  for (int32_t k = 0; k < layers_; ++k) range[2 * k] = INT16_MAX, range[2 * k + 1] = -1;
  const int16_t* s = RadiusRow(y);
  for (int32_t x = 0; x < width_; ++x) {
    const uint16_t e = layer_of[s[x] + offset];
    const int32_t k = e >> 8;
    int16_t* r = range + 2 * k;
    if (r[0] > x) r[0] = static_cast<int16_t>(x);
    r[1] = static_cast<int16_t>(x);
    if (e & 255) {
      if (r[2] > x) r[2] = static_cast<int16_t>(x);
      r[3] = static_cast<int16_t>(x);
    }
  }
  next_row_ = y + 1;
}

void LayerPlane::RenderLayer(int32_t k, int32_t y0, int32_t n, const uint16_t* layer_of,
                             int32_t offset, int32_t ri) {
  const int32_t h = halves_[ri];
  const KernelRow* kernel = kernels_ + ri * (2 * max_half_ + 1);
  const int32_t jlo = Max(0, y0 - h), jhi = Min(height_, y0 + n + h);
  int32_t lo = width_, hi = -1;
  for (int32_t j = jlo; j < jhi; ++j) {
    const int16_t* r = ranges_ + (Slot(j) * layers_ + k) * 2;
    lo = Min(lo, r[0]);
    hi = Max(hi, r[1]);
  }
  if (hi < lo) return;  // no pixel of this layer reaches the strip
  const int32_t out_lo = Max(0, lo - h), out_hi = Min(width_ - 1, hi + h);
  const int32_t p_lo = out_lo - h, p_hi = out_hi + h + 2;
  const int32_t planes = channels_ + 1;
  const int32_t base = y0 - max_half_;  // window row 0
  const int32_t pad = max_half_ + 1;

  // Row prefix sums of the layer's premultiplied values and of its weight (alpha).
  for (int32_t j = jlo; j < jhi; ++j) {
    const int16_t* r = ranges_ + (Slot(j) * layers_ + k) * 2;
    uint8_t& active = active_[j - base];
    active = r[1] >= r[0];
    if (!active) continue;
    const int32_t rlo = r[0], rhi = r[1];
    const int16_t* s = RadiusRow(j);
    uint32_t* p[kMaxChannels + 1];
    const int16_t* v[kMaxChannels];
    for (int32_t c = 0; c < planes; ++c) {
      p[c] = prefix_ + ((j - base) * planes + c) * static_cast<ptrdiff_t>(pitch_) + pad;
      if (c < channels_) v[c] = ValueRow(j, c);
    }
    for (int32_t c = 0; c < planes; ++c) {
      for (int32_t i = p_lo; i <= rlo; ++i) p[c][i] = 0;
    }
    for (int32_t x = rlo; x <= rhi; ++x) {
      const uint16_t e = layer_of[s[x] + offset];
      const int32_t first = e >> 8, frac = e & 255;
      const int32_t a = first == k ? 256 - frac : (first + 1 == k ? frac : 0);
      for (int32_t c = 0; c < channels_; ++c) {
        p[c][x + 1] = p[c][x] + static_cast<uint32_t>((v[c][x] * a) >> shift_);
      }
      p[channels_][x + 1] = p[channels_][x] + static_cast<uint32_t>(a);
    }
    for (int32_t c = 0; c < planes; ++c) {
      const uint32_t last = p[c][rhi + 1];
      for (int32_t i = rhi + 2; i <= p_hi; ++i) p[c][i] = last;
    }
  }

  // Gather each output row, normalise the layer to Q16 and lay it over what is behind.
  const uint64_t rec = reciprocal_[ri];
  for (int32_t y = y0; y < y0 + n; ++y) {
    for (int32_t c = 0; c < planes; ++c) {
      int64_t* acc = acc_ + c * static_cast<ptrdiff_t>(width_);
      for (int32_t x = out_lo; x <= out_hi; ++x) acc[x] = 0;
    }
    for (int32_t dy = -h; dy <= h; ++dy) {
      const int32_t j = y + dy;
      if (j < jlo || j >= jhi || !active_[j - base]) continue;
      const KernelRow& kr = kernel[dy + h];
      if (kr.w == 0 && kr.wl == 0 && kr.wr == 0) continue;
      for (int32_t c = 0; c < planes; ++c) {
        const uint32_t* p =
            prefix_ + ((j - base) * planes + c) * static_cast<ptrdiff_t>(pitch_) + pad;
        GatherRow(p, kr, acc_ + c * static_cast<ptrdiff_t>(width_), out_lo, out_hi);
      }
    }
    int32_t* out = out_ + (y - y0) * planes * static_cast<ptrdiff_t>(width_);
    const int64_t* acc_a = acc_ + channels_ * static_cast<ptrdiff_t>(width_);
    int32_t* out_a = out + channels_ * static_cast<ptrdiff_t>(width_);
    for (int32_t x = out_lo; x <= out_hi; ++x) {
      // alpha = acc / (total * 256) in Q16; acc <= total * 256, rec = 2^40 / total.
      int64_t alpha = static_cast<int64_t>((static_cast<uint64_t>(acc_a[x]) * rec) >> 32);
      alpha = alpha > 65536 ? 65536 : alpha;
      const int64_t keep = 65536 - alpha;
      for (int32_t c = 0; c < channels_; ++c) {
        const int64_t* acc = acc_ + c * static_cast<ptrdiff_t>(width_);
        int32_t* o = out + c * static_cast<ptrdiff_t>(width_);
        const int64_t colour = (acc[x] * static_cast<int64_t>(rec)) >> (32 - shift_);
        o[x] = static_cast<int32_t>(((o[x] * keep + 32768) >> 16) + colour);
      }
      out_a[x] = static_cast<int32_t>(((out_a[x] * keep + 32768) >> 16) + alpha);
    }
  }
}

void LayerPlane::RenderStrip(int32_t y0, int32_t n, const uint16_t* layer_of, int32_t offset,
                             const int32_t* radius_of_layer, int32_t bias, ImageU8* dst) {
  const int32_t planes = channels_ + 1;
  for (size_t i = 0; i < static_cast<size_t>(n) * planes * width_; ++i) out_[i] = 0;
  for (int32_t k = 0; k < layers_; ++k) {
    RenderLayer(k, y0, n, layer_of, offset, radius_of_layer[k]);
  }
  for (int32_t y = y0; y < y0 + n; ++y) {
    const int32_t* out = out_ + (y - y0) * planes * static_cast<ptrdiff_t>(width_);
    const int32_t* out_a = out + channels_ * static_cast<ptrdiff_t>(width_);
    for (int32_t c = 0; c < channels_; ++c) {
      const int32_t* o = out + c * static_cast<ptrdiff_t>(width_);
      const int16_t* v = ValueRow(y, c);
      uint8_t* d = dst[c].Row(y - y0);
      for (int32_t x = 0; x < width_; ++x) {
        // A pixel always covers itself, so alpha is positive; the fallback is for safety.
        const int64_t value = out_a[x] > 0 ? RoundDiv(o[x], out_a[x]) : v[x];
        const int64_t b = value + bias;
        d[x] = static_cast<uint8_t>(b < 0 ? 0 : (b > 255 ? 255 : b));
      }
    }
  }
}

}  // namespace lb
