// Layered compositing of one plane group (luma, or the two chroma planes) strip by strip.
//
// Every pixel belongs to two neighbouring depth layers with weights that sum to 1 (Q8), so a
// slanted surface blurs smoothly. Layers are composited back to front (far to near): each layer's
// premultiplied colour and coverage (alpha) are blurred by its aperture kernel and laid over what
// is behind, then the colour is divided by the accumulated alpha. So a blurred foreground spreads
// over the background; a sharp foreground stays in its own layer and does not bleed; and the
// background's hole behind an object is renormalised from its visible pixels instead of glowing.
//
// Memory: a ring of rows (signed radius and boosted colour per pixel) sized strip + 2 * largest
// kernel half, and one layer's row prefix sums for one strip's window; nothing at full size.
// Fixed point: colour value v (int16, Y * gain or (C - 128) * gain), layer weight a (Q8);
// prefix of c = (v * a) >> shift in uint32 (wrapping, only differences are used, each below
// 2^31); a kernel row's term w * span in int32 (shift chosen so it cannot overflow); the
// per-pixel sum in int64; the layer's colour and alpha normalised to Q16; compositing in Q16.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/arena.h"
#include "algo/core/image.h"
#include "algo/render/aperture.h"

namespace lb {

class LayerPlane {
 public:
  static constexpr int32_t kMaxChannels = 2;

  // `sub` is 1 for luma, 2 for chroma; `layers` the number of depth layers; `radii` the number of
  // distinct kernel radii; `max_half` the largest kernel half at this plane's scale.
  void Carve(Arena& arena, int32_t width, int32_t height, int32_t channels, int32_t strip_rows,
             int32_t max_half, int32_t layers, int32_t radii);

  // Begin-time: kernel i blurs by radius_px[i] (this plane's px); `shift` scales c (see above).
  void SetKernel(int32_t i, const ApertureShape& shape, float radius_px);
  void Begin(int32_t shift) { shift_ = shift, next_row_ = 0; }

  // The ring row for plane row y, to be filled by the caller: signed radius Q4 and values.
  int16_t* RadiusRow(int32_t y) { return ring_s_ + Slot(y) * static_cast<ptrdiff_t>(width_); }
  int16_t* ValueRow(int32_t y, int32_t ch) {
    return ring_v_ + (Slot(y) * channels_ + ch) * static_cast<ptrdiff_t>(width_);
  }
  // After filling row y: records which columns each layer covers. `layer_of` maps a radius
  // (Q4 + offset) to (first layer << 8 | weight of the next layer Q8).
  void CommitRow(int32_t y, const uint16_t* layer_of, int32_t offset);
  int32_t next_row() const { return next_row_; }
  int32_t ring_rows() const { return ring_rows_; }

  // Renders plane rows [y0, y0 + n) of every layer (back to front), `radius_of_layer[k]` being
  // the kernel index of layer k; writes 8-bit results (value + bias) into `dst`.
  void RenderStrip(int32_t y0, int32_t n, const uint16_t* layer_of, int32_t offset,
                   const int32_t* radius_of_layer, int32_t bias, ImageU8* dst);

 private:
  int32_t Slot(int32_t y) const { return y % ring_rows_; }
  void RenderLayer(int32_t k, int32_t y0, int32_t n, const uint16_t* layer_of, int32_t offset,
                   int32_t radius_index);

  int32_t width_ = 0, height_ = 0, channels_ = 1, strip_rows_ = 0, max_half_ = 0;
  int32_t layers_ = 0, radii_ = 0, ring_rows_ = 0, pitch_ = 0, shift_ = 0, next_row_ = 0;
  int16_t* ring_s_ = nullptr;       // ring_rows x width: signed radius, Q4 full-resolution px
  int16_t* ring_v_ = nullptr;       // ring_rows x channels x width
  int16_t* ranges_ = nullptr;       // ring_rows x layers x 2: first and last column of the layer
  uint32_t* prefix_ = nullptr;      // (strip_rows + 2 max_half) x (channels + 1) x pitch
  uint8_t* active_ = nullptr;       // per window row: the layer has pixels there
  int64_t* acc_ = nullptr;          // (channels + 1) x width
  int32_t* out_ = nullptr;          // strip_rows x (channels + 1) x width, premultiplied Q16
  KernelRow* kernels_ = nullptr;    // radii x (2 max_half + 1)
  int32_t* halves_ = nullptr;       // per kernel
  uint64_t* reciprocal_ = nullptr;  // per kernel: 2^40 / total weight
};

}  // namespace lb
