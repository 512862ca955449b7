#include "algo/depth/depth_order.h"

namespace lb {
namespace {

// One view pixel's candidates: the highest and lowest label seen there and their errors.
struct Slot {
  uint8_t high, low, high_error, low_error;
};

int32_t ColourError(const uint8_t* a, const uint8_t* b) {
  int32_t e = 0;
  for (int32_t k = 0; k < 3; ++k) e += a[k] > b[k] ? a[k] - b[k] : b[k] - a[k];
  return e / 3;  // 0..255
}

}  // namespace

DepthOrderVotes VoteDepthOrder(const ConstImageU8* views, int32_t view_count, int32_t reference,
                               const uint8_t* labels, int32_t label_count,
                               const PlaneHomography* planes, const DepthOrderParams& params,
                               uint8_t* scratch) {
  DepthOrderVotes votes;
  const ConstImageU8& ref = views[reference];
  const int32_t w = ref.width, h = ref.height;
  Slot* slots = reinterpret_cast<Slot*>(scratch);
  for (int32_t v = 0; v < view_count; ++v) {
    if (v == reference) continue;
    const ConstImageU8& view = views[v];
    // Empty: low above high.
    for (int32_t i = 0; i < w * h; ++i) slots[i] = Slot{0, 255, 255, 255};
    for (int32_t y = 0; y < h; ++y) {
      const uint8_t* ref_row = ref.Row(y);
      for (int32_t x = 0; x < w; ++x) {
        const uint8_t l = labels[y * w + x];
        int32_t xq = 0, yq = 0;
        if (!planes[v * label_count + l].Map(x, y, &xq, &yq)) continue;
        const int32_t vx = (xq + (1 << 15)) >> 16, vy = (yq + (1 << 15)) >> 16;
        if (vx < 0 || vy < 0 || vx >= w || vy >= h) continue;
        const int32_t e = ColourError(ref_row + 3 * x, view.Row(vy) + 3 * vx);
        Slot& s = slots[vy * w + vx];
        if (s.low > s.high) {
          s = Slot{l, l, static_cast<uint8_t>(e), static_cast<uint8_t>(e)};
          continue;
        }
        if (l > s.high || (l == s.high && e < s.high_error)) {
          s.high = l;
          s.high_error = static_cast<uint8_t>(e);
        }
        if (l < s.low || (l == s.low && e < s.low_error)) {
          s.low = l;
          s.low_error = static_cast<uint8_t>(e);
        }
      }
    }
    for (int32_t i = 0; i < w * h; ++i) {
      const Slot& s = slots[i];
      if (s.low > s.high || s.high - s.low < params.min_gap) continue;
      if (s.high_error + params.margin < s.low_error) ++votes.high_near;
      if (s.low_error + params.margin < s.high_error) ++votes.low_near;
    }
  }
  return votes;
}

}  // namespace lb
