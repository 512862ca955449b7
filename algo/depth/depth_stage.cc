// Depth by graph cuts: labels start at the winner-take-all choice of the data term, then
// alpha-expansion cycles lower E(f) = sum D_p(f_p) + sum w_pq min(|f_p - f_q|, K), each move an
// exact minimum cut on the pixel grid, until a cycle changes nothing or the cycle cap.
// The 2-label move energy per neighbour pair, with x = 1 meaning "switch to alpha",
// A = V(fp,fq), B = V(fp,alpha), C = V(alpha,fq), V(alpha,alpha) = 0, is
//   A + (C - A) x_p - C x_q + (B + C - A) (1 - x_p) x_q,
// and B + C - A >= 0 because truncated linear is a metric, so every move is a graph cut.
#include "algo/depth/depth_stage.h"

namespace lb {

int32_t DepthStage::LabelDispQ8(int32_t label) const {
  const DepthConfig& c = config_;
  return c.disp_min_q8 +
         static_cast<int32_t>((int64_t{c.disp_max_q8 - c.disp_min_q8} * label) / (c.labels - 1));
}

Status DepthStage::Validate(const DepthConfig& c) {
  if (c.width < 8 || c.height < 8 || int64_t{c.width} * c.height > (int64_t{1} << 24)) {
    return Status(Code::kInvalidArgument, "depth: working size %dx%d outside 8x8 .. 16M pixels",
                  c.width, c.height);
  }
  if (c.views < 2 || c.views > DepthConfig::kMaxViews) {
    return Status(Code::kInvalidArgument, "depth: %d views (needs 2 to %d)", c.views,
                  DepthConfig::kMaxViews);
  }
  if (c.reference < 0 || c.reference >= c.views) {
    return Status(Code::kInvalidArgument, "depth: reference %d outside 0..%d", c.reference,
                  c.views - 1);
  }
  if (c.labels < 2 || c.labels > DepthConfig::kMaxLabels) {
    return Status(Code::kInvalidArgument, "depth: %d labels (needs 2 to %d)", c.labels,
                  DepthConfig::kMaxLabels);
  }
  if (c.disp_min_q8 < 0 || c.disp_max_q8 <= c.disp_min_q8 || c.disp_max_q8 > 0xffff) {
    return Status(Code::kInvalidArgument, "depth: disparity range %d..%d (Q8) is empty or too wide",
                  c.disp_min_q8, c.disp_max_q8);
  }
  // These bounds keep every node's terminal balance and arc capacity far below
  // GridMaxflow::kMaxCapacity: |balance| <= 2295 + 8 * 4096 * 64.
  if (c.color_trunc < 1 || c.color_trunc > 765 || c.census_weight < 0 || c.census_weight > 10 ||
      c.smooth_weight < 0 || c.smooth_weight > 4096 || c.smooth_trunc < 1 || c.smooth_trunc > 64 ||
      c.edge_threshold < 0 || c.edge_threshold > 255 || c.edge_weight_q8 < 0 ||
      c.edge_weight_q8 > 256 || c.max_cycles < 0 || c.max_cycles > 32 || c.move_margin < 0 ||
      c.move_margin > 65535) {
    return Status(Code::kInvalidArgument,
                  "depth: cost parameters out of range (colour %d, census %d, smoothness %d "
                  "trunc %d edge %d/%d, cycles %d)",
                  c.color_trunc, c.census_weight, c.smooth_weight, c.smooth_trunc, c.edge_threshold,
                  c.edge_weight_q8, c.max_cycles);
  }
  return Status::Ok();
}

size_t DepthStage::RequiredBytes(const DepthConfig& config) {
  DepthStage planner;
  planner.config_ = config;
  Arena plan;
  (void)planner.Carve(plan);
  return plan.used();
}

Status DepthStage::Carve(Arena& arena) {
  const size_t start = arena.used();
  const int32_t w = config_.width, h = config_.height;
  const size_t n = static_cast<size_t>(w) * h;
  data_.Carve(arena, w, h, config_.views);
  maxflow_.Carve(arena, w * h);
  labels_ = arena.Allocate<uint8_t>(n);
  cost_ = arena.Allocate<uint16_t>(n);
  cost_alpha_ = arena.Allocate<uint16_t>(n);
  weight_right_ = arena.Allocate<uint16_t>(n);
  weight_down_ = arena.Allocate<uint16_t>(n);
  state_ = arena.Allocate<uint8_t>(n);
  reach_ = arena.Allocate<uint16_t>(static_cast<size_t>(w));
  prev_alpha_ = arena.Allocate<uint16_t>(n);
  below_ = arena.Allocate<uint16_t>(n);
  above_ = arena.Allocate<uint16_t>(n);
  stats_.arena_bytes = arena.used() - start;
  if (arena.overflowed()) return Status(Code::kOutOfMemory, "depth: arena too small");
  return Status::Ok();
}

Status DepthStage::Configure(const DepthConfig& config, Arena& arena) {
  LB_RETURN_IF_ERROR(Validate(config));
  config_ = config;
  stats_ = DepthStats{};
  stats_.labels = config.labels;
  DataTermParams params;
  params.color_trunc = config.color_trunc;
  params.census_weight = config.census_weight;
  data_.SetParams(params, config.reference);
  return Carve(arena);
}

void DepthStage::EdgeWeights(const ConstImageU8& ref) {
  const int32_t w = config_.width, h = config_.height;
  const int32_t flat = config_.smooth_weight;
  const int32_t edge = (config_.smooth_weight * config_.edge_weight_q8 + 128) >> 8;
  auto weight = [&](const uint8_t* a, const uint8_t* b) {
    int32_t step = 0;
    for (int32_t c = 0; c < 3; ++c) {
      const int32_t d = a[c] > b[c] ? a[c] - b[c] : b[c] - a[c];
      step = d > step ? d : step;
    }
    return static_cast<uint16_t>(step > config_.edge_threshold ? edge : flat);
  };
  for (int32_t y = 0; y < h; ++y) {
    const uint8_t* row = ref.Row(y);
    const uint8_t* below = ref.Row(y + 1 < h ? y + 1 : y);
    for (int32_t x = 0; x < w; ++x) {
      const int32_t p = y * w + x;
      weight_right_[p] = x + 1 < w ? weight(row + 3 * x, row + 3 * x + 3) : 0;
      weight_down_[p] = y + 1 < h ? weight(row + 3 * x, below + 3 * x) : 0;
    }
  }
}

// Energy of the current labels from the stored D_p(f_p) and the edge weights.
static int64_t LabelEnergy(const uint8_t* labels, const uint16_t* cost, const uint16_t* right,
                           const uint16_t* down, int32_t w, int32_t h, int32_t trunc) {
  int64_t e = 0;
  for (int32_t y = 0; y < h; ++y) {
    int64_t row = 0;  // at most 8192 * (2295 + 2 * 4096 * 64): fits easily
    for (int32_t x = 0; x < w; ++x) {
      const int32_t p = y * w + x;
      const int32_t f = labels[p];
      row += cost[p];
      if (x + 1 < w) {
        const int32_t d = f > labels[p + 1] ? f - labels[p + 1] : labels[p + 1] - f;
        row += int64_t{right[p]} * (d < trunc ? d : trunc);
      }
      if (y + 1 < h) {
        const int32_t d = f > labels[p + w] ? f - labels[p + w] : labels[p + w] - f;
        row += int64_t{down[p]} * (d < trunc ? d : trunc);
      }
    }
    e += row;
  }
  return e;
}

void DepthStage::WinnerTakeAll() {
  const int32_t w = config_.width, h = config_.height;
  const int32_t n = w * h;
  for (int32_t p = 0; p < n; ++p) {
    cost_[p] = 0xffff;
    labels_[p] = 0;
  }
  for (int32_t label = 0; label < config_.labels; ++label) {
    data_.ComputeRows(LabelDispQ8(label), 0, h, cost_alpha_, w);
    for (int32_t p = 0; p < n; ++p) {
      if (cost_alpha_[p] < cost_[p]) {
        cost_[p] = cost_alpha_[p];
        labels_[p] = static_cast<uint8_t>(label);
      }
    }
  }
}

bool DepthStage::Expand(int32_t alpha) {
  const int32_t w = config_.width, h = config_.height;
  data_.ComputeRows(LabelDispQ8(alpha), 0, h, cost_alpha_, w);
  // Pass 1: pixels whose choice does not depend on their neighbours are fixed before the cut.
  // Flipping p to alpha changes the energy by u_p plus, per neighbour q, C - A (q keeps its
  // label) or -B (q takes alpha); if that is > 0 whatever the neighbours do, p keeps its label
  // in every optimal move, and if it is < 0 whatever they do, p takes alpha. Each pair term
  // moves the sum by at most w_pq * trunc, which settles most pixels without looking further.
  // With a move margin, pixels for which alpha costs more than that above their label also keep
  // it: a restricted move, still an exact cut over the pixels it frees, so the energy still
  // never rises, over a much smaller graph.
  const int32_t margin = config_.move_margin > 0 ? config_.move_margin : INT32_MAX;
  int32_t y_lo = h, y_hi = -1;  // rows holding free or switching pixels
  for (int32_t y = 0; y < h; ++y) {
    const int32_t row = y * w;
    uint8_t* state = state_ + row;
    const uint16_t* ca = cost_alpha_ + row;
    const uint16_t* cc = cost_ + row;
    // Largest change of the pair terms around a pixel when it alone switches label
    // (saturating is safe: D <= 2295).
    uint16_t* reach = reach_;
    for (int32_t x = 0; x < w; ++x) {
      const int32_t sum = weight_right_[row + x] + (x > 0 ? weight_right_[row + x - 1] : 0) +
                          weight_down_[row + x] + (y > 0 ? weight_down_[row + x - w] : 0);
      const int32_t r = sum * config_.smooth_trunc;
      reach[x] = static_cast<uint16_t>(r > 0xffff ? 0xffff : r);
    }
    bool open = false;
    for (int32_t x = 0; x < w; ++x) {
      const int32_t u = ca[x] - cc[x];
      const int32_t limit = reach[x] < margin ? reach[x] : margin;
      state[x] = u > limit ? kKeep : kFree;
      open |= u <= limit;
    }
    if (!open) continue;
    for (int32_t x = 0; x < w; ++x) {
      if (state[x] == kKeep) continue;
      const int32_t p = row + x;
      const int32_t fp = labels_[p];
      if (fp == alpha) {
        state[x] = kKeep;
        continue;
      }
      const int32_t u = ca[x] - cc[x];
      int32_t lo = u, hi = u;
      auto edge = [&](int32_t q, int32_t wpq) {
        const int32_t fq = labels_[q];
        const int32_t keep = wpq * (Smooth(alpha, fq) - Smooth(fp, fq));
        const int32_t take = -wpq * Smooth(fp, alpha);
        lo += keep < take ? keep : take;
        hi += keep < take ? take : keep;
      };
      if (x + 1 < w) edge(p + 1, weight_right_[p]);
      if (x > 0) edge(p - 1, weight_right_[p - 1]);
      if (y + 1 < h) edge(p + w, weight_down_[p]);
      if (y > 0) edge(p - w, weight_down_[p - w]);
      if (lo > 0) {
        state[x] = kKeep;
        continue;
      }
      state[x] = hi < 0 ? kTake : kFree;
      y_lo = y < y_lo ? y : y_lo;
      y_hi = y;
    }
  }
  if (y_hi < 0) {
    Record(alpha);
    return false;
  }

  // Pass 2: the cut over the free pixels of rows y_lo..y_hi (node = p - y_lo * w). A fixed
  // neighbour turns a pair term into a unary one: E(x_p) = a + (c - a) x_p with a = V(fp, lq),
  // c = V(alpha, lq), lq the label the neighbour is fixed to.
  const int32_t base = y_lo * w;
  maxflow_.Reset(w, y_hi - y_lo + 1);
  bool any_free = false;
  for (int32_t y = y_lo; y <= y_hi; ++y) {
    for (int32_t x = 0; x < w; ++x) {
      const int32_t p = y * w + x;
      if (state_[p] != kFree) continue;
      any_free = true;
      ++stats_.cut_pixels;
      const int32_t fp = labels_[p];
      const int32_t node = p - base;
      int32_t balance = cost_alpha_[p] - cost_[p];
      auto fixed = [&](int32_t q, int32_t wpq) {
        const int32_t lq = state_[q] == kTake ? alpha : labels_[q];
        balance += wpq * (Smooth(alpha, lq) - Smooth(fp, lq));
      };
      auto pair = [&](int32_t q, int32_t wpq, GridMaxflow::Dir dir) {
        if (state_[q] != kFree) return fixed(q, wpq);
        const int32_t fq = labels_[q];
        const int32_t a = wpq * Smooth(fp, fq), b = wpq * Smooth(fp, alpha);
        const int32_t c = wpq * Smooth(alpha, fq);
        balance += c - a;
        maxflow_.AddTerminalBalance(node + (q - p), -c);
        maxflow_.AddEdge(node, dir, b + c - a, 0);
      };
      if (x + 1 < w) pair(p + 1, weight_right_[p], GridMaxflow::kRight);
      if (y + 1 < h) {
        if (y + 1 <= y_hi) {
          pair(p + w, weight_down_[p], GridMaxflow::kDown);
        } else {
          fixed(p + w, weight_down_[p]);
        }
      }
      // Left and upper pairs with a free neighbour were added from that neighbour.
      if (x > 0 && state_[p - 1] != kFree) fixed(p - 1, weight_right_[p - 1]);
      if (y > 0 && state_[p - w] != kFree) fixed(p - w, weight_down_[p - w]);
      maxflow_.AddTerminalBalance(node, balance);
    }
  }
  if (any_free) (void)maxflow_.Solve();

  // Apply, and update the energy from the pixels that changed and their pair terms.
  for (int32_t y = y_lo; y <= y_hi; ++y) {
    for (int32_t x = 0; x < w; ++x) {
      const int32_t p = y * w + x;
      if (state_[p] == kFree) state_[p] = maxflow_.InSource(p - base) ? kKeep : kTake;
    }
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
        const int32_t after = state_[q] == kTake ? 0 : Smooth(alpha, fq);
        delta += int64_t{wpq} * (after - Smooth(fp, fq));
      };
      if (x + 1 < w) pair(p + 1, weight_right_[p], true);
      if (x > 0) pair(p - 1, weight_right_[p - 1], false);
      if (y + 1 < h) pair(p + w, weight_down_[p], true);
      if (y > 0) pair(p - w, weight_down_[p - w], false);
    }
  }
  for (int32_t y = y_lo; y <= y_hi; ++y) {
    for (int32_t x = 0; x < w; ++x) {
      const int32_t p = y * w + x;
      if (state_[p] != kTake) continue;
      labels_[p] = static_cast<uint8_t>(alpha);
      cost_[p] = cost_alpha_[p];
    }
  }
  energy_ += delta;
  Record(alpha);
  return delta < 0;
}

// Keeps D_p(f_p - 1) and D_p(f_p + 1) for the sub-label fit without another pass of the data
// term: moves run in label order, so a pixel that keeps label f saw D(f - 1) and D(f + 1) in
// the moves before and after f, and one that just took alpha saw D(alpha - 1) in the move
// before (kept in prev_alpha_) and will see D(alpha + 1) in the next.
void DepthStage::Record(int32_t alpha) {
  const int32_t n = config_.width * config_.height;
  const bool have_prev = prev_label_ == alpha - 1;
  for (int32_t p = 0; p < n; ++p) {
    const int32_t f = labels_[p];
    if (state_[p] == kTake) {
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

int64_t DepthStage::Energy(const uint8_t* labels) {
  const int32_t w = config_.width, h = config_.height;
  prev_label_ = -1;  // cost_alpha_ is used as scratch below
  int64_t data = 0;
  for (int32_t label = 0; label < config_.labels; ++label) {
    data_.ComputeRows(LabelDispQ8(label), 0, h, cost_alpha_, w);
    for (int32_t p = 0; p < w * h; ++p) {
      if (labels[p] == label) data += cost_alpha_[p];
    }
  }
  // The smoothness part with zero data costs: reuse LabelEnergy over a zero cost image.
  for (int32_t p = 0; p < w * h; ++p) cost_alpha_[p] = 0;
  return data +
         LabelEnergy(labels, cost_alpha_, weight_right_, weight_down_, w, h, config_.smooth_trunc);
}

// Sub-label disparity: a parabola through D at f_p - 1, f_p, f_p + 1 (as recorded by the
// moves), its vertex within half a label either side. Without expansion moves there is nothing
// recorded and the output is the labels' disparities.
void DepthStage::Refine(ImageU16 disp_q8) {
  const int32_t w = config_.width, h = config_.height;
  for (int32_t y = 0; y < h; ++y) {
    uint16_t* out = disp_q8.Row(y);
    for (int32_t x = 0; x < w; ++x) {
      const int32_t p = y * w + x;
      const int32_t f = labels_[p];
      int32_t d_q8 = LabelDispQ8(f);
      if (config_.subpixel && f > 0 && f + 1 < config_.labels) {
        const int32_t cm = below_[p], c0 = cost_[p], cp = above_[p];
        const int32_t curvature = cm + cp - 2 * c0;
        if (cm != 0xffff && cp != 0xffff && c0 <= cm && c0 <= cp && curvature > 0) {
          const int32_t step_q8 = (LabelDispQ8(f + 1) - LabelDispQ8(f - 1)) / 2;
          // Vertex at (cm - cp) / (2 * curvature) labels; |cm - cp| <= curvature keeps it
          // within half a label. Truncating division, the same on every target.
          d_q8 += ((cm - cp) * step_q8) / (2 * curvature);
        }
      }
      out[x] = static_cast<uint16_t>(d_q8);
    }
  }
}

Status DepthStage::Compute(const ConstImageU8* views, ImageU16 disp_q8) {
  const DepthConfig& c = config_;
  if (disp_q8.width != c.width || disp_q8.height != c.height || disp_q8.channels != 1) {
    return Status(Code::kInvalidArgument, "depth: output is %dx%dx%d, expected %dx%dx1",
                  disp_q8.width, disp_q8.height, disp_q8.channels, c.width, c.height);
  }
  for (int32_t v = 0; v < c.views; ++v) {
    if (views[v].width != c.width || views[v].height != c.height || views[v].channels != 3 ||
        views[v].data == nullptr) {
      return Status(Code::kInvalidArgument, "depth: view %d is %dx%dx%d, expected %dx%d RGB", v,
                    views[v].width, views[v].height, views[v].channels, c.width, c.height);
    }
  }
  const int32_t w = c.width, h = c.height;
  data_.Prepare(views);
  EdgeWeights(views[c.reference]);
  WinnerTakeAll();
  energy_ = LabelEnergy(labels_, cost_, weight_right_, weight_down_, w, h, c.smooth_trunc);
  stats_.initial_energy = energy_;
  for (int32_t p = 0; p < w * h; ++p) below_[p] = above_[p] = 0xffff;
  prev_label_ = -1;
  stats_.cycles = 0;
  stats_.moves = 0;
  stats_.cut_pixels = 0;
  for (int32_t cycle = 0; cycle < c.max_cycles; ++cycle) {
    bool lowered = false;
    for (int32_t alpha = 0; alpha < c.labels; ++alpha) {
      if (Expand(alpha)) {
        lowered = true;
        ++stats_.moves;
      }
    }
    ++stats_.cycles;
    if (!lowered) break;
  }
  stats_.energy = energy_;
  Refine(disp_q8);
  return Status::Ok();
}

}  // namespace lb
