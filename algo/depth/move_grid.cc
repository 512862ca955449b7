// The shared grid of the expansion moves: its buffers, its row labels, its energy, and the
// winner-take-all's step.
#include "algo/depth/move_grid.h"

#include "algo/core/clones.h"

namespace lb {
namespace {

// Energy of a grid's labels from its stored D_p(f_p) and edge weights. A row's costs, pairs
// right and pairs down in loops of their own, so that each vectorizes.
LB_CLONES_AVX2 int64_t LabelEnergy(const uint8_t* __restrict labels,
                                   const uint16_t* __restrict cost,
                                   const uint16_t* __restrict right,
                                   const uint16_t* __restrict down, int32_t w, int32_t h,
                                   int32_t trunc) {
  int64_t e = 0;
  for (int32_t y = 0; y < h; ++y) {
    const uint8_t* f = labels + y * w;
    const uint8_t* fd = f + w;
    const ptrdiff_t row = static_cast<ptrdiff_t>(y) * w;
    // Each term is below 2^20 (8192 * 64, 9180): int64 sums never overflow.
    int64_t sum = 0;
    for (int32_t x = 0; x < w; ++x) sum += cost[row + x];
    for (int32_t x = 0; x + 1 < w; ++x) {
      const int32_t d = f[x] > f[x + 1] ? f[x] - f[x + 1] : f[x + 1] - f[x];
      sum += int64_t{right[row + x]} * (d < trunc ? d : trunc);
    }
    if (y + 1 < h) {
      for (int32_t x = 0; x < w; ++x) {
        const int32_t d = f[x] > fd[x] ? f[x] - fd[x] : fd[x] - f[x];
        sum += int64_t{down[row + x]} * (d < trunc ? d : trunc);
      }
    }
    e += sum;
  }
  return e;
}

}  // namespace

void CarveGrid(Arena& arena, MoveGrid& g, int32_t width, int32_t height, int32_t labels,
               bool prev_alpha) {
  const size_t n = static_cast<size_t>(width) * height, rows = static_cast<size_t>(height);
  g.width = width;
  g.height = height;
  g.labels = arena.Allocate<uint8_t>(n);
  g.cost = arena.Allocate<uint16_t>(n);
  g.cost_alpha = arena.Allocate<uint16_t>(n);
  g.prev_alpha = prev_alpha ? arena.Allocate<uint16_t>(n) : nullptr;
  g.weight_right = arena.Allocate<uint16_t>(n);
  g.weight_down = arena.Allocate<uint16_t>(n);
  g.state = arena.Allocate<uint8_t>(n);
  g.row_labels = arena.Allocate<uint64_t>(4 * rows);
  g.label_count = arena.Allocate<int32_t>(rows * static_cast<size_t>(labels));
  g.span = arena.Allocate<int32_t>(2 * rows);
  g.prev_span = arena.Allocate<int32_t>(2 * rows);
  g.near_span = arena.Allocate<int32_t>(2 * rows);
  // A restricted move's runs of rows are at most one per 2 rows; the splits of each run into
  // smaller rectangles stop when the list is full (a larger rectangle is as exact).
  g.rect_capacity = 4 * height + 64;
  g.rects = arena.Allocate<MoveRect>(static_cast<size_t>(g.rect_capacity));
  g.rect_count = 0;
  g.written_capacity = prev_alpha ? g.rect_capacity + height : 0;
  g.written = arena.Allocate<MoveRect>(static_cast<size_t>(g.written_capacity));
  g.prev_written = arena.Allocate<MoveRect>(static_cast<size_t>(g.written_capacity));
  g.written_count = g.prev_written_count = 0;
  g.row_took = arena.Allocate<uint8_t>(rows);
}

void RowLabels(MoveGrid& g, int32_t labels, int32_t y) {
  const int32_t w = g.width;
  uint64_t* m = g.row_labels + 4 * y;
  int32_t* count = g.label_count + y * labels;
  for (int32_t l = 0; l < labels; ++l) count[l] = 0;
  const uint8_t* f = g.labels + y * w;
  for (int32_t x = 0; x < w; ++x) ++count[f[x]];
  m[0] = m[1] = m[2] = m[3] = 0;
  for (int32_t l = 0; l < labels; ++l) m[l >> 6] |= uint64_t{count[l] > 0} << (l & 63);
}

int64_t GridEnergy(const MoveGrid& g, int32_t smooth_trunc) {
  return LabelEnergy(g.labels, g.cost, g.weight_right, g.weight_down, g.width, g.height,
                     smooth_trunc);
}

// Without branches, so that it vectorizes (a block's winner is a coin toss to a predictor).
LB_CLONES_AVX2 void TakeBetter(const uint16_t* __restrict d, int32_t n, uint8_t label,
                               uint16_t* __restrict cost, uint8_t* __restrict labels) {
  for (int32_t p = 0; p < n; ++p) {
    const bool better = d[p] < cost[p];
    cost[p] = better ? d[p] : cost[p];
    labels[p] = better ? label : labels[p];
  }
}

}  // namespace lb
