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
// energy still never rises, over a much smaller graph. Returns the rows holding free or
// switching pixels in *y_lo..*y_hi (*y_hi < 0 when there are none).
void DepthStage::Classify(int32_t alpha, int32_t* y_lo, int32_t* y_hi) {
  const int32_t w = config_.width, h = config_.height;
  const int32_t margin = config_.move_margin > 0 ? config_.move_margin : INT32_MAX;
  const int32_t trunc = config_.smooth_trunc;
  *y_lo = h;
  *y_hi = -1;
  for (int32_t y = 0; y < h; ++y) {
    const int32_t row = y * w;
    uint8_t* state = state_ + row;
    const uint16_t* ca = cost_alpha_ + row;
    const uint16_t* cc = cost_ + row;
    const uint16_t* wr = weight_right_ + row;
    const uint16_t* wd = weight_down_ + row;
    // Each pixel's pair weights summed (<= 4 * 4096); the right weight of the last column and
    // the down weight of the last row are 0.
    uint16_t* sum_w = sum_w_;
    sum_w[0] = static_cast<uint16_t>(wr[0] + wd[0] + (y > 0 ? wd[-w] : 0));
    for (int32_t x = 1; x < w; ++x) {
      sum_w[x] = static_cast<uint16_t>(wr[x] + wr[x - 1] + wd[x] + (y > 0 ? wd[x - w] : 0));
    }
    bool open = false;
    for (int32_t x = 0; x < w; ++x) {
      const int32_t u = ca[x] - cc[x];
      int32_t limit = sum_w[x] * trunc;
      limit = limit < 0xffff ? limit : 0xffff;
      limit = limit < margin ? limit : margin;
      state[x] = u > limit ? kKeep : kFree;
      open |= u <= limit;
    }
    if (!open) continue;
    const uint8_t* f = labels_ + row;
    for (int32_t x = 0; x < w; ++x) {
      if (state[x] == kKeep) continue;
      const int32_t fp = f[x];
      const int32_t u = ca[x] - cc[x];
      if (fp == alpha || u - smooth_[Abs(fp - alpha)] * sum_w[x] > 0) {
        state[x] = kKeep;
        continue;
      }
      int32_t hi = u;
      auto keep = [&](int32_t fq, int32_t wpq) {
        hi += wpq * (smooth_[Abs(alpha - fq)] - smooth_[Abs(fp - fq)]);
      };
      if (x + 1 < w) keep(f[x + 1], wr[x]);
      if (x > 0) keep(f[x - 1], wr[x - 1]);
      if (y + 1 < h) keep(f[x + w], wd[x]);
      if (y > 0) keep(f[x - w], wd[x - w]);
      state[x] = hi < 0 ? kTake : kFree;
      *y_lo = y < *y_lo ? y : *y_lo;
      *y_hi = y;
    }
  }
}

// Pass 2: the graph over the free pixels of rows y_lo..y_hi (node = p - y_lo * w), each node
// written once. A fixed neighbour turns a pair term into a unary one, E(x_p) = a + (c - a) x_p
// with a = V(fp, lq), c = V(alpha, lq), lq the label the neighbour is fixed to; a free right or
// down neighbour adds the pair's arc p -> q, and a free left or up neighbour q the -C of the
// pair (q, p) to p's balance. Returns the number of free pixels.
int32_t DepthStage::BuildMove(int32_t alpha, int32_t y_lo, int32_t y_hi) {
  const int32_t w = config_.width, h = config_.height;
  const int32_t base = y_lo * w;
  maxflow_.Begin(w, y_hi - y_lo + 1);
  int32_t free_pixels = 0;
  for (int32_t y = y_lo; y <= y_hi; ++y) {
    for (int32_t x = 0; x < w; ++x) {
      const int32_t p = y * w + x;
      if (state_[p] != kFree) {
        maxflow_.SetNode(p - base, 0, 0, 0);
        continue;
      }
      ++free_pixels;
      const int32_t fp = labels_[p];
      const int32_t b1 = smooth_[Abs(fp - alpha)];  // B / w_pq, and C / w_pq of (q, p)
      int32_t balance = cost_alpha_[p] - cost_[p];
      int32_t cap_right = 0, cap_down = 0;
      auto fixed = [&](int32_t q, int32_t wpq) {
        const int32_t lq = state_[q] == kTake ? alpha : labels_[q];
        balance += wpq * (smooth_[Abs(alpha - lq)] - smooth_[Abs(fp - lq)]);
      };
      auto forward = [&](int32_t q, int32_t wpq, int32_t* cap) {
        if (state_[q] != kFree) return fixed(q, wpq);
        const int32_t fq = labels_[q];
        const int32_t a = wpq * smooth_[Abs(fp - fq)], c = wpq * smooth_[Abs(alpha - fq)];
        balance += c - a;
        *cap = wpq * b1 + c - a;
      };
      auto backward = [&](int32_t q, int32_t wpq) {
        if (state_[q] != kFree) return fixed(q, wpq);
        balance -= wpq * b1;
      };
      if (x + 1 < w) forward(p + 1, weight_right_[p], &cap_right);
      if (x > 0) backward(p - 1, weight_right_[p - 1]);
      if (y + 1 < h) forward(p + w, weight_down_[p], &cap_down);
      if (y > 0) backward(p - w, weight_down_[p - w]);
      maxflow_.SetNode(p - base, balance, cap_right, cap_down);
    }
    maxflow_.RowDone(y - y_lo);
  }
  return free_pixels;
}

bool DepthStage::Expand(int32_t alpha) {
  const int32_t w = config_.width, h = config_.height;
  data_.ComputeRows(LabelDispQ8(alpha), 0, h, cost_alpha_, w);
  int32_t y_lo = 0, y_hi = 0;
  Classify(alpha, &y_lo, &y_hi);
  if (y_hi < 0) {
    Record(alpha);
    return false;
  }
  const int32_t base = y_lo * w;
  const int32_t free_pixels = BuildMove(alpha, y_lo, y_hi);
  stats_.cut_pixels += free_pixels;
  if (free_pixels > 0) (void)maxflow_.Solve();

  // Apply, and update the energy from the pixels that changed and their pair terms.
  for (int32_t p = base; p < (y_hi + 1) * w; ++p) {
    if (state_[p] == kFree) state_[p] = maxflow_.InSource(p - base) ? kKeep : kTake;
  }
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
