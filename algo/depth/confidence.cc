// The confidence map (confidence.h): the winner-take-all's two lowest D per pixel, and the map
// from them, the final labels and the reference's texture.
#include "algo/depth/confidence.h"

#include "algo/core/clones.h"

namespace lb {
namespace {
// The margin as a share of the cost away from the chosen label, Q0.8: (away - D) / (away +
// kMarginFloor). A share, not a difference: a chosen label whose own D is high (a poor match,
// as when the truth lies between the labels the winner-take-all tried and the moves never
// reached it) is barely better than the rest however large the costs, and the floor keeps the
// small costs of a flat patch, where both are noise, from reading as a large share. Under
// kDoubtShare it says nothing for the depth, at kSureShare (D half of away, or less) sure.
constexpr int32_t kMarginFloor = 64;
constexpr int32_t kDoubtShare = 32;
constexpr int32_t kSureShare = 128;
// Texture: the reference's luma (R + 2G + B, 0..1020) steps to the right and down, summed over
// 3x3 (18 steps). Under kFlatTexture (a mean step of 8, two levels a channel: sensor noise on a
// wall) it is flat, confidence 0; at kSureTexture (a mean step of 48) and above it says nothing.
constexpr int32_t kFlatTexture = 18 * 8;
constexpr int32_t kSureTexture = 18 * 48;

inline int32_t Luma(const uint8_t* rgb) { return rgb[0] + 2 * rgb[1] + rgb[2]; }

inline int32_t Abs(int32_t v) { return v < 0 ? -v : v; }

// The luma steps right and down of pixel x of `row` (0 past the last column or row).
inline int32_t Steps(const uint8_t* row, const uint8_t* below, int32_t x, int32_t w) {
  const int32_t l = Luma(row + 3 * x);
  const int32_t right = x + 1 < w ? Abs(Luma(row + 3 * x + 3) - l) : 0;
  const int32_t down = below != nullptr ? Abs(Luma(below + 3 * x) - l) : 0;
  return right + down;
}

// Q0.8 from v on a ramp lo..hi, clamped.
inline int32_t Ramp(int32_t v, int32_t lo, int32_t hi) {
  if (v <= lo) return 0;
  if (v >= hi) return 255;
  return ((v - lo) * 255 + (hi - lo) / 2) / (hi - lo);
}
}  // namespace

void LabelMargins::Carve(Arena& arena, int32_t w, int32_t h) {
  const size_t n = static_cast<size_t>(w) * h;
  width = w;
  height = h;
  best = arena.Allocate<uint16_t>(n);
  second = arena.Allocate<uint16_t>(n);
  best_label = arena.Allocate<uint8_t>(n);
  confidence = arena.Allocate<uint8_t>(n);
}

void LabelMargins::Reset() {
  const int32_t n = width * height;
  for (int32_t p = 0; p < n; ++p) {
    best[p] = second[p] = 0xffff;
    best_label[p] = 0;
  }
}

// Without branches, so that it vectorizes. Labels come ascending, so label - best_label >= 0.
LB_CLONES_AVX2 static void TakeTwoBest(const uint16_t* __restrict d, int32_t n, uint8_t label,
                                       uint16_t* __restrict best, uint16_t* __restrict second,
                                       uint8_t* __restrict best_label) {
  for (int32_t p = 0; p < n; ++p) {
    const uint16_t b = best[p], s = second[p], v = d[p];
    const bool wins = v < b;
    const bool apart = static_cast<uint8_t>(label - best_label[p]) > 1;
    const uint16_t low = v < s ? v : s;
    second[p] = apart ? (wins ? b : low) : s;
    best[p] = wins ? v : b;
    best_label[p] = wins ? label : best_label[p];
  }
}

void LabelMargins::Take(const uint16_t* d, int32_t p0, int32_t n, uint8_t label) {
  TakeTwoBest(d, n, label, best + p0, second + p0, best_label + p0);
}

int64_t LabelMargins::Finish(const uint8_t* labels, const uint16_t* cost, int32_t step,
                             const ConstImageU8& reference) {
  const int32_t w = width, h = height;
  // A final label this near the winner's is its own minimum (the fine moves place it between
  // the coarse labels): the margin is to the second; else the winner itself is away from it.
  const int32_t near = step / 2 > 1 ? step / 2 : 1;
  int64_t low = 0;
  for (int32_t y = 0; y < h; ++y) {
    const uint8_t* rows[3] = {reference.Row(y > 0 ? y - 1 : y), reference.Row(y),
                              reference.Row(y + 1 < h ? y + 1 : y)};
    const uint8_t* below[3] = {y > 0 ? rows[1] : nullptr, y + 1 < h ? rows[2] : nullptr,
                               y + 2 < h ? reference.Row(y + 2) : nullptr};
    for (int32_t x = 0; x < w; ++x) {
      const int32_t p = y * w + x;
      const int32_t f = labels[p];
      const int32_t apart = Abs(f - best_label[p]) > near;
      const int32_t away = apart ? best[p] : second[p];
      const int32_t margin = away > cost[p] ? away - cost[p] : 0;
      const int32_t by_data = Ramp((margin << 8) / (away + kMarginFloor), kDoubtShare, kSureShare);
      int32_t texture = 0;
      for (int32_t k = 0; k < 3; ++k) {
        if ((k == 0 && y == 0) || (k == 2 && y + 1 >= h)) continue;
        for (int32_t dx = x > 0 ? -1 : 0; dx <= 1 && x + dx < w; ++dx) {
          texture += Steps(rows[k], below[k], x + dx, w);
        }
      }
      const int32_t by_texture = Ramp(texture, kFlatTexture, kSureTexture);
      const int32_t c = (by_data * by_texture + 127) / 255;
      confidence[p] = static_cast<uint8_t>(c);
      low += c < kLow ? 1 : 0;
    }
  }
  return low;
}

}  // namespace lb
