// One alpha-expansion move of the depth stage over a rectangle: which nodes the move can change,
// the 2-label graph over them, and the cut. The 2-label move energy per neighbour
// pair, with x = 1 meaning "switch to alpha", A = V(fp,fq), B = V(fp,alpha), C = V(alpha,fq),
// V(alpha,alpha) = 0, is
//   A + (C - A) x_p - C x_q + (B + C - A) (1 - x_p) x_q,
// and B + C - A >= 0 because truncated linear is a metric, so every move is a graph cut.
#include "algo/depth/expansion_move.h"

#include <cstring>

#include "algo/core/clones.h"

namespace lb {

namespace {

constexpr uint8_t kFree = MoveGrid::kFree, kKeep = MoveGrid::kKeep, kTake = MoveGrid::kTake;

}  // namespace

void ExpansionMove::Carve(Arena& arena, const DepthConfig& config, size_t spare_bytes) {
  const int32_t w = config.width, h = config.height;
  width_ = w;
  labels_ = config.labels;
  maxflow_.Carve(arena, w, h, spare_bytes, (w + 1) / 2, (h + 1) / 2);
  move_rows_ = arena.Allocate<int32_t>(11 * static_cast<size_t>(w));
  keep_row_ = arena.Allocate<uint8_t>(static_cast<size_t>(w));
  free_span_ = arena.Allocate<int32_t>(2 * static_cast<size_t>(h));
}

void ExpansionMove::Start(int32_t smooth_trunc) {
  trunc_ = smooth_trunc;
  for (int32_t x = 0; x < width_; ++x) keep_row_[x] = kKeep;
  for (int32_t x = 0; x < width_; ++x) move_rows_[9 * width_ + x] = 0;  // ZeroRow
}

// Pass 1: pixels whose choice does not depend on their neighbours are fixed before the cut.
// Flipping p to alpha changes the energy by u_p plus, per neighbour q, C - A (q keeps its label)
// or -B (q takes alpha); -B is the smaller of the two (the triangle inequality), so if
// u_p - B * sum(w_pq) > 0, p keeps its label in every optimal move, and if u_p + sum(C - A) < 0,
// p takes alpha. The bound u_p > trunc * sum(w_pq) settles textured pixels without looking at
// the neighbours.
//
// Written as e_pq = B + C - A of each pair (symmetric in p and q, >= 0), C - A = e_pq - w_pq b_p
// with b_p = V(fp, alpha) / w_pq, so u_p + sum(C - A) = u_p - b_p sum(w_pq) + sum(e_pq): one
// branch-free pass per row. Row y keeps its e_pq to the right and down and that sum in the ring
// slot y % 3 for pass 2. Returns kRowFree | kRowTake for the states present in the row.
//
// Columns x0..x1-1 are classified (the caller fixed the others as far from alpha), and the pairs
// down are kept over e0..e1-1, which also covers the next row's x0..x1-1 (its sums read them).
LB_CLONES_AVX2 int32_t ExpansionMove::ClassifyRow(MoveGrid& g, int32_t alpha, int32_t y, int32_t x0,
                                                  int32_t x1, int32_t e0, int32_t e1) {
  const int32_t w = g.width, h = g.height;
  const int32_t k = trunc_;
  const int32_t row = y * w;
  const uint8_t* f = g.labels + row;
  const uint8_t* fd = y + 1 < h ? f + w : f;  // the last row's down weights are 0
  const uint16_t* wr = g.weight_right + row;
  const uint16_t* wd = g.weight_down + row;
  int32_t* er = Ring(y, kPairRight);
  int32_t* ed = Ring(y, kPairDown);
  int32_t* hi = Ring(y, kHigh);
  auto v = [k](int32_t a, int32_t b) {
    const int32_t d = a > b ? a - b : b - a;
    return d < k ? d : k;
  };
  // Pairs to the right from x0 - 1 (the left neighbour, fixed or not, is paired with x0).
  const int32_t xe = x1 < w ? x1 : w - 1;
  for (int32_t x = x0 > 0 ? x0 - 1 : 0; x < xe; ++x) {
    er[x] = wr[x] * (v(f[x], alpha) + v(f[x + 1], alpha) - v(f[x], f[x + 1]));
  }
  if (x1 == w) er[w - 1] = 0;
  for (int32_t x = e0; x < e1; ++x) {
    ed[x] = wd[x] * (v(f[x], alpha) + v(fd[x], alpha) - v(f[x], fd[x]));
  }
  // The first row's pairs up are a row of zeros (ZeroRow).
  const uint16_t* wu = y > 0 ? wd - w : reinterpret_cast<const uint16_t*>(ZeroRow());
  const int32_t* eu = y > 0 ? Ring(y - 1, kPairDown) : ZeroRow();
  // Restricted moves: which columns hold a label near alpha in rows y - 1..y + 1.
  uint8_t* near = reinterpret_cast<uint8_t*>(move_rows_ + 10 * width_) + 1;
  const bool restricted = !Full();
  if (restricted) {
    const int32_t lo = alpha - window_, top = alpha + window_;
    const uint8_t* fu = y > 0 ? f - w : f;
    const uint8_t base = static_cast<uint8_t>(lo > 0 ? lo : 0);
    const uint8_t width = static_cast<uint8_t>((top < 255 ? top : 255) - base);
    const int32_t xe1 = x1 + 1 < w ? x1 + 1 : w;
    MarkNearLabels(fu, f, fd, base, width, x0 > 0 ? x0 - 1 : 0, xe1, near);
    if (x0 == 0) near[-1] = 0;
    if (x1 == w) near[w] = 0;
  }
  const uint16_t* ca = g.cost_alpha + row;
  const uint16_t* cc = g.cost + row;
  uint8_t* state = g.state + row;
  const uint8_t full = restricted ? 0 : 1;
  static_assert(kRowFree == 1 && kRowTake == 2);
  return StatesRow(f, wr, wd, wu, er, ed, eu, ca, cc, near, alpha, k, full, x0, x1, hi, state);
}

// Pass 1's states of pixels x0..x1-1 of a row (ClassifyRow), without branches so that the loop
// vectorizes (its own function: the pointers it is handed do not overlap); returns kRowFree |
// kRowTake for the states present.
LB_CLONES_AVX2 uint8_t ExpansionMove::StatesRow(
    const uint8_t* __restrict f, const uint16_t* __restrict wr, const uint16_t* __restrict wd,
    const uint16_t* __restrict wu, const int32_t* __restrict er, const int32_t* __restrict ed,
    const int32_t* __restrict eu, const uint16_t* __restrict ca, const uint16_t* __restrict cc,
    const uint8_t* __restrict near, int32_t alpha, int32_t k, uint8_t full, int32_t x0, int32_t x1,
    int32_t* __restrict hi, uint8_t* __restrict state) {
  auto v = [k](int32_t a, int32_t b) {
    const int32_t d = a > b ? a - b : b - a;
    return d < k ? d : k;
  };
  uint8_t any_free = 0, any_take = 0;
  for (int32_t x = x0; x < x1; ++x) {
    const int32_t sw = wr[x] + wd[x] + wu[x] + (x > 0 ? wr[x - 1] : 0);  // the pair weights
    const int32_t u = ca[x] - cc[x];
    int32_t limit = sw * k;
    limit = limit < 0xffff ? limit : 0xffff;
    const int32_t lo = u - v(f[x], alpha) * sw;
    const int32_t high = er[x] + ed[x] + eu[x] + (x > 0 ? er[x - 1] : 0) + lo;
    hi[x] = high;
    const uint8_t far = (near[x - 1] | near[x] | near[x + 1] | full) == 0;
    const uint8_t keep = static_cast<uint8_t>(u > limit) | static_cast<uint8_t>(f[x] == alpha) |
                         static_cast<uint8_t>(lo > 0) | far;
    const uint8_t take = static_cast<uint8_t>(keep == 0) & static_cast<uint8_t>(high < 0);
    state[x] = keep != 0 ? kKeep : (take != 0 ? kTake : kFree);
    any_free |= static_cast<uint8_t>((keep | take) == 0);
    any_take |= take;
  }
  return static_cast<uint8_t>((any_free != 0 ? kRowFree : 0) | (any_take != 0 ? kRowTake : 0));
}

// The pairs from row y (fixed: above a rectangle) down into the rectangle's first row.
void ExpansionMove::PairsDown(const MoveGrid& g, int32_t alpha, int32_t y, int32_t x0, int32_t x1) {
  const int32_t w = g.width, k = trunc_;
  const uint8_t* f = g.labels + y * w;
  const uint8_t* fd = f + w;
  const uint16_t* wd = g.weight_down + y * w;
  int32_t* ed = Ring(y, kPairDown);
  auto v = [k](int32_t a, int32_t b) {
    const int32_t d = a > b ? a - b : b - a;
    return d < k ? d : k;
  };
  for (int32_t x = x0; x < x1; ++x) {
    ed[x] = wd[x] * (v(f[x], alpha) + v(fd[x], alpha) - v(f[x], fd[x]));
  }
}

// BuildRow's terms of pixels x0..x1-1 of a row (state st, the rows above and below up and
// down), 0 for fixed pixels. The left neighbour of x0 and the right one of x1 - 1 are the row's
// own when inside the rectangle's columns r0..r1-1, else they keep their labels: the first and
// last pixel are peeled.
LB_CLONES_AVX2 void ExpansionMove::BuildTerms(
    const uint8_t* __restrict st, const uint8_t* __restrict up, const uint8_t* __restrict down,
    const int32_t* __restrict er, const int32_t* __restrict ed, const int32_t* __restrict eu,
    const int32_t* __restrict hi, int32_t x0, int32_t x1, int32_t r0, int32_t r1,
    int32_t* __restrict balance, int32_t* __restrict cap_right, int32_t* __restrict cap_down) {
  auto terms = [&](int32_t x, uint8_t left, uint8_t right, int32_t e_left, int32_t e_right) {
    const int32_t free = st[x] == kFree ? -1 : 0;
    const int32_t b = hi[x] - (right == kTake ? e_right : 0) - (left != kKeep ? e_left : 0) -
                      (down[x] == kTake ? ed[x] : 0) - (up[x] != kKeep ? eu[x] : 0);
    balance[x] = b & free;
    cap_right[x] = (right == kFree ? e_right : 0) & free;
    cap_down[x] = (down[x] == kFree ? ed[x] : 0) & free;
  };
  const uint8_t left = x0 > r0 ? st[x0 - 1] : uint8_t{kKeep};
  const int32_t e_left = x0 > r0 ? er[x0 - 1] : 0;
  const uint8_t right = x1 < r1 ? st[x1] : uint8_t{kKeep};
  const int32_t e_right = x1 < r1 ? er[x1 - 1] : 0;
  if (x1 - x0 == 1) {
    terms(x0, left, right, e_left, e_right);
    return;
  }
  terms(x0, left, st[x0 + 1], e_left, er[x0]);
  for (int32_t x = x0 + 1; x < x1 - 1; ++x) terms(x, st[x - 1], st[x + 1], er[x - 1], er[x]);
  terms(x1 - 1, st[x1 - 2], right, er[x1 - 2], e_right);
}

// Pass 2, one row behind pass 1: row y's nodes of the 2-label graph over the free pixels (node
// row `node_row`). A fixed neighbour q turns the pair into a unary term on p: C - A when q keeps
// its label, -B = C - A - e_pq when it takes alpha. A free right or down neighbour makes the arc
// p -> q of capacity e_pq (p's balance keeps C - A), and a free left or up neighbour q puts the
// -C of the pair (q, p), here -B = C - A - e_pq, on p's balance. Neighbours outside the
// rectangle keep their labels. Returns the free pixels.
//
// The terms are computed for every pixel of the row without branches (BuildTerms) and are 0 for
// fixed pixels, whose nodes are then the solver's idle nodes.
int32_t ExpansionMove::BuildRow(const MoveGrid& g, const MoveRect& r, int32_t y, int32_t node_row) {
  const int32_t w = g.width;
  const uint8_t* st = g.state + y * w;
  // Rows outside the rectangle keep their labels: a row of kKeep stands for them.
  const uint8_t* up = y > r.y0 ? st - w : keep_row_;
  const uint8_t* down = y + 1 < r.y1 ? st + w : keep_row_;
  const int32_t* er = Ring(y, kPairRight);
  const int32_t* ed = Ring(y, kPairDown);
  const int32_t* eu = y > r.y0 ? Ring(y - 1, kPairDown) : ed;  // unread when up is keep_row_
  const int32_t* hi = Ring(y, kHigh);
  // Only the nodes a free node can reach are set (Reach); the others are never read. The terms
  // are needed only from the row's first free pixel to its last, and go straight to the
  // solver's staging rows; the other reachable nodes are idle.
  int32_t x0 = r.x0, x1 = r.x1;
  Reach(r, y, &x0, &x1);
  const int32_t* span = free_span_ + 2 * y;
  const int32_t f0 = span[0], f1 = span[1];
  const int32_t base = node_row * (r.x1 - r.x0) - r.x0;
  ptrdiff_t stride = 0;
  int32_t* const balance = maxflow_.Staged(base, &stride);
  if (x0 > r.x0) maxflow_.SetIdle(base + r.x0);
  if (x1 < r.x1) maxflow_.SetIdle(base + r.x1 - 1);
  int32_t free_pixels = 0;
  if (f0 < f1) {
    BuildTerms(st, up, down, er, ed, eu, hi, f0, f1, r.x0, r.x1, balance, balance + stride,
               balance + 2 * stride);
    for (int32_t x = f0; x < f1; ++x) free_pixels += st[x] == kFree ? 1 : 0;
  }
  const int32_t idle_end = f0 < f1 ? f0 : x1;
  for (int32_t k = 0; k < 3; ++k) {
    int32_t* const row = balance + k * stride;
    if (idle_end > x0) memset(row + x0, 0, sizeof(int32_t) * static_cast<size_t>(idle_end - x0));
    if (f0 < f1 && x1 > f1) memset(row + f1, 0, sizeof(int32_t) * static_cast<size_t>(x1 - f1));
  }
  // The solver's row passes look only from the first free pixel to the last.
  if (free_pixels > 0) {
    maxflow_.RowDone(node_row, f0 - r.x0, f1 - r.x0);
  } else {
    maxflow_.RowDone(node_row, 0, 0);
  }
  return free_pixels;
}

// Row y's free pixels within r (after ClassifyRow): [first, last + 1) into free_span_, empty
// at r.x0 when none.
void ExpansionMove::FreeSpan(const MoveGrid& g, const MoveRect& r, int32_t y, bool any) {
  int32_t* span = free_span_ + 2 * y;
  span[0] = span[1] = r.x0;
  if (!any) return;
  const uint8_t* st = g.state + y * g.width;
  const void* first = memchr(st + r.x0, kFree, static_cast<size_t>(r.x1 - r.x0));  // one there
  const int32_t a = static_cast<int32_t>(static_cast<const uint8_t*>(first) - st);
  const void* last = memrchr(st + a, kFree, static_cast<size_t>(r.x1 - a));
  const int32_t b = static_cast<int32_t>(static_cast<const uint8_t*>(last) - st) + 1;
  span[0] = a;
  span[1] = b;
}

// The columns of row y (of rectangle r) whose nodes a free node may look at: its own free
// pixels and those of the rows above and below, one column either side, as one interval. A row's
// first and last node also neighbour the rows before and after in node order, so the caller
// sets them as well.
void ExpansionMove::Reach(const MoveRect& r, int32_t y, int32_t* x0, int32_t* x1) const {
  int32_t lo = r.x1, hi = r.x0;
  for (int32_t k = y > r.y0 ? y - 1 : y; k <= y + 1 && k < r.y1; ++k) {
    const int32_t* span = free_span_ + 2 * k;
    if (span[0] >= span[1]) continue;
    lo = span[0] - 1 < lo ? span[0] - 1 : lo;
    hi = span[1] + 1 > hi ? span[1] + 1 : hi;
  }
  *x0 = lo > r.x0 ? lo : r.x0;
  *x1 = hi < r.x1 ? hi : r.x1;
}

// Classifies and builds the rectangle's rows, cuts the graph and settles its free pixels.
int32_t ExpansionMove::Cut(MoveGrid& g, int32_t alpha, const MoveRect& r, int32_t window) {
  window_ = window;
  const int32_t w = g.width, gw = r.x1 - r.x0;
  if (r.y0 > 0) PairsDown(g, alpha, r.y0 - 1, r.x0, r.x1);
  // Rows with free or switching pixels (y_lo..y_hi), and the graph's rows g_lo..: rows without
  // a free pixel are left out at either end, and written as empty rows only between two others.
  int32_t y_lo = r.y1, y_hi = -1, g_lo = -1, rows = 0, pending = 0, free_pixels = 0;
  int32_t present = 0;
  // Pass 1 looks only at the columns of each row that are not far from alpha (NearColumns); the
  // others keep their labels.
  int32_t next0 = r.x0, next1 = r.x1;
  NearColumns(g, Full(), r, r.y0, &next0, &next1);
  for (int32_t y = r.y0; y <= r.y1; ++y) {
    const int32_t above = present;
    if (y < r.y1) {
      const int32_t c0 = next0, c1 = next1;
      next0 = next1 = r.x0;
      if (y + 1 < r.y1) NearColumns(g, Full(), r, y + 1, &next0, &next1);
      // The pairs down: over this row's columns and the next one's.
      int32_t e0 = c0, e1 = c1;
      if (next0 < next1) {
        e0 = c0 < c1 && c0 < next0 ? c0 : next0;
        e1 = c0 < c1 && c1 > next1 ? c1 : next1;
      }
      uint8_t* st = g.state + y * w;
      memset(st + r.x0, kKeep, static_cast<size_t>(c0 - r.x0));
      memset(st + c1, kKeep, static_cast<size_t>(r.x1 - c1));
      present = ClassifyRow(g, alpha, y, c0, c1, e0, e1);
      g.row_took[y] |= (present & kRowTake) != 0 ? 1 : 0;
      FreeSpan(g, r, y, (present & kRowFree) != 0);
      if (present != 0) {
        y_lo = y < y_lo ? y : y_lo;
        y_hi = y;
      }
    }
    if (y == r.y0) continue;
    if (!(above & kRowFree)) {
      pending += g_lo >= 0 ? 1 : 0;
      continue;
    }
    if (g_lo < 0) {
      g_lo = y - 1;
      maxflow_.Begin(gw, r.y1 - g_lo);
    }
    for (; pending > 0; --pending, ++rows) {
      int32_t u0 = 0, u1 = 0;
      Reach(r, y - 1 - pending, &u0, &u1);
      for (int32_t x = u0; x < u1; ++x) maxflow_.SetIdle(rows * gw + x - r.x0);
      maxflow_.SetIdle(rows * gw);
      maxflow_.SetIdle(rows * gw + gw - 1);
      maxflow_.RowDone(rows, 0, 0);
    }
    free_pixels += BuildRow(g, r, y - 1, rows++);
  }
  if (y_hi < 0) return 0;
  if (free_pixels > 0) {
    maxflow_.Truncate(rows);
    (void)maxflow_.Solve();
    for (int32_t gy = 0; gy < rows; ++gy) {
      uint8_t* st = g.state + (g_lo + gy) * w;
      uint8_t took = 0;
      const int32_t* span = free_span_ + 2 * (g_lo + gy);
      for (int32_t x = span[0]; x < span[1]; ++x) {
        if (st[x] == kFree) {
          st[x] = maxflow_.InSource(gy * gw + x - r.x0) ? kKeep : kTake;
          took |= static_cast<uint8_t>(st[x] == kTake);
        }
      }
      g.row_took[g_lo + gy] |= took;
    }
  }
  return free_pixels;
}

}  // namespace lb
