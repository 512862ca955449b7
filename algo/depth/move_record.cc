// What an expansion move leaves behind (MoveBook::Record): its switches on the grid, the energy
// change, and on the fine grid the D either side of each pixel's label for the sub-label fit.
#include <cstring>

#include "algo/core/clones.h"
#include "algo/core/int_math.h"
#include "algo/depth/move_book.h"

namespace lb {
namespace {

constexpr uint8_t kTake = MoveGrid::kTake;
constexpr uint16_t kNotComputed = MoveGrid::kNotComputed;

}  // namespace

void MoveBook::Carve(Arena& arena, const DepthConfig& config) {
  const int32_t w = config.width, h = config.height;
  width_ = w;
  height_ = h;
  labels_ = config.labels;
  subpixel_ = config.subpixel;
  want_span_ = arena.Allocate<int32_t>(2 * static_cast<size_t>(h));
  split_ = arena.Allocate<uint8_t>(static_cast<size_t>(w > h ? w : h) + 2);
  runs_ = arena.Allocate<RowRuns>(static_cast<size_t>(h));
  run_marks_ = arena.Allocate<uint8_t>(2 * (static_cast<size_t>(w) + 2));
  below_ = above_ = nullptr;
}

void MoveBook::SetFitMemory(uint16_t* fit) {
  below_ = fit;
  above_ = fit == nullptr ? nullptr : fit + static_cast<size_t>(width_) * height_;
}

void MoveBook::Start(int32_t smooth_trunc) {
  for (int32_t d = 0; d < DepthConfig::kMaxLabels; ++d) {
    smooth_[d] = d < smooth_trunc ? d : smooth_trunc;
  }
  prev_label_ = -1;
  for (int32_t y = 0; y < height_; ++y) {
    want_span_[2 * y] = width_;
    want_span_[2 * y + 1] = 0;
  }
}

void MoveBook::StartFine(MoveGrid& fine) {
  const int32_t w = width_, h = height_;
  for (int32_t p = 0; p < w * h; ++p) {
    below_[p] = above_[p] = 0xffff;
    fine.cost_alpha[p] = fine.prev_alpha[p] = kNotComputed;  // as MoveRects keeps them
  }
  fine.written_count = fine.prev_written_count = 0;
  for (int32_t y = 0; y < h; ++y) {
    fine.span[2 * y] = fine.span[2 * y + 1] = 0;
    fine.row_took[y] = 0;
  }
}

// The sub-label fit's D of the pixels that keep a label next to alpha: D(alpha) is D(f + 1) of a
// pixel of label alpha - 1 and D(f - 1) of one of label alpha + 1. Without branches, so that
// the loop vectorizes.
LB_CLONES_AVX2 void MoveBook::RecordNeighbours(int32_t alpha, const uint8_t* __restrict st,
                                               const uint8_t* __restrict f,
                                               const uint16_t* __restrict ca,
                                               uint16_t* __restrict below,
                                               uint16_t* __restrict above, int32_t x0, int32_t x1) {
  // Label 255 has no alpha + 1 and label 0 no alpha - 1: 256 and -1 match no uint8_t.
  const int32_t up = alpha + 1, down = alpha - 1;
  for (int32_t x = x0; x < x1; ++x) {
    const uint16_t keeps = st[x] != kTake ? 0xffff : 0;
    const uint16_t b = f[x] == up ? keeps : 0, a = f[x] == down ? keeps : 0;
    below[x] = static_cast<uint16_t>((ca[x] & b) | (below[x] & ~b));
    above[x] = static_cast<uint16_t>((ca[x] & a) | (above[x] & ~a));
  }
}

// Applies the move's switches. On the pixels it also keeps D_p(f_p - 1) and D_p(f_p + 1) for
// the sub-label fit without another pass of the data term: moves run in label order, so a pixel
// that keeps label f saw D(f - 1) and D(f + 1) in the moves before and after f, and one that
// just took alpha saw D(alpha - 1) in the move before (kept in prev_alpha) when it lay in the
// columns that move's run of rows looked at (prev_span), and will see D(alpha + 1) in the next.
// A restricted move looks at every pixel within its window, so at every pixel of label alpha - 1
// and alpha + 1. The move before computed D only next to labels within its window (and on its
// split rectangles, move_rects.cc); a pixel of its columns that now took alpha without one gets
// its D(alpha - 1) here, all such pixels of the move in one pass of the data term
// (PastCosts), so the fit depends neither on how the rectangles were split nor on where the
// move before looked.
//
// Returns the energy change: each switching pixel's D, and its pairs with the neighbours that
// keep their labels; a pair of two switching pixels goes from V(fp, fq) to 0 and is counted once,
// from its left or upper pixel, whose labels are still the old ones then (the rectangles' rings
// never switch, so a neighbour outside the rectangle keeps its label).
int64_t MoveBook::Record(MoveGrid& g, int32_t alpha, bool fine, const LabelTerm& term) {
  const int32_t w = g.width, h = g.height;
  int64_t delta = 0;
  const bool refine = fine && subpixel_;  // the labels alone need none of it
  const bool have_prev = refine && prev_label_ == alpha - 1;
  for (int32_t i = 0; i < g.rect_count; ++i) {
    const MoveRect& r = g.rects[i];
    for (int32_t y = r.y0; y < r.y1; ++y) {
      const uint8_t* st = g.state + y * w;
      const uint8_t* f = g.labels + y * w;
      const uint16_t* ca = g.cost_alpha + y * w;
      if (refine) RecordNeighbours(alpha, st, f, ca, below_ + y * w, above_ + y * w, r.x0, r.x1);
      if (g.row_took[y] == 0) continue;  // the cut marks the rows where a pixel takes alpha
      const int32_t px0 = have_prev ? g.prev_span[2 * y] : 0;
      const int32_t px1 = have_prev ? g.prev_span[2 * y + 1] : 0;
      for (int32_t x = r.x0; x < r.x1; ++x) {
        const void* next = memchr(st + x, kTake, static_cast<size_t>(r.x1 - x));
        if (next == nullptr) break;
        x = static_cast<int32_t>(static_cast<const uint8_t*>(next) - st);
        const int32_t p = y * w + x;
        const int32_t fp = f[x];
        delta += g.cost_alpha[p] - g.cost[p];
        auto pair = [&](int32_t q, int32_t wpq, bool first, bool inside) {
          const bool takes = inside && g.state[q] == kTake;
          if (takes && !first) return;
          const int32_t fq = g.labels[q];
          const int32_t after = takes ? 0 : smooth_[Abs(alpha - fq)];
          delta += int64_t{wpq} * (after - smooth_[Abs(fp - fq)]);
        };
        if (x + 1 < w) pair(p + 1, g.weight_right[p], true, x + 1 < r.x1);
        if (x > 0) pair(p - 1, g.weight_right[p - 1], false, x > r.x0);
        if (y + 1 < h) pair(p + w, g.weight_down[p], true, y + 1 < r.y1);
        if (y > 0) pair(p - w, g.weight_down[p - w], false, y > r.y0);
        g.labels[p] = static_cast<uint8_t>(alpha);
        MoveLabel(g, labels_, y, fp, alpha);
        g.cost[p] = g.cost_alpha[p];
        if (!refine) continue;
        below_[p] = kNotComputed;
        if (x >= px0 && x < px1) {
          below_[p] = g.prev_alpha[p];
          if (below_[p] == kNotComputed) {  // PastCosts fills it in
            below_[p] = kWanted;
            int32_t* want = want_span_ + 2 * y;
            want[0] = x < want[0] ? x : want[0];
            want[1] = x + 1 > want[1] ? x + 1 : want[1];
          }
        }
        above_[p] = kNotComputed;
      }
    }
  }
  for (int32_t i = 0; i < g.rect_count; ++i) {
    for (int32_t y = g.rects[i].y0; y < g.rects[i].y1; ++y) {
      g.row_took[y] = 0;
    }
  }
  if (have_prev) PastCosts(g, term, alpha - 1);
  if (refine) {
    uint16_t* t = g.prev_alpha;
    g.prev_alpha = g.cost_alpha;
    g.cost_alpha = t;
    MoveRect* tw = g.prev_written;
    g.prev_written = g.written;
    g.written = tw;
    const int32_t count = g.prev_written_count;
    g.prev_written_count = g.written_count;
    g.written_count = count;
    prev_label_ = alpha;
  }
  return delta;
}

// The D(label) that Record wanted (kWanted in below_, over want_span_): the rows' runs of them
// in one pass of the data term, into prev_alpha, which holds D(label) (the same bits as any
// other pass: a pixel's D depends only on the views around it); the columns the runs join
// across get D(label) too, and prev_alpha's record of where it holds D grows by the runs, so
// that MoveRects clears them in turn.
void MoveBook::PastCosts(MoveGrid& fine, const LabelTerm& term, int32_t label) {
  MoveGrid& g = fine;
  const int32_t w = g.width, h = g.height;
  uint8_t* const mark = run_marks_ + w + 3;
  int32_t y0 = h, y1 = 0;
  for (int32_t y = 0; y < h; ++y) {
    int32_t* want = want_span_ + 2 * y;
    if (want[0] >= want[1]) {
      runs_[y].count = 0;
      continue;
    }
    const uint16_t* b = below_ + y * w;
    for (int32_t x = want[0]; x < want[1]; ++x) mark[x] = b[x] == kWanted ? 1 : 0;
    runs_[y].FromMarks(mark, want[0], want[1], w, term.data.RunJoin());
    y0 = y < y0 ? y : y0;
    y1 = y + 1;
  }
  if (y0 >= y1) return;
  term.Use(label);
  term.data.ComputeRuns(term.DispQ8(label), runs_, y0, y1, g.prev_alpha + y0 * w, w);
  for (int32_t y = y0; y < y1; ++y) {
    int32_t* want = want_span_ + 2 * y;
    uint16_t* b = below_ + y * w;
    const uint16_t* d = g.prev_alpha + y * w;
    for (int32_t x = want[0]; x < want[1]; ++x) b[x] = b[x] == kWanted ? d[x] : b[x];
    want[0] = w;
    want[1] = 0;
    const RowRuns& r = runs_[y];
    for (int32_t k = 0; k < r.count; ++k) {
      NoteWritten(g.prev_written, &g.prev_written_count, g.written_capacity,
                  MoveRect{r.x[2 * k], r.x[2 * k + 1], y, y + 1});
    }
  }
}

}  // namespace lb
