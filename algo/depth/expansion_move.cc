// One alpha-expansion move of the depth stage: which pixels the move can change, the 2-label
// graph over them, the cut, and the energy bookkeeping. The 2-label move energy per neighbour
// pair, with x = 1 meaning "switch to alpha", A = V(fp,fq), B = V(fp,alpha), C = V(alpha,fq),
// V(alpha,alpha) = 0, is
//   A + (C - A) x_p - C x_q + (B + C - A) (1 - x_p) x_q,
// and B + C - A >= 0 because truncated linear is a metric, so every move is a graph cut.
#include "algo/depth/depth_stage.h"

namespace lb {
namespace {

inline int32_t Abs(int32_t v) { return v < 0 ? -v : v; }

}  // namespace

// Pass 1: pixels whose choice does not depend on their neighbours are fixed before the cut.
// Flipping p to alpha changes the energy by u_p plus, per neighbour q, C - A (q keeps its label)
// or -B (q takes alpha); -B is the smaller of the two (the triangle inequality), so if
// u_p - B * sum(w_pq) > 0, p keeps its label in every optimal move, and if u_p + sum(C - A) < 0,
// p takes alpha. The bound u_p > trunc * sum(w_pq) settles textured pixels without looking at
// the neighbours. With a move margin, pixels for which alpha costs more than that above their
// label also keep it: a restricted move, still an exact cut over the pixels it frees, so the
// energy still never rises, over a much smaller graph.
//
// Written as e_pq = B + C - A of each pair (symmetric in p and q, >= 0), C - A = e_pq - w_pq b_p
// with b_p = V(fp, alpha) / w_pq, so u_p + sum(C - A) = u_p - b_p sum(w_pq) + sum(e_pq): one
// branch-free pass per row. Row y keeps its e_pq to the right and down and that sum in the ring
// slot y % 3 for pass 2. Returns kRowFree | kRowTake for the states present in the row.
int32_t DepthStage::ClassifyRow(int32_t alpha, int32_t y) {
  const int32_t w = config_.width, h = config_.height;
  const int32_t margin = config_.move_margin > 0 ? config_.move_margin : INT32_MAX;
  const int32_t k = config_.smooth_trunc;
  const int32_t row = y * w;
  const uint8_t* f = labels_ + row;
  const uint8_t* fd = y + 1 < h ? f + w : f;  // the last row's down weights are 0
  const uint16_t* wr = weight_right_ + row;
  const uint16_t* wd = weight_down_ + row;
  int32_t* er = Ring(y, kPairRight);
  int32_t* ed = Ring(y, kPairDown);
  int32_t* hi = Ring(y, kHigh);
  int32_t* sw = move_rows_ + 9 * w;  // each pixel's pair weights summed
  auto v = [k](int32_t a, int32_t b) {
    const int32_t d = a > b ? a - b : b - a;
    return d < k ? d : k;
  };
  for (int32_t x = 0; x + 1 < w; ++x) {
    er[x] = wr[x] * (v(f[x], alpha) + v(f[x + 1], alpha) - v(f[x], f[x + 1]));
  }
  er[w - 1] = 0;
  for (int32_t x = 0; x < w; ++x) {
    ed[x] = wd[x] * (v(f[x], alpha) + v(fd[x], alpha) - v(f[x], fd[x]));
  }
  sw[0] = wr[0] + wd[0];
  hi[0] = er[0] + ed[0];
  for (int32_t x = 1; x < w; ++x) {
    sw[x] = wr[x] + wr[x - 1] + wd[x];
    hi[x] = er[x] + er[x - 1] + ed[x];
  }
  if (y > 0) {
    const uint16_t* wu = wd - w;
    const int32_t* eu = Ring(y - 1, kPairDown);
    for (int32_t x = 0; x < w; ++x) {
      sw[x] += wu[x];
      hi[x] += eu[x];
    }
  }
  const uint16_t* ca = cost_alpha_ + row;
  const uint16_t* cc = cost_ + row;
  uint8_t* state = state_ + row;
  int32_t present = 0;
  for (int32_t x = 0; x < w; ++x) {
    const int32_t u = ca[x] - cc[x];
    int32_t limit = sw[x] * k;
    limit = limit < 0xffff ? limit : 0xffff;
    limit = limit < margin ? limit : margin;
    const int32_t lo = u - v(f[x], alpha) * sw[x];
    hi[x] += lo;
    const bool keep = u > limit || f[x] == alpha || lo > 0;
    const uint8_t s = keep ? kKeep : (hi[x] < 0 ? kTake : kFree);
    state[x] = s;
    present |= (s == kFree ? kRowFree : 0) | (s == kTake ? kRowTake : 0);
  }
  return present;
}

// Pass 2, one row behind pass 1: row y's nodes of the 2-label graph over the free pixels (node
// row `node_row`). A fixed neighbour q turns the pair into a unary term on p: C - A when q keeps
// its label, -B = C - A - e_pq when it takes alpha. A free right or down neighbour makes the arc
// p -> q of capacity e_pq (p's balance keeps C - A), and a free left or up neighbour q puts the
// -C of the pair (q, p), here -B = C - A - e_pq, on p's balance. Returns the free pixels.
int32_t DepthStage::BuildRow(int32_t y, int32_t node_row) {
  const int32_t w = config_.width, h = config_.height;
  const uint8_t* st = state_ + y * w;
  const uint8_t* up = y > 0 ? st - w : nullptr;
  const uint8_t* down = y + 1 < h ? st + w : nullptr;
  const int32_t* er = Ring(y, kPairRight);
  const int32_t* ed = Ring(y, kPairDown);
  const int32_t* eu = y > 0 ? Ring(y - 1, kPairDown) : nullptr;
  const int32_t* hi = Ring(y, kHigh);
  const int32_t base = node_row * w;
  int32_t free_pixels = 0;
  for (int32_t x = 0; x < w; ++x) {
    if (st[x] != kFree) {
      maxflow_.SetNode(base + x, 0, 0, 0);
      continue;
    }
    ++free_pixels;
    int32_t balance = hi[x];
    int32_t cap_right = 0, cap_down = 0;
    if (x + 1 < w) {
      if (st[x + 1] == kFree) cap_right = er[x];
      if (st[x + 1] == kTake) balance -= er[x];
    }
    if (x > 0 && st[x - 1] != kKeep) balance -= er[x - 1];
    if (down) {
      if (down[x] == kFree) cap_down = ed[x];
      if (down[x] == kTake) balance -= ed[x];
    }
    if (up && up[x] != kKeep) balance -= eu[x];
    maxflow_.SetNode(base + x, balance, cap_right, cap_down);
  }
  maxflow_.RowDone(node_row);
  return free_pixels;
}

bool DepthStage::Expand(int32_t alpha) {
  const int32_t w = config_.width, h = config_.height;
  LabelCosts(alpha, cost_alpha_);
  // Rows with free or switching pixels (y_lo..y_hi), and the graph's rows g_lo..: rows without
  // a free pixel are left out at either end, and written as empty rows only between two others.
  int32_t y_lo = h, y_hi = -1, g_lo = -1, rows = 0, pending = 0, free_pixels = 0;
  int32_t present = 0;
  for (int32_t y = 0; y <= h; ++y) {
    const int32_t above = present;
    if (y < h) {
      present = ClassifyRow(alpha, y);
      if (present != 0) {
        y_lo = y < y_lo ? y : y_lo;
        y_hi = y;
      }
    }
    if (y == 0) continue;
    if (!(above & kRowFree)) {
      pending += g_lo >= 0 ? 1 : 0;
      continue;
    }
    if (g_lo < 0) {
      g_lo = y - 1;
      maxflow_.Begin(w, h - g_lo);
    }
    for (; pending > 0; --pending, ++rows) {
      for (int32_t x = 0; x < w; ++x) maxflow_.SetNode(rows * w + x, 0, 0, 0);
      maxflow_.RowDone(rows);
    }
    free_pixels += BuildRow(y - 1, rows++);
  }
  if (y_hi < 0) {
    Record(alpha);
    return false;
  }
  stats_.cut_pixels += free_pixels;
  if (free_pixels > 0) {
    maxflow_.Truncate(rows);
    (void)maxflow_.Solve();
    const int32_t base = g_lo * w;
    for (int32_t p = base; p < base + rows * w; ++p) {
      if (state_[p] == kFree) state_[p] = maxflow_.InSource(p - base) ? kKeep : kTake;
    }
  }

  // Update the energy from the pixels that changed and their pair terms.
  int64_t delta = 0;
  for (int32_t y = y_lo; y <= y_hi; ++y) {
    for (int32_t x = 0; x < w; ++x) {
      const int32_t p = y * w + x;
      if (state_[p] != kTake) continue;
      const int32_t fp = labels_[p];
      delta += cost_alpha_[p] - cost_[p];
      // Pairs with an unchanged neighbour; a pair of two switching pixels goes from
      // V(fp, fq) to 0 and is counted once, from its left or upper pixel.
      auto pair = [&](int32_t q, int32_t wpq, bool first) {
        if (state_[q] == kTake && !(first && q > p)) return;
        const int32_t fq = labels_[q];
        const int32_t after = state_[q] == kTake ? 0 : smooth_[Abs(alpha - fq)];
        delta += int64_t{wpq} * (after - smooth_[Abs(fp - fq)]);
      };
      if (x + 1 < w) pair(p + 1, weight_right_[p], true);
      if (x > 0) pair(p - 1, weight_right_[p - 1], false);
      if (y + 1 < h) pair(p + w, weight_down_[p], true);
      if (y > 0) pair(p - w, weight_down_[p - w], false);
    }
  }
  energy_ += delta;
  Record(alpha);
  return delta < 0;
}

// Applies the move's switches and keeps D_p(f_p - 1) and D_p(f_p + 1) for the sub-label fit
// without another pass of the data term: moves run in label order, so a pixel that keeps label
// f saw D(f - 1) and D(f + 1) in the moves before and after f, and one that just took alpha saw
// D(alpha - 1) in the move before (kept in prev_alpha_) and will see D(alpha + 1) in the next.
void DepthStage::Record(int32_t alpha) {
  const int32_t n = config_.width * config_.height;
  const bool have_prev = prev_label_ == alpha - 1;
  for (int32_t p = 0; p < n; ++p) {
    const int32_t f = labels_[p];
    if (state_[p] == kTake) {
      labels_[p] = static_cast<uint8_t>(alpha);
      cost_[p] = cost_alpha_[p];
      below_[p] = have_prev ? prev_alpha_[p] : 0xffff;
      above_[p] = 0xffff;
    } else if (f == alpha + 1) {
      below_[p] = cost_alpha_[p];
    } else if (f + 1 == alpha) {
      above_[p] = cost_alpha_[p];
    }
  }
  uint16_t* t = prev_alpha_;
  prev_alpha_ = cost_alpha_;
  cost_alpha_ = t;
  prev_label_ = alpha;
}

}  // namespace lb
