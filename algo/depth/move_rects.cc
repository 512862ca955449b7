// Where an expansion move looks (MoveBook::MoveRects): the rectangles of a grid whose nodes it
// may free, and per row the columns whose D it computes.
#include "algo/depth/move_book.h"

#include <cstring>

#include "algo/core/clones.h"

namespace lb {
namespace {

constexpr uint16_t kNotComputed = MoveGrid::kNotComputed;

// The first and the last column of a row whose label is in lo..hi, which the row holds: 16
// labels at a time (one unsigned compare each, in the compiler's generic vectors: SSE2 or NEON),
// then one by one.
void LabelsIn(const uint8_t* f, int32_t w, int32_t lo, int32_t hi, int32_t* x0, int32_t* x1) {
  constexpr int32_t kStep = 16;
  typedef uint8_t Bytes __attribute__((vector_size(kStep)));
  typedef uint64_t Words __attribute__((vector_size(kStep)));
  const uint8_t base = static_cast<uint8_t>(lo), width = static_cast<uint8_t>(hi - lo);
  auto in = [&](int32_t x) { return static_cast<uint8_t>(f[x] - base) <= width; };
  auto any = [&](int32_t x) {
    Bytes v;
    memcpy(&v, f + x, kStep);
    const Words m = reinterpret_cast<Words>((v - base) <= width);
    return (m[0] | m[1]) != 0;
  };
  int32_t a = 0;
  while (a + kStep <= w && !any(a)) a += kStep;
  while (!in(a)) ++a;
  int32_t b = w;
  while (b - kStep >= a && !any(b - kStep)) b -= kStep;
  while (!in(b - 1)) --b;
  *x0 = a;
  *x1 = b;
}

}  // namespace

// A move looks at rectangles: the whole grid for a full move. A restricted move frees only
// nodes with a label within `window` of alpha in their 3x3 neighbourhood, so it looks at the runs
// of rows next to such a label, each over the columns from the first to the last of them. The
// rows between runs keep their labels, which makes each rectangle's cut independent of the
// others.
int32_t MoveBook::MoveRects(MoveGrid& g, int32_t alpha, int32_t window, bool fine) {
  const int32_t w = g.width, h = g.height;
  int32_t* t = g.prev_span;
  g.prev_span = g.span;
  g.span = t;
  int32_t* span = g.span;
  // The pixels' D of this move goes where the move before last left its own (Record swaps the
  // two buffers): back to "not computed" there, so that Record can tell which D the move before
  // this one computed (fine grid only; the coarse grid keeps no D for the refinement).
  if (fine && !subpixel_) g.written_count = 0;  // no sub-label fit to feed
  if (fine && subpixel_) {
    if (g.written_count < 0) {
      for (int32_t p = 0; p < w * h; ++p) g.cost_alpha[p] = kNotComputed;
    }
    for (int32_t i = 0; i < g.written_count; ++i) {
      const MoveRect& r = g.written[i];
      for (int32_t y = r.y0; y < r.y1; ++y) {
        uint16_t* d = g.cost_alpha + y * w;
        for (int32_t x = r.x0; x < r.x1; ++x) d[x] = kNotComputed;
      }
    }
    g.written_count = 0;
  }
  if (window >= labels_ - 1) {
    for (int32_t y = 0; y < h; ++y) {
      span[2 * y] = 0;
      span[2 * y + 1] = w;
    }
    g.rects[0] = MoveRect{0, w, 0, h};
    g.rect_count = 1;
    return 1;
  }
  const int32_t lo = alpha - window > 0 ? alpha - window : 0;
  const int32_t hi = alpha + window < labels_ - 1 ? alpha + window : labels_ - 1;
  uint64_t want[4] = {};
  for (int32_t l = lo; l <= hi; ++l) want[l >> 6] |= uint64_t{1} << (l & 63);
  // Each row's own columns with such a label: [w, 0) when none. Also where the move computes D
  // (ComputeNear: next to such a label). The sub-label fit wants D(alpha) of the pixels that take
  // alpha + 1 in the next move too, which may lie next to none (with a label of alpha + 3): Record
  // has those computed afterwards, far fewer than the pixels next to a label of alpha + 3.
  near_lo_ = lo;
  near_hi_ = hi;
  for (int32_t y = 0; y < h; ++y) {
    const uint64_t* m = g.row_labels + 4 * y;
    int32_t x0 = w, x1 = 0;
    if (((m[0] & want[0]) | (m[1] & want[1]) | (m[2] & want[2]) | (m[3] & want[3])) != 0) {
      LabelsIn(g.labels + y * w, w, lo, hi, &x0, &x1);  // the row holds one
    }
    span[2 * y] = g.near_span[2 * y] = x0;
    span[2 * y + 1] = g.near_span[2 * y + 1] = x1;
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
    MoveRect r{w, 0, y, y};
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
  // Each run's rectangle, split until no split is left (or the list is full): the cuts and the
  // data term then cover far fewer fixed pixels.
  for (int32_t i = 0; i < count;) {
    const int32_t after = SplitRect(g, i, count, lo, hi);
    if (after < 0) {
      ++i;
    } else {
      count = after;
    }
  }
  g.rect_count = count;
  return count;
}

// A rectangle R of a restricted move holds every pixel within one of a label near alpha (the
// set S) among its own, and the ring of pixels around it holds no such pixel. A column of R
// with no S in it or in the columns either side (within R) then holds no pixel the move may
// free, nor does a row likewise; and the pixels of R either side of such a line are never
// neighbours of each other nor of S on the other side. So R can be cut into the runs of the
// other columns (or rows), each again such a rectangle, and the cuts over them together are
// the cut over R: the same labels. Returns the new count of rectangles when rects[i] changed
// (it is to be looked at again), or -1 when it cannot be split.
int32_t MoveBook::SplitRect(MoveGrid& g, int32_t i, int32_t count, int32_t lo, int32_t hi) {
  const int32_t w = g.width;
  const uint8_t width = static_cast<uint8_t>(hi - lo);
  const uint8_t base = static_cast<uint8_t>(lo);
  const MoveRect r = g.rects[i];
  uint8_t* mark = split_ + 1;  // mark[-1] and mark[n] are 0
  for (int pass = 0; pass < 2; ++pass) {
    const bool columns = pass == 0;
    const int32_t a0 = columns ? r.x0 : r.y0, a1 = columns ? r.x1 : r.y1;
    mark[a0 - 1] = mark[a1] = 0;
    if (columns) {
      for (int32_t x = r.x0; x < r.x1; ++x) mark[x] = 0;
      for (int32_t y = r.y0; y < r.y1; ++y) {
        const uint8_t* f = g.labels + y * w;
        for (int32_t x = r.x0; x < r.x1; ++x)
          mark[x] |= static_cast<uint8_t>(static_cast<uint8_t>(f[x] - base) <= width);
      }
    } else {
      for (int32_t y = r.y0; y < r.y1; ++y) {
        const uint8_t* f = g.labels + y * w;
        uint8_t any = 0;
        for (int32_t x = r.x0; x < r.x1; ++x)
          any |= static_cast<uint8_t>(static_cast<uint8_t>(f[x] - base) <= width);
        mark[y] = any;
      }
    }
    // The runs of lines next to a marked one.
    int32_t pieces = 0, first0 = a1, first1 = a1, last = -1;  // last: R's last piece so far
    for (int32_t k = a0; k < a1;) {
      if ((mark[k - 1] | mark[k] | mark[k + 1]) == 0) {
        ++k;
        continue;
      }
      const int32_t k0 = k;
      while (k < a1 && (mark[k - 1] | mark[k] | mark[k + 1]) != 0) ++k;
      if (pieces == 0) {
        first0 = k0;
        first1 = k;
      } else {
        MoveRect piece = r;
        (columns ? piece.x0 : piece.y0) = k0;
        (columns ? piece.x1 : piece.y1) = k;
        if (count < g.rect_capacity) {
          last = count;
          g.rects[count++] = piece;
        } else if (last >= 0) {  // full: R's last piece takes in the rest
          (columns ? g.rects[last].x1 : g.rects[last].y1) = k;
        } else {
          first1 = k;
        }
      }
      ++pieces;
    }
    if (pieces == 0) {  // no pixel to free (cannot happen for a run; kept safe)
      g.rects[i] = g.rects[count - 1];
      return count - 1;
    }
    if (first0 != a0 || first1 != a1) {
      MoveRect& first = g.rects[i];
      (columns ? first.x0 : first.y0) = first0;
      (columns ? first.x1 : first.y1) = first1;
      return count;
    }
  }
  return -1;
}

// A restricted move needs D only at the pixels it may free: next to a label within the window of
// alpha (near_lo_..near_hi_), in the row or the rows either side. Per row, the runs of such
// columns (RowRuns: joined where close, at most a few), over the whole image in one pass of the
// data term (its ring covers every row's runs, the image pays its 2 starting rows once, and each
// view row is read once: the move's rectangles may share rows). The others keep kNotComputed,
// which pass 1 never reads (they are fixed as far from alpha whatever their D); the sub-label
// fit mostly finds its D(alpha) at hand, and Record has the rest computed (PastCosts). Written
// records a rectangle per run of rows with the same single run, or each run, exactly where D
// was computed.
LB_CLONES_AVX2 void MoveBook::ComputeNear(MoveGrid& fine, const LabelTerm& term, int32_t disp_q8) {
  const MoveGrid& g = fine;
  const int32_t w = g.width, h = g.height;
  const MoveRect whole{0, w, 0, h};
  const uint8_t base = static_cast<uint8_t>(near_lo_);
  const uint8_t width = static_cast<uint8_t>(near_hi_ - near_lo_);
  uint8_t* const near = run_marks_ + 1;      // near[-1 .. w]: a label near in the column
  uint8_t* const mark = run_marks_ + w + 3;  // mark[x]: one next to column x
  for (int32_t y = 0; y < h; ++y) {
    int32_t lo = 0, hi = 0;
    NearColumns(g, false, whole, y, &lo, &hi);
    if (lo >= hi) {
      runs_[y].count = 0;
      continue;
    }
    const uint8_t* f = g.labels + y * w;
    const int32_t a = lo > 0 ? lo - 1 : 0, b = hi < w ? hi + 1 : w;
    MarkNearLabels(y > 0 ? f - w : f, f, y + 1 < h ? f + w : f, base, width, a, b, near);
    near[a - 1] = near[b] = 0;
    for (int32_t x = lo; x < hi; ++x) {
      mark[x] = static_cast<uint8_t>(near[x - 1] | near[x] | near[x + 1]);
    }
    runs_[y].FromMarks(mark, lo, hi, w, term.data.RunJoin());
  }
  term.data.ComputeRuns(disp_q8, runs_, 0, h, g.cost_alpha, w);
  for (int32_t y0 = 0; y0 < h;) {
    const RowRuns& a = runs_[y0];
    int32_t y1 = y0 + 1;
    if (a.count == 1) {
      while (y1 < h && runs_[y1].count == 1 && runs_[y1].x[0] == a.x[0] &&
             runs_[y1].x[1] == a.x[1]) {
        ++y1;
      }
    }
    for (int32_t k = 0; k < a.count; ++k)
      Written(fine, MoveRect{a.x[2 * k], a.x[2 * k + 1], y0, y1});
    y0 = y1;
  }
}

}  // namespace lb
