// Where an expansion move looks (DepthStage::MoveRects): the rectangles of grid() whose nodes it
// may free, and per row the columns whose D it computes.
#include "algo/depth/depth_stage.h"

namespace lb {

// A move looks at rectangles: the whole grid for a full move. A restricted move frees only
// nodes with a label within window_ of alpha in their 3x3 neighbourhood, so it looks at the runs
// of rows next to such a label, each over the columns from the first to the last of them. The
// rows between runs keep their labels, which makes each rectangle's cut independent of the
// others.
int32_t DepthStage::MoveRects(int32_t alpha) {
  Grid& g = grid();
  const int32_t w = g.width, h = g.height;
  int32_t* t = g.prev_span;
  g.prev_span = g.span;
  g.span = t;
  int32_t* span = g.span;
  if (window_ >= config_.labels - 1) {
    for (int32_t y = 0; y < h; ++y) {
      span[2 * y] = 0;
      span[2 * y + 1] = w;
    }
    g.rects[0] = Rect{0, w, 0, h};
    return 1;
  }
  const int32_t lo = alpha - window_ > 0 ? alpha - window_ : 0;
  const int32_t hi = alpha + window_ < config_.labels - 1 ? alpha + window_ : config_.labels - 1;
  uint64_t want[4] = {};
  for (int32_t l = lo; l <= hi; ++l) want[l >> 6] |= uint64_t{1} << (l & 63);
  auto outside = [lo, hi](int32_t f) { return f < lo || f > hi; };
  // Each row's own columns with such a label: [w, 0) when none.
  for (int32_t y = 0; y < h; ++y) {
    const uint64_t* m = g.row_labels + 4 * y;
    int32_t x0 = w, x1 = 0;
    if (((m[0] & want[0]) | (m[1] & want[1]) | (m[2] & want[2]) | (m[3] & want[3])) != 0) {
      const uint8_t* f = g.labels + y * w;
      x0 = 0;
      x1 = w;
      while (outside(f[x0])) ++x0;  // the row holds one
      while (outside(f[x1 - 1])) --x1;
    }
    span[2 * y] = x0;
    span[2 * y + 1] = x1;
  }
  // Runs of rows next to one, over the columns next to one.
  auto row_near = [&](int32_t y) {
    for (int32_t k = y > 0 ? y - 1 : 0; k <= y + 1 && k < h; ++k) {
      if (span[2 * k] < span[2 * k + 1]) return true;
    }
    return false;
  };
  int32_t count = 0;
  for (int32_t y = 0; y < h;) {
    if (!row_near(y)) {
      ++y;
      continue;
    }
    Rect r{w, 0, y, y};
    for (; y < h && row_near(y); ++y) {
      for (int32_t k = y > 0 ? y - 1 : 0; k <= y + 1 && k < h; ++k) {
        r.x0 = span[2 * k] < r.x0 ? span[2 * k] : r.x0;
        r.x1 = span[2 * k + 1] > r.x1 ? span[2 * k + 1] : r.x1;
      }
    }
    r.y1 = y;
    r.x0 = r.x0 > 0 ? r.x0 - 1 : 0;
    r.x1 = r.x1 < w ? r.x1 + 1 : w;
    g.rects[count++] = r;
  }
  // The final columns per row: the rectangle's, none between them (no run reads the own
  // columns of a row of another, as rows next to a run's rows belong to it or hold none).
  for (int32_t y = 0; y < h; ++y) span[2 * y] = span[2 * y + 1] = 0;
  for (int32_t i = 0; i < count; ++i) {
    for (int32_t y = g.rects[i].y0; y < g.rects[i].y1; ++y) {
      span[2 * y] = g.rects[i].x0;
      span[2 * y + 1] = g.rects[i].x1;
    }
  }
  return count;
}

}  // namespace lb
