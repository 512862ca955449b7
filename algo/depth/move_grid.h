// What the pieces of the depth stage share: the grid of labels the expansion moves work on (the
// image's pixels, or the coarse pass's 2x2 blocks), the rectangles a move looks at, and the data
// term as they call it, label by label. Plain structs, owned by DepthStage and handed to the
// pieces by reference for each call.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/arena.h"
#include "algo/depth/data_term.h"
#include "algo/depth/depth_config.h"
#include "algo/motion/plane_homography.h"

namespace lb {

// Nodes [x0, x1) x [y0, y1) of a grid.
struct MoveRect {
  int32_t x0, x1, y0, y1;
};

struct MoveGrid {
  // A node's state in a move: free for the cut, or fixed (keeps its label or takes alpha).
  enum : uint8_t { kFree = 0, kKeep = 1, kTake = 2 };
  // A pixel's D in cost_alpha or prev_alpha where its move did not compute it: no D is this
  // large (DataTerm::kMaxCost).
  static constexpr uint16_t kNotComputed = 0xffff;

  int32_t width = 0, height = 0;
  uint8_t* labels = nullptr;
  uint16_t* cost = nullptr;          // D_p(f_p) of the current labels
  uint16_t* cost_alpha = nullptr;    // D_p(alpha) of the move in progress
  uint16_t* prev_alpha = nullptr;    // D of the previous move's label (MoveBook)
  uint16_t* weight_right = nullptr;  // w_pq to the right neighbour
  uint16_t* weight_down = nullptr;
  uint8_t* state = nullptr;  // per node in a move
  // Per row, the labels present (bit l of word l / 64), and the columns whose D the move in
  // progress (span) and the one before (prev_span) computed: [x0, x1) as two entries.
  uint64_t* row_labels = nullptr;
  int32_t* label_count = nullptr;  // per row, how many nodes hold each label (labels per row)
  int32_t* span = nullptr;
  int32_t* prev_span = nullptr;
  // Per row, the columns from the first to the last label within the window of the move in
  // progress ([x0, x1) as two entries, x0 >= x1 when none): MoveBook and pass 1.
  int32_t* near_span = nullptr;
  // The rectangles of the move in progress (move_rects.cc), at most rect_capacity; their cut
  // is exact however they are split.
  MoveRect* rects = nullptr;
  int32_t rect_count = 0, rect_capacity = 0;
  // Fine grid: where the D in cost_alpha and in prev_alpha were computed (they swap with
  // them), at most written_capacity each; a count of -1: anywhere.
  MoveRect* written = nullptr;
  MoveRect* prev_written = nullptr;
  int32_t written_count = 0, prev_written_count = 0, written_capacity = 0;
  uint8_t* row_took = nullptr;  // per row, 1 when a node of it takes alpha (the cut, Record)
};

// Carves g's buffers for width x height nodes and `labels` labels; prev_alpha and the written
// records only with `prev_alpha` (the fine grid).
void CarveGrid(Arena& arena, MoveGrid& g, int32_t width, int32_t height, int32_t labels,
               bool prev_alpha);
// Counts row y's labels, from scratch.
void RowLabels(MoveGrid& g, int32_t labels, int32_t y);
// Energy of a grid's labels from its stored D_p(f_p) and edge weights.
int64_t GridEnergy(const MoveGrid& g, int32_t smooth_trunc);
// The columns of row y (within r) that pass 1 may not fix as far from alpha: those within one
// of a label near alpha (g.near_span, the fine grid's) in the rows y - 1..y + 1; all of r for a
// full move. Empty at r.x0 when none. Inline, as the next helper: both run per row inside the
// callers' loops, which keep their bounds in registers only when the call does not take their
// address.
inline void NearColumns(const MoveGrid& g, bool full, const MoveRect& r, int32_t y, int32_t* x0,
                        int32_t* x1) {
  if (full) {
    *x0 = r.x0;
    *x1 = r.x1;
    return;
  }
  int32_t lo = r.x1, hi = r.x0;
  for (int32_t k = y > 0 ? y - 1 : 0; k <= y + 1 && k < g.height; ++k) {
    const int32_t a = g.near_span[2 * k], b = g.near_span[2 * k + 1];
    if (a >= b) continue;
    lo = a - 1 < lo ? a - 1 : lo;
    hi = b + 1 > hi ? b + 1 : hi;
  }
  lo = lo > r.x0 ? lo : r.x0;
  hi = hi < r.x1 ? hi : r.x1;
  *x0 = lo < hi ? lo : r.x0;
  *x1 = lo < hi ? hi : r.x0;
}
// out[x] = 1 where column x of the rows up, f and down holds a label in base..base + width, for
// x in a..b-1: one unsigned compare per label (a label below base wraps above the width).
// Without branches: it vectorizes in the callers' LB_CLONES_AVX2 copies.
inline void MarkNearLabels(const uint8_t* __restrict up, const uint8_t* __restrict f,
                           const uint8_t* __restrict down, uint8_t base, uint8_t width, int32_t a,
                           int32_t b, uint8_t* __restrict out) {
  for (int32_t x = a; x < b; ++x) {
    out[x] = static_cast<uint8_t>(static_cast<uint8_t>(up[x] - base) <= width) |
             static_cast<uint8_t>(static_cast<uint8_t>(f[x] - base) <= width) |
             static_cast<uint8_t>(static_cast<uint8_t>(down[x] - base) <= width);
  }
}
// The winner-take-all's step: where d is below the best so far (cost), d and `label` become
// the best.
void TakeBetter(const uint16_t* d, int32_t n, uint8_t label, uint16_t* cost, uint8_t* labels);

// Node (x, y) of g leaves label `from` for `to`: row y's counts and label mask follow.
inline void MoveLabel(MoveGrid& g, int32_t labels, int32_t y, int32_t from, int32_t to) {
  int32_t* count = g.label_count + y * labels;
  uint64_t* m = g.row_labels + 4 * y;
  if (--count[from] == 0) m[from >> 6] &= ~(uint64_t{1} << (from & 63));
  if (count[to]++ == 0) m[to >> 6] |= uint64_t{1} << (to & 63);
}

// Notes in a D buffer's record (list, *count of capacity; -1: anywhere) that it holds D over r:
// MoveBook clears it there before the buffer is used again. A rectangle over the columns of the
// last one, right below it, extends that one.
inline void NoteWritten(MoveRect* list, int32_t* count, int32_t capacity, const MoveRect& r) {
  MoveRect* last = *count > 0 ? list + *count - 1 : nullptr;
  if (last != nullptr && last->y1 == r.y0 && last->x0 == r.x0 && last->x1 == r.x1) {
    last->y1 = r.y1;
  } else if (list != nullptr && *count >= 0 && *count < capacity) {
    list[(*count)++] = r;
  } else {
    *count = -1;
  }
}

// The data term as the moves and the coarse pass call it, one label at a time (borrowed from
// the stage for the call).
struct LabelTerm {
  DataTerm& data;
  const DepthConfig& config;
  const PlaneHomography* planes;  // kKnownPoses: [label * views + view]

  // The label's disparity, Q8.8 (DepthStage::LabelDispQ8).
  int32_t DispQ8(int32_t label) const;
  // kKnownPoses: points the data term at one label's planes (a no-op for rectified shifts).
  void Use(int32_t label) const {
    if (config.geometry == ViewGeometry::kKnownPoses) data.SetPlanes(planes + label * config.views);
  }
  // The planes of one label for a data term call that takes them (nullptr: rectified shifts).
  const PlaneHomography* Planes(int32_t label) const {
    return config.geometry == ViewGeometry::kKnownPoses ? planes + label * config.views : nullptr;
  }
};

}  // namespace lb
