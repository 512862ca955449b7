// Layered compositing of one plane group (luma, or the two chroma planes) strip by strip.
//
// Every pixel belongs to two neighbouring depth layers with weights that sum to 1 (Q8), so a
// slanted surface blurs smoothly. Layers are composited back to front (far to near): each layer's
// premultiplied colour and coverage (alpha) are blurred by its aperture kernel and laid over what
// is behind, then the colour is divided by the accumulated alpha. So a blurred foreground spreads
// over the background; a sharp foreground stays in its own layer and does not bleed; and the
// background's hole behind an object is renormalised from its visible pixels instead of glowing.
//
// Speed: a kernel row is a span read from row prefix sums (cost per pixel ~ kernel height), and
// a layer whose radius exceeds kLevelRadius is blurred at 1/2, 1/4 .. resolution (box-averaged
// colour and coverage, kernel scaled down, result upsampled bilinearly): a large blur has no fine
// detail to lose, and its cost per output pixel stays about constant. Layers that have no pixel
// near a strip are skipped, and so are the column tiles (64 px or more) a layer does not reach.
//
// Memory: a ring of rows (signed radius and boosted colour per pixel) sized strip + 2 * the
// largest reach, one layer's prefix sums for one strip's window, and strip-sized accumulators.
// Fixed point: colour value v (int16, Y * gain or (C - 128) * gain), layer weight a (Q8);
// prefix of c = (v * a) >> shift in uint32 (wrapping, only differences are used, each below
// 2^31); the kernel sum per pixel in int32 (kernels stay within 17 x 17 cells at their level,
// and the shift is chosen so 17^2 x 256 x c cannot overflow); the layer's colour and alpha
// normalised to Q16 (int64 product with a reciprocal); compositing in Q16.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/arena.h"
#include "algo/core/image.h"
#include "algo/core/status.h"
#include "algo/core/task_runner.h"
#include "algo/render/aperture.h"
#include "algo/render/layer_rows.h"

namespace lb {

class LayerPlane {
 public:
  // Kernels (distinct radii) a plane holds: RenderStage::kMaxRadii is this bound, and the
  // 2 x kMaxKernels - 1 layers must fit the 8-bit layer index of a layer_of entry.
  static constexpr int32_t kMaxKernels = 40;
  static_assert(2 * kMaxKernels - 1 <= 255, "layer indices are 8 bits in layer_of");
  static constexpr int32_t kMaxLevel = 4;
  // Largest radius (px of the level it runs at) blurred at a level; above, the next level.
  static constexpr float kLevelRadius = 8.0f;

  // `sub` is 1 for luma, 2 for chroma (radii are given in luma px, Q4); `layers` the number of
  // depth layers; kernels[i] has radius radii_q4[i] / 16 / sub.
  // `extra_rows` of ring are kept for a caller that reads ahead (the chroma of the next strip).
  // `workers` strips may render at once (RenderStrip's `worker`, 1..kMaxWorkers): each has its
  // own accumulators, and the ring holds the rows of that many consecutive strips.
  // Refuses (and carves nothing) radii outside 1..kMaxKernels, layers outside
  // 1..2 kMaxKernels - 1 and channels other than 1 or 2. Picks the row kernels for this CPU.
  [[nodiscard]] Status Carve(Arena& arena, int32_t width, int32_t height, int32_t channels,
                             int32_t strip_rows, int32_t sub, const int32_t* radii_q4,
                             int32_t radii, int32_t layers, int32_t extra_rows,
                             int32_t workers = 1);
  // Rows beyond a strip (above or below) that rendering it reads, for a configuration.
  static int32_t Reach(int32_t sub, const int32_t* radii_q4, int32_t radii);

  // Rows beyond a strip (above or below) that rendering it reads, in this plane's rows.
  int32_t reach() const { return reach_; }
  // Largest kernel half, at the level the kernel runs at.
  int32_t max_half() const { return (kernel_rows_ - 1) / 2; }

  // Begin-time: builds the kernels for this aperture; `shift` scales c (see above).
  void Begin(const ApertureShape& shape, int32_t shift);

  // The ring row for plane row y, to be filled by the caller: signed radius Q4 and values.
  int16_t* RadiusRow(int32_t y) { return ring_s_ + Slot(y) * static_cast<ptrdiff_t>(width_); }
  int16_t* ValueRow(int32_t y, int32_t ch) {
    return ring_v_ + (Slot(y) * channels_ + ch) * static_cast<ptrdiff_t>(width_);
  }
  const int16_t* RadiusRow(int32_t y) const {
    return ring_s_ + Slot(y) * static_cast<ptrdiff_t>(width_);
  }
  const int16_t* ValueRow(int32_t y, int32_t ch) const {
    return ring_v_ + (Slot(y) * channels_ + ch) * static_cast<ptrdiff_t>(width_);
  }
  // After filling row y: records which columns each layer covers. `layer_of` maps a radius
  // (Q4 + offset) to (first layer << 8 | weight of the next layer Q8).
  void CommitRow(int32_t y, const uint16_t* layer_of, int32_t offset);
  // CommitRow for rows that several workers fill at once (each row by one of them): it leaves
  // next_row() alone, and Advance tells it once they are all committed.
  void CommitRowShared(int32_t y, const uint16_t* layer_of, int32_t offset);
  void Advance(int32_t next_row) { next_row_ = next_row; }
  int32_t next_row() const { return next_row_; }
  // Whether ring row y still holds plane row y, and whether a strip ever read a row that the
  // ring had already recycled (a sizing bug; checked once per row, reported by the stage).
  bool Holds(int32_t y) const;
  bool stale() const;

  // Renders plane rows [y0, y0 + n) of every layer (back to front), `radius_of_layer[k]` being
  // the kernel index of layer k; writes 8-bit results (value + bias) into dst[0 .. channels).
  // Reads the ring only, so strips of different workers may render at once.
  void RenderStrip(int32_t worker, int32_t y0, int32_t n, const uint16_t* layer_of, int32_t offset,
                   const int32_t* radius_of_layer, int32_t bias, ImageU8* dst);

 private:
  // One worker's accumulators for one strip.
  struct Scratch {
    uint32_t* prefix = nullptr;  // window_rows x (channels + 1) x pitch
    uint8_t* active = nullptr;   // per window row: the layer has pixels there
    int32_t* box = nullptr;      // (channels + 1) x pitch: one low-res row's box sums
    uint32_t* acc = nullptr;     // (channels + 1) x pitch: kernel sums, wrapping
    int32_t* layer = nullptr;    // low_rows x (channels + 1) x pitch: normalised layer, Q16
    int32_t* out = nullptr;      // strip_rows x (channels + 1) x width, premultiplied Q16
    bool stale = false;          // a strip read a ring row that was recycled
  };

  int32_t Slot(int32_t y) const { return y % ring_rows_; }
  void RenderLayer(Scratch& s, int32_t k, int32_t y0, int32_t n, const uint16_t* layer_of,
                   int32_t offset, int32_t kernel) const;
  // Builds the prefix rows of layer k at `level` for low-res rows [jlo, jhi) from the plane's
  // columns [x0, x1] (a run of tiles): values outside the run are zero.
  void BuildPrefix(Scratch& s, int32_t k, int32_t level, int32_t half, int32_t jlo, int32_t jhi,
                   int32_t x0, int32_t x1, uint64_t run, int32_t window_base,
                   const uint16_t* layer_of, int32_t offset) const;
  template <int C>
  void BuildPrefixT(Scratch& s, int32_t k, int32_t level, int32_t half, int32_t jlo, int32_t jhi,
                    int32_t x0, int32_t x1, uint64_t run, int32_t window_base,
                    const uint16_t* layer_of, int32_t offset) const;
  void RenderRun(Scratch& s, int32_t k, int32_t y0, int32_t n, const uint16_t* layer_of,
                 int32_t offset, int32_t kernel, int32_t x0, int32_t x1, uint64_t run) const;
  // Tiles of layer k in plane rows [y0, y1).
  uint64_t Tiles(Scratch& s, int32_t k, int32_t y0, int32_t y1) const;
  // Gathers low-res row m of the layer into `layer` (normalised Q16) over columns [x0, x1].
  void GatherNormalise(Scratch& s, int32_t kernel, int32_t m, int32_t jlo, int32_t jhi,
                       int32_t window_base, int32_t x0, int32_t x1, int32_t* layer,
                       ptrdiff_t layer_stride) const;
  void Composite(const int32_t* layer, ptrdiff_t layer_stride, int32_t x0, int32_t x1,
                 int32_t* out) const;

  int32_t width_ = 0, height_ = 0, channels_ = 1;
  int32_t layers_ = 0, radii_ = 0, ring_rows_ = 0, pitch_ = 0, shift_ = 0, next_row_ = 0;
  int32_t reach_ = 0, kernel_rows_ = 0, window_rows_ = 0, low_rows_ = 0;
  float radius_[kMaxKernels] = {};  // this plane's px
  int32_t level_[kMaxKernels] = {};
  int32_t half_[kMaxKernels] = {};         // at the kernel's level
  uint64_t reciprocal_[kMaxKernels] = {};  // 2^40 / total kernel weight
  int16_t* ring_s_ = nullptr;    // ring_rows x width: signed radius, Q4 full-resolution px
  int16_t* ring_v_ = nullptr;    // ring_rows x channels x width
  int32_t* ring_tag_ = nullptr;  // ring_rows: the plane row each slot holds
  uint64_t* tiles_ = nullptr;    // ring_rows x layers: bit t = the layer has a pixel in tile t
  uint64_t* pure_ = nullptr;     // ring_rows x layers: bit t = every pixel of tile t is wholly
                                 // in the layer
  int32_t tile_shift_ = 6;       // tiles of 2^tile_shift columns, at most 64 of them
  Scratch scratch_[kMaxWorkers];
  int32_t workers_ = 1;
  KernelRow* kernels_ = nullptr;                               // radii x kernel_rows
  const layer_rows::Kernels* rows_ = &layer_rows::kReference;  // picked at Carve
  uint8_t* frac_[kMaxLevel + 1] = {};  // per level and column: the right low-res tap's weight
};

}  // namespace lb
