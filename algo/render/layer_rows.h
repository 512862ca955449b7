// The row kernels of layered compositing (layer_plane.h): each a plain C reference; those on the
// per-pixel path also have SIMD twins, picked once when a plane is carved (never per row):
// AVX2 on x86-64 and NEON on ARM (layer_rows_avx2.cc, layer_rows_neon.cc: intrinsics, ARMv7
// ones so armhf builds them too; gather is the C source compiled for each). Integer
// arithmetic only, so every variant gives the same bits as the reference; the tests
// (tests/algo/render/layer_rows_test.cc) run each variant the CPU has against it.
//
// Formats, shared by the kernels (bounds from render_stage.cc and layer_plane.h):
//   v       int16, a plane's value: Y * gain or (C - 128) * gain, gain <= 8: |v| <= 2040.
//   a       layer weight, Q8: 0..256.
//   c       (v * a) >> shift, the shift chosen by the render stage (ShiftFor) so that a whole
//           kernel's sum, cells x 256 x |c| with cells <= 17 x 17, stays below 2^31.
//   prefix  row prefix sums of c in uint32, wrapping: only differences are read, each below
//           2^31 in magnitude, so modular arithmetic gives them exactly.
//   Q16     normalised layer colour (premultiplied by its alpha) and alpha (0..65536), and the
//           composited strip: |colour| <= 2040 * 65536 < 2^27.
// Internal to algo/render.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/render/aperture.h"

namespace lb::layer_rows {

// Weight (Q8, 0..256) of layer k in a pixel whose layer entry (RenderStage's layer_of) is e =
// first layer << 8 | weight of the next layer (Q8): 256 - that weight in the first layer, that
// weight in the next, 0 elsewhere.
inline int32_t LayerWeightQ8(uint16_t e, int32_t k) {
  const int32_t first = e >> 8, frac = e & 255;
  return first == k ? 256 - frac : (first + 1 == k ? frac : 0);
}

// ---- Prefix rows of a layer (C colour planes, then its weight), at full resolution. v[c] are
// the value rows, s the signed radius row (Q4), p[c] the prefix rows, written at x + 1 for x in
// [x0, x1] from p[c][x0]. Overflow: per pixel |c| <= 2040 x 256 and the weight <= 256; prefix
// sums wrap in uint32 and only their differences (< 2^31, see above) are read. ----

// A tile where the layer is absent: the prefix stays flat.
template <int C>
void FlatPrefixRowC(int32_t x0, int32_t x1, uint32_t* const* p);
// A tile wholly in the layer (weight 256): c = (v x 256) >> shift.
template <int C>
void PurePrefixRowC(const int16_t* const* v, int32_t shift, int32_t x0, int32_t x1,
                    uint32_t* const* p);
// Any tile: the weight a of layer k per pixel from layer_of[s[x] + offset], c = (v x a) >> shift.
template <int C>
void WeightedPrefixRowC(const int16_t* const* v, const int16_t* s, const uint16_t* layer_of,
                        int32_t offset, int32_t k, int32_t shift, int32_t x0, int32_t x1,
                        uint32_t* const* p);

// ---- Box sums of a reduced level (1..4): box[c][x >> level] += sum of c over the columns of
// [x0, x1] in that box (x0 a multiple of 2^level), one full-resolution row at a time.
// Overflow: a box of 2^level x 2^level <= 256 pixels of |c| <= 2040 x 256: < 2^27, int32. ----

// A tile wholly in the layer, shift <= 8: (sum of v) << (8 - shift), which equals the sum of
// (v x 256) >> shift exactly (v x 256 is a multiple of 2^shift); weights 256 per pixel.
template <int C>
void PureBoxRowC(const int16_t* const* v, int32_t shift, int32_t level, int32_t x0, int32_t x1,
                 int32_t* const* box);
// Any tile: as WeightedPrefixRowC, summed per box.
template <int C>
void WeightedBoxRowC(const int16_t* const* v, const int16_t* s, const uint16_t* layer_of,
                     int32_t offset, int32_t k, int32_t shift, int32_t level, int32_t x0,
                     int32_t x1, int32_t* const* box);
// p[q + 1] = p[q] + round(box[q] / 4^level) for q in [q0, q1]: the box means' prefix row.
// Overflow: box + 2^(2 level - 1) < 2^27 + 2^7, int32.
void BoxPrefixRowC(const int32_t* box, int32_t level, int32_t q0, int32_t q1, uint32_t* p);

// acc[x] += sum over the kernel row's cells of weight x c, for x in [x0, x1]: the span
// [left, right] at w and the ends left - 1, right + 1 at wl, wr (Q8, 0..256), read from the
// prefix row p (p[i] = sum of c over columns < i, valid for i in [x0 + left - 1,
// x1 + right + 2]). As BuildKernel makes them: right >= left - 1 (an empty span is
// right = left - 1).
// Overflow: uint32, wrapping; the true value of acc after every row of a kernel is at most
// total weight x max |c| < 2^31 (see above), so acc read as int32 is exact.
void GatherRowC(const uint32_t* p, const KernelRow& k, uint32_t* acc, int32_t x0, int32_t x1);

// out[x] = ((out[x] x (65536 - alpha[x]) + 32768) >> 16) + colour[x], x in [x0, x1]: lays a
// layer row (Q16 colour premultiplied, Q16 alpha 0..65536) over what is behind (Q16).
// Overflow: the product is int64 (|out| < 2^27 times 2^16); the result is a convex mix of
// values below 2^27 plus rounding, so it stays int32.
void CompositeRowC(int32_t* out, const int32_t* colour, const int32_t* alpha, int32_t x0,
                   int32_t x1);

// A reduced layer (level 1..4, factor f = 2^level) upsampled and composited in one pass:
// col holds C colour planes then alpha, `stride` apart, Q16, valid at low-res columns
// q_lo - 1 .. q_hi + 1 around [x0 >> level, x1 >> level]; output column x lies between q =
// (x - f / 2) >> level and q + 1, at the weight frac[x] (Q8, 0..255) of q + 1; each plane of
// `out` (`out_stride` apart) is composited as CompositeRowC does. C is 1 (luma) or 2 (chroma).
// Overflow: the difference of two Q16 values (< 2^28) times frac (< 2^8) in int64; the
// interpolated values stay within their two taps, so the compositing bound above holds.
template <int C>
void LerpCompositeC(const int32_t* col, ptrdiff_t stride, const uint8_t* frac, int32_t level,
                    int32_t x0, int32_t x1, int32_t* out, ptrdiff_t out_stride);

// box[x >> level] += (sum of v over its 2^level columns within [x0, x1]) << up, x0 a multiple
// of 2^level (a tile edge), level 1..4,
// up 0..8 (up = 8 - shift: the weight 256 of a pixel wholly in the layer, undoing the shift).
// Overflow: a box of 2^level x 2^level <= 256 pixels, |v| <= 2040, << 8: < 2^27 per box, int32.
void SumGroupsC(const int16_t* v, int32_t x0, int32_t x1, int32_t level, int32_t up, int32_t* box);

// alpha[x] = min(65536, (acc[x] x rec) >> 32), x in [x0, x1]: a layer's coverage sum (acc,
// at most total x 256) normalised by rec = 2^40 / total, to Q16.
// Overflow: acc x rec <= total x 256 x 2^40 / total = 2^48, uint64.
void NormaliseAlphaRowC(const uint32_t* acc, uint64_t rec, int32_t x0, int32_t x1, int32_t* alpha);

// colour[x] = (int32(acc[x]) x rec) >> (32 - shift): a layer's colour sum (c units, wrapping
// uint32 read as int32) normalised to Q16 of v, undoing the shift (0..16).
// Overflow: |acc| <= total x max |c| and rec = 2^40 / total, so |product| <= 2^40 x 2^19 <
// 2^63, int64.
void NormaliseColourRowC(const uint32_t* acc, uint64_t rec, int32_t shift, int32_t x0, int32_t x1,
                         int32_t* colour);

// col[q] = (a[q] x (256 - fy) + b[q] x fy + 128) >> 8 for q in [q0, q1], and the edges
// col[q0 - 1], col[q1 + 1] replicated: two low-res rows (Q16) blended at fy (Q8, 0..255).
// Overflow: Q16 values < 2^28 times 2^8 in int64.
void BlendRowsC(const int32_t* a, const int32_t* b, int64_t fy, int32_t q0, int32_t q1,
                int32_t* col);

// dst[x] = clamp(round(out[x] / alpha[x]) + bias, 0, 255) for x in [0, width): the composited
// premultiplied value (Q16) divided by its coverage (Q16, a shift when it is exactly 65536),
// rounded half away from zero (the same on every platform); where alpha is 0 (never, a pixel
// covers itself; kept for safety) the pixel's own value v[x].
// Overflow: |out| < 2^31 - 2^16, so out + alpha / 2 fits int32.
void ResolveRowC(const int32_t* out, const int32_t* alpha, const int16_t* v, int32_t width,
                 int32_t bias, uint8_t* dst);

// The kernels that have faster variants, as a table picked once. The SIMD twins rely on the
// formats above (Q16 values below 2^28, alpha 0..65536) where the references compute in int64:
// they split the products into 32-bit parts whose sum is exact within those bounds.
struct Kernels {
  void (*gather)(const uint32_t* p, const KernelRow& k, uint32_t* acc, int32_t x0, int32_t x1);
  void (*composite)(int32_t* out, const int32_t* colour, const int32_t* alpha, int32_t x0,
                    int32_t x1);
  // LerpCompositeC<1> and <2>.
  void (*lerp_composite[2])(const int32_t* col, ptrdiff_t stride, const uint8_t* frac,
                            int32_t level, int32_t x0, int32_t x1, int32_t* out,
                            ptrdiff_t out_stride);
  // WeightedBoxRowC<1> and <2>, PureBoxRowC<1> and <2>.
  void (*weighted_box[2])(const int16_t* const* v, const int16_t* s, const uint16_t* layer_of,
                          int32_t offset, int32_t k, int32_t shift, int32_t level, int32_t x0,
                          int32_t x1, int32_t* const* box);
  void (*pure_box[2])(const int16_t* const* v, int32_t shift, int32_t level, int32_t x0, int32_t x1,
                      int32_t* const* box);
  void (*normalise_alpha)(const uint32_t* acc, uint64_t rec, int32_t x0, int32_t x1,
                          int32_t* alpha);
  void (*normalise_colour)(const uint32_t* acc, uint64_t rec, int32_t shift, int32_t x0, int32_t x1,
                           int32_t* colour);
  void (*blend)(const int32_t* a, const int32_t* b, int64_t fy, int32_t q0, int32_t q1,
                int32_t* col);
  void (*box_prefix)(const int32_t* box, int32_t level, int32_t q0, int32_t q1, uint32_t* p);
  void (*resolve)(const int32_t* out, const int32_t* alpha, const int16_t* v, int32_t width,
                  int32_t bias, uint8_t* dst);
  // WeightedPrefixRowC<1> and <2>: the running sums eight (AVX2) or four (NEON) columns a step,
  // each step's own prefix in-register (wrapping uint32, as the reference), then its carry.
  void (*weighted_prefix[2])(const int16_t* const* v, const int16_t* s, const uint16_t* layer_of,
                             int32_t offset, int32_t k, int32_t shift, int32_t x0, int32_t x1,
                             uint32_t* const* p);
};

extern const Kernels kReference;
#if defined(__x86_64__)
// GatherRowC's source compiled for AVX2 (the caller checks the CPU).
void GatherRowCAvx2(const uint32_t* p, const KernelRow& k, uint32_t* acc, int32_t x0, int32_t x1);
#endif
#if defined(__ARM_NEON) || defined(__arm__)
// GatherRowC's source compiled for NEON (on armhf the caller checks the CPU).
void GatherRowCNeon(const uint32_t* p, const KernelRow& k, uint32_t* acc, int32_t x0, int32_t x1);
#endif
// The AVX2 variants (x86-64) when the processor has AVX2, else nullptr.
const Kernels* Avx2Kernels();
// The NEON variants on ARM (aarch64; armhf compiles them for NEON whatever its baseline, and
// the caller must know the CPU has NEON), else nullptr.
const Kernels* NeonKernels();
// The fastest variants this processor has, from the features the firmware read
// (algo/core/cpu.h; armhf takes NEON only when HWCAP says the core has it). The one place that
// chooses; a plane asks once, when it is carved.
const Kernels& BestKernels();

}  // namespace lb::layer_rows
