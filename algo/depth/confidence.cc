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
// kDoubtShare it says nothing for the depth, at kSureShare (D about half of away, or less)
// sure.
constexpr int32_t kMarginFloor = 64;
constexpr int32_t kDoubtShare = 32;
constexpr int32_t kSureShare = 128;
// The table of shares: every away cost (at most DataTerm::kMaxCost; none seen: the last entry).
constexpr int32_t kShareEntries = 4096;
// Texture: the reference's luma (R + 2G + B, 0..1020) steps to the right and down, summed over
// 3x3 (18 steps). Under kFlatTexture (a mean step of 8, two levels a channel: sensor noise on a
// wall) it is flat, confidence 0; at kSureTexture (a mean step of 48) and above it says nothing.
constexpr int32_t kFlatTexture = 18 * 8;
constexpr int32_t kSureTexture = 18 * 48;

inline int32_t Abs(int32_t v) { return v < 0 ? -v : v; }

// Q0.8 from v on a ramp lo..hi, clamped; without branches.
inline int32_t Ramp(int32_t v, int32_t lo, int32_t hi) {
  int32_t t = v - lo;
  t = t < 0 ? 0 : t;
  t = t > hi - lo ? hi - lo : t;
  return (t * 255 + (hi - lo) / 2) / (hi - lo);
}

// R + 2G + B of a row, 0..1020.
LB_CLONES_AVX2 void LumaRow(const uint8_t* __restrict rgb, int32_t w, uint16_t* __restrict out) {
  for (int32_t x = 0; x < w; ++x) {
    out[x] = static_cast<uint16_t>(rgb[3 * x] + 2 * rgb[3 * x + 1] + rgb[3 * x + 2]);
  }
}

// Each pixel's luma steps to the right and down (0 past the last column; below: nullptr past the
// last row), at most 2040.
LB_CLONES_AVX2 void StepsRow(const uint16_t* __restrict l, const uint16_t* __restrict below,
                             int32_t w, uint16_t* __restrict out) {
  for (int32_t x = 0; x < w; ++x) out[x] = below != nullptr ? Abs(below[x] - l[x]) : 0;
  for (int32_t x = 0; x + 1 < w; ++x) out[x] = static_cast<uint16_t>(out[x] + Abs(l[x + 1] - l[x]));
}
}  // namespace

void LabelMargins::Carve(Arena& arena, int32_t w, int32_t h) {
  const size_t n = static_cast<size_t>(w) * h;
  width = w;
  height = h;
  best = arena.Allocate<uint16_t>(n);
  second = arena.Allocate<uint16_t>(n);
  best_label = arena.Allocate<uint16_t>(n);
  confidence = arena.Allocate<uint8_t>(n);
  steps = arena.Allocate<uint16_t>(6 * static_cast<size_t>(w) + 2);
  column = steps == nullptr ? nullptr : steps + 3 * static_cast<size_t>(w);
  luma = column == nullptr ? nullptr : column + w + 2;
  share = arena.Allocate<uint32_t>(kShareEntries);
  // The margin's share without a division a pixel (Finish): 256 << 16 over at least
  // kMarginFloor fits 18 bits, and times a margin of 12 bits, 30.
  for (int32_t a = 0; share != nullptr && a < kShareEntries; ++a) {
    share[a] = static_cast<uint32_t>((int64_t{256} << 16) / (a + kMarginFloor));
  }
}

void LabelMargins::Reset() {
  const int32_t n = width * height;
  for (int32_t p = 0; p < n; ++p) {
    best[p] = second[p] = 0xffff;
    best_label[p] = 0;
  }
}

// Labels more than one apart (a step over 1): the two lowest, a min and a max a pixel.
LB_CLONES_AVX2 static void TakeTwo(const uint16_t* __restrict d, int32_t n, uint16_t label,
                                   uint16_t* __restrict best, uint16_t* __restrict second,
                                   uint16_t* __restrict best_label) {
  for (int32_t p = 0; p < n; ++p) {
    const uint16_t b = best[p], v = d[p];
    const uint16_t high = v > b ? v : b;
    second[p] = high < second[p] ? high : second[p];
    best[p] = v < b ? v : b;
    best_label[p] = v < b ? label : best_label[p];
  }
}

// Every label (a step of 1): the second only from labels apart from the best as it stands.
// Labels come ascending, so label - best_label >= 0.
LB_CLONES_AVX2 static void TakeTwoApart(const uint16_t* __restrict d, int32_t n, uint16_t label,
                                        uint16_t* __restrict best, uint16_t* __restrict second,
                                        uint16_t* __restrict best_label) {
  for (int32_t p = 0; p < n; ++p) {
    const uint16_t b = best[p], s = second[p], v = d[p];
    const bool wins = v < b;
    const bool apart = static_cast<uint16_t>(label - best_label[p]) > 1;
    const uint16_t low = v < s ? v : s;
    second[p] = apart ? (wins ? b : low) : s;
    best[p] = wins ? v : b;
    best_label[p] = wins ? label : best_label[p];
  }
}

void LabelMargins::Take(const uint16_t* d, int32_t p0, int32_t n, int32_t label, int32_t step) {
  const uint16_t l = static_cast<uint16_t>(label);
  if (step > 1) {
    TakeTwo(d, n, l, best + p0, second + p0, best_label + p0);
  } else {
    TakeTwoApart(d, n, l, best + p0, second + p0, best_label + p0);
  }
}

int64_t LabelMargins::Finish(const uint8_t* labels, const uint16_t* cost, int32_t step,
                             const ConstImageU8& reference) {
  const int32_t w = width, h = height;
  if (!carved() || luma == nullptr) return 0;
  // A final label this near the winner's is its own minimum (the fine moves place it between
  // the coarse labels): the margin is to the second; else the winner itself is away from it.
  const int32_t near = step / 2 > 1 ? step / 2 : 1;
  int64_t low = 0;
  // The texture's steps of rows y - 1, y and y + 1 in a ring of three, from the luma of rows
  // y + 1 and y + 2 in a ring of two.
  LumaRow(reference.Row(0), w, luma);
  if (h > 1) LumaRow(reference.Row(1), w, luma + w);
  StepsRow(luma, h > 1 ? luma + w : nullptr, w, steps);
  column[0] = column[w + 1] = 0;
  for (int32_t y = 0; y < h; ++y) {
    if (y + 1 < h) {
      if (y + 2 < h) LumaRow(reference.Row(y + 2), w, luma + (y % 2) * w);
      StepsRow(luma + ((y + 1) % 2) * w, y + 2 < h ? luma + (y % 2) * w : nullptr, w,
               steps + ((y + 1) % 3) * w);
    }
    const uint16_t* mid = steps + (y % 3) * w;
    const uint16_t* up = y > 0 ? steps + ((y + 2) % 3) * w : mid;
    const uint16_t* down = y + 1 < h ? steps + ((y + 1) % 3) * w : mid;
    const int32_t rows = 1 + (y > 0 ? 1 : 0) + (y + 1 < h ? 1 : 0);
    // Both neighbours or only the row itself: the sum over the rows there are, without a branch.
    for (int32_t x = 0; x < w; ++x) {
      column[x + 1] = static_cast<uint16_t>(rows == 3   ? up[x] + mid[x] + down[x]
                                            : rows == 2 ? up[x] + down[x]
                                                        : mid[x]);
    }
    for (int32_t x = 0; x < w; ++x) {
      const int32_t p = y * w + x;
      const int32_t f = labels[p];
      const int32_t apart = Abs(f - best_label[p]) > near;
      const int32_t seen = apart != 0 ? best[p] : second[p];
      const int32_t away = seen < kShareEntries ? seen : kShareEntries - 1;
      const int32_t margin = away > cost[p] ? away - cost[p] : 0;
      const int32_t by_data =
          Ramp(static_cast<int32_t>((static_cast<uint32_t>(margin) * share[away]) >> 16),
               kDoubtShare, kSureShare);
      const int32_t texture = column[x] + column[x + 1] + column[x + 2];
      const int32_t by_texture = Ramp(texture, kFlatTexture, kSureTexture);
      const int32_t c = (by_data * by_texture + 127) / 255;
      confidence[p] = static_cast<uint8_t>(c);
      low += c < kLow ? 1 : 0;
    }
  }
  return low;
}

}  // namespace lb
