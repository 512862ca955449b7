// Depth by graph cuts: alpha-expansion moves lower E(f) = sum D_p(f_p) + sum w_pq
// min(|f_p - f_q|, K), each move an exact minimum cut. Coarse to fine (the default): the best
// of every coarse_step-th label per 2x2 block, full moves over those labels on the blocks
// (coarse_pass.h), then cycles of moves over every label restricted to pixels near labels
// within fine_window of alpha, until a cycle changes nothing or the cycle cap.
// With coarse_step 1: the winner-take-all labels, then cycles of full moves over every label.
// The stage composes the pieces: a move's rectangles and record (MoveBook), its graph and cut
// (ExpansionMove), and the blocks of the coarse pass (CoarsePass), over the grids of move_grid.h.
#include "algo/depth/depth_stage.h"

#include "algo/core/clones.h"

namespace lb {

int32_t DepthStage::LabelDispQ8(const DepthConfig& c, int32_t label) {
  // Validate asks for 2 labels or more; a config of one (never configured) gets label 0's.
  const int32_t steps = c.labels > 1 ? c.labels - 1 : 1;
  return c.disp_min_q8 +
         static_cast<int32_t>((int64_t{c.disp_max_q8 - c.disp_min_q8} * label) / steps);
}

Status DepthStage::Validate(const DepthConfig& c) {
  if (c.width < DepthConfig::kMinSize || c.height < DepthConfig::kMinSize ||
      int64_t{c.width} * c.height > (int64_t{1} << 24)) {
    return Status(Code::kInvalidArgument, "depth: working size %dx%d outside %dx%d .. 16M pixels",
                  c.width, c.height, DepthConfig::kMinSize, DepthConfig::kMinSize);
  }
  if (c.views < 2 || c.views > DepthConfig::kMaxViews) {
    return Status(Code::kInvalidArgument, "depth: %d views (needs 2 to %d)", c.views,
                  DepthConfig::kMaxViews);
  }
  if (c.reference < 0 || c.reference >= c.views) {
    return Status(Code::kInvalidArgument, "depth: reference %d outside 0..%d", c.reference,
                  c.views - 1);
  }
  if (c.workers < 1 || c.workers > kMaxWorkers) {
    return Status(Code::kInvalidArgument, "depth: %d workers (needs 1 to %d)", c.workers,
                  kMaxWorkers);
  }
  if (c.labels < 2 || c.labels > DepthConfig::kMaxLabels) {
    return Status(Code::kInvalidArgument, "depth: %d labels (needs 2 to %d)", c.labels,
                  DepthConfig::kMaxLabels);
  }
  if (c.disp_min_q8 < -0xffff || c.disp_max_q8 <= c.disp_min_q8 || c.disp_max_q8 > 0xffff ||
      c.disp_max_q8 - c.disp_min_q8 > 0xffff) {
    return Status(Code::kInvalidArgument, "depth: disparity range %d..%d (Q8) is empty or too wide",
                  c.disp_min_q8, c.disp_max_q8);
  }
  // These bounds keep every node's terminal balance far below GridMaxflow::kMaxCapacity:
  // |balance| <= 2295 + 8 * 4096 * 64.
  if (c.color_trunc < 1 || c.census_weight < 0 || c.census_weight > 10 ||
      c.color_trunc + DataTerm::kCensusBits * c.census_weight > 254 || c.smooth_weight < 0 ||
      c.smooth_weight > 4096 || c.smooth_trunc < 1 || c.smooth_trunc > 64 || c.edge_threshold < 0 ||
      c.edge_threshold > 255 || c.edge_weight_q8 < 0 || c.edge_weight_q8 > 256 ||
      c.max_cycles < 0 || c.max_cycles > 32 || c.coarse_step < 1 || c.coarse_step > 16 ||
      c.fine_window < 1 || c.fine_window > 255) {
    return Status(Code::kInvalidArgument,
                  "depth: cost parameters out of range (colour %d, census %d, smoothness %d "
                  "trunc %d edge %d/%d, cycles %d, coarse step %d window %d)",
                  c.color_trunc, c.census_weight, c.smooth_weight, c.smooth_trunc, c.edge_threshold,
                  c.edge_weight_q8, c.max_cycles, c.coarse_step, c.fine_window);
  }
  if (c.geometry != ViewGeometry::kRectified && c.geometry != ViewGeometry::kKnownPoses) {
    return Status(Code::kInvalidArgument, "depth: geometry %d is neither rectified nor known poses",
                  static_cast<int>(c.geometry));
  }
  if (c.smooth_weight > MaxSmoothWeight(c.smooth_trunc)) {
    return Status(Code::kInvalidArgument,
                  "depth: smoothness %d is over %d at truncation %d (the graph's arcs are 16 bits)",
                  c.smooth_weight, MaxSmoothWeight(c.smooth_trunc), c.smooth_trunc);
  }
  return Status::Ok();
}

DepthStage::Smoothness DepthStage::SmoothnessFor(const DepthConfig& c) {
  // Labels (span / steps) apart against kSmoothSpacingQ8: the weight scales with the spacing and
  // the truncation against it, so min(|a - b| * spacing, trunc * kSmoothSpacingQ8) keeps its
  // price in px. Validate keeps both products far inside 64 bits.
  const int64_t span = int64_t{c.disp_max_q8} - c.disp_min_q8;
  const int64_t per = int64_t{DepthConfig::kSmoothSpacingQ8} * (c.labels > 1 ? c.labels - 1 : 1);
  if (span <= 0) return Smoothness{c.smooth_weight, c.smooth_trunc};
  Smoothness s;
  const int64_t trunc = (int64_t{c.smooth_trunc} * per + span / 2) / span;
  s.trunc = static_cast<int32_t>(trunc < 1 ? 1 : (trunc > 64 ? 64 : trunc));
  int64_t weight = (int64_t{c.smooth_weight} * span + per / 2) / per;
  if (weight < 1 && c.smooth_weight > 0) weight = 1;
  const int32_t cap = MaxSmoothWeight(s.trunc);
  s.weight = static_cast<int32_t>(weight > cap ? cap : weight);
  return s;
}

size_t DepthStage::RequiredBytes(const DepthConfig& config) {
  DepthStage planner;
  planner.config_ = config;
  Arena plan;
  (void)planner.Carve(plan);
  return plan.used();
}

size_t DepthStage::SpareBytes(const DepthConfig& config) {
  DataTerm data;
  Arena plan;
  data.Carve(plan, config.width, config.height, config.views, config.workers);
  return data.census_block_bytes();
}

Status DepthStage::Carve(Arena& arena) {
  const size_t start = arena.used();
  const int32_t w = config_.width, h = config_.height;
  const size_t n = static_cast<size_t>(w) * h;
  data_.Carve(arena, w, h, config_.views, config_.workers);
  // The coarse pass's costs, rings and winners ride in the solver's spare: room for them
  // whatever the labels and workers, or the pass computes the costs again per move.
  const bool coarse = config_.coarse_step > 1 && config_.max_cycles > 0 && config_.coarse_blocks;
  const size_t room = coarse ? CoarsePass::SpareBytes(config_, data_.CarriedRingSize()) : 0;
  move_.Carve(arena, config_, room);
  CarveGrid(arena, fine_, w, h, config_.labels, true);
  book_.Carve(arena, config_);
  // The coarse grid is done with before the fine moves record anything in the fit's costs, so
  // it lives in their memory (enlarged for the smallest images, where alignment dominates).
  Arena plan;
  coarse_.CarveGrid(plan, config_);
  const size_t refine_bytes = 4 * n > plan.used() ? 4 * n : plan.used();
  uint8_t* refine = arena.Allocate<uint8_t>(refine_bytes);
  book_.SetFitMemory(reinterpret_cast<uint16_t*>(refine));
  Arena blocks(refine, refine == nullptr ? 0 : refine_bytes);
  coarse_.CarveGrid(blocks, config_);
  margins_ = LabelMargins{};
  if (config_.confidence) margins_.Carve(arena, w, h);
  coarse_.SetMargins(config_.confidence ? &margins_ : nullptr);
  planes_ = nullptr;
  if (config_.geometry == ViewGeometry::kKnownPoses) {
    planes_ = arena.Allocate<PlaneHomography>(static_cast<size_t>(config_.labels) * config_.views);
  }
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
  data_.SetPlanes(nullptr);
  planes_set_ = false;
  return Carve(arena);
}

Status DepthStage::SetPlanes(const PlaneHomography* homographies) {
  const DepthConfig& c = config_;
  if (c.geometry != ViewGeometry::kKnownPoses || planes_ == nullptr || homographies == nullptr) {
    return Status(Code::kInvalidArgument, "depth: planes need a known-poses configuration");
  }
  // Label-major, so one label's views are contiguous for the data term.
  for (int32_t v = 0; v < c.views; ++v) {
    for (int32_t l = 0; l < c.labels; ++l)
      planes_[l * c.views + v] = homographies[v * c.labels + l];
  }
  planes_set_ = true;
  return Status::Ok();
}

Status DepthStage::SetDisparityRange(int32_t disp_min_q8, int32_t disp_max_q8) {
  DepthConfig c = config_;
  c.disp_min_q8 = disp_min_q8;
  c.disp_max_q8 = disp_max_q8;
  LB_RETURN_IF_ERROR(Validate(c));
  config_ = c;
  return Status::Ok();
}

int32_t LabelTerm::DispQ8(int32_t label) const { return DepthStage::LabelDispQ8(config, label); }

void DepthStage::LabelCosts(int32_t label, uint16_t* out) {
  Term().Use(label);
  data_.ComputeRows(LabelDispQ8(label), 0, config_.height, out, config_.width);
}

// The pair weight of two RGB pixels: edge across a colour step (largest channel) above the
// threshold, else flat. Without branches, so that the loops vectorize.
static inline uint16_t PairWeight(const uint8_t* a, const uint8_t* b, int32_t threshold,
                                  uint16_t flat, uint16_t edge) {
  int32_t step = 0;
  for (int32_t c = 0; c < 3; ++c) {
    const int32_t d = a[c] > b[c] ? a[c] - b[c] : b[c] - a[c];
    step = d > step ? d : step;
  }
  return step > threshold ? edge : flat;
}

LB_CLONES_AVX2 static void WeightRow(const uint8_t* __restrict row, const uint8_t* __restrict below,
                                     int32_t w, bool last_row, int32_t threshold, uint16_t flat,
                                     uint16_t edge, uint16_t* __restrict right,
                                     uint16_t* __restrict down) {
  for (int32_t x = 0; x + 1 < w; ++x) {
    right[x] = PairWeight(row + 3 * x, row + 3 * x + 3, threshold, flat, edge);
  }
  right[w - 1] = 0;
  for (int32_t x = 0; x < w; ++x) {
    down[x] = last_row ? 0 : PairWeight(row + 3 * x, below + 3 * x, threshold, flat, edge);
  }
}

void DepthStage::EdgeWeights(const ConstImageU8& ref) {
  const int32_t w = config_.width, h = config_.height;
  const uint16_t flat = static_cast<uint16_t>(smooth_.weight);
  const uint16_t edge = static_cast<uint16_t>((smooth_.weight * config_.edge_weight_q8 + 128) >> 8);
  for (int32_t y = 0; y < h; ++y) {
    WeightRow(ref.Row(y), ref.Row(y + 1 < h ? y + 1 : y), w, y + 1 >= h, config_.edge_threshold,
              flat, edge, fine_.weight_right + y * w, fine_.weight_down + y * w);
  }
}

void DepthStage::WinnerTakeAll() {
  const int32_t n = config_.width * config_.height;
  uint8_t* labels = fine_.labels;
  uint16_t* cost = fine_.cost;
  for (int32_t p = 0; p < n; ++p) {
    cost[p] = 0xffff;
    labels[p] = 0;
  }
  // Coarse to fine starts from the best coarse label: the fine labels come in the fine moves.
  const int32_t step = config_.max_cycles > 0 ? config_.coarse_step : 1;
  for (int32_t label = 0; label < config_.labels; label += step) {
    LabelCosts(label, fine_.cost_alpha);
    if (margins_.carved()) margins_.Take(fine_.cost_alpha, 0, n, label, step);
    TakeBetter(fine_.cost_alpha, n, static_cast<uint8_t>(label), cost, labels);
  }
}

int64_t DepthStageProbe::Energy(DepthStage& s, const uint8_t* labels) {
  const int32_t w = s.config_.width, h = s.config_.height;
  uint16_t* scratch = s.fine_.cost_alpha;
  s.book_.ForgetPrevious();  // cost_alpha is used as scratch below
  int64_t data = 0;
  for (int32_t label = 0; label < s.config_.labels; ++label) {
    s.LabelCosts(label, scratch);
    for (int32_t p = 0; p < w * h; ++p) {
      if (labels[p] == label) data += scratch[p];
    }
  }
  // The smoothness part: the energy of the labels over a zero cost image.
  for (int32_t p = 0; p < w * h; ++p) scratch[p] = 0;
  MoveGrid g = s.fine_;
  g.labels = const_cast<uint8_t*>(labels);
  g.cost = scratch;
  const int64_t e = data + GridEnergy(g, s.smooth_.trunc);
  for (int32_t p = 0; p < w * h; ++p) scratch[p] = MoveGrid::kNotComputed;  // as the moves expect
  s.fine_.written_count = 0;
  return e;
}

// One move: where it looks, the D of alpha there, the cut of each rectangle, and the record.
bool DepthStage::Expand(int32_t alpha) {
  MoveGrid& g = on_coarse_ ? coarse_.grid() : fine_;
  const LabelTerm term = Term();
  const int32_t count = book_.MoveRects(g, alpha, window_, !on_coarse_);
  term.Use(alpha);
  const int32_t disp_q8 = LabelDispQ8(alpha);
  const bool near = !on_coarse_ && window_ < config_.labels - 1;
  if (near && count > 0) book_.ComputeNear(fine_, term, disp_q8);
  for (int32_t i = 0; i < count; ++i) {
    const MoveRect& r = g.rects[i];
    if (on_coarse_) {
      coarse_.MoveCosts(alpha, r, fine_, term);
    } else if (!near) {
      data_.ComputeRect(disp_q8, r.x0, r.x1, r.y0, r.y1, g.cost_alpha + r.y0 * g.width, g.width);
      MoveBook::Written(fine_, r);
    }
    stats_.cut_pixels += move_.Cut(g, alpha, r, window_);
  }
  const int64_t delta = book_.Record(g, alpha, !on_coarse_, term);
  energy_ += delta;
  return delta < 0;
}

void DepthStage::CoarseMoves() {
  const LabelTerm term = Term();
  coarse_.Start(fine_, term, move_.solver());
  energy_ = GridEnergy(coarse_.grid(), smooth_.trunc);
  stats_.initial_energy = energy_;
  on_coarse_ = true;
  window_ = DepthConfig::kMaxLabels;
  for (int32_t alpha = 0; alpha < config_.labels; alpha += config_.coarse_step) {
    if (Expand(alpha)) ++stats_.moves;
  }
  stats_.coarse_energy = energy_;
  on_coarse_ = false;
  coarse_.Finish(fine_, term, book_.runs(), book_.run_marks());
  energy_ = GridEnergy(fine_, smooth_.trunc);
  stats_.handover_energy = energy_;
}

// Sub-label disparity: a parabola through D at f_p - 1, f_p, f_p + 1 (as recorded by the
// moves), its vertex within half a label either side. Without expansion moves there is nothing
// recorded and the output is the labels' disparities.
void DepthStage::Refine(ImageU16 disp_q8) {
  const int32_t w = config_.width, h = config_.height;
  const int32_t bias = MapBiasQ8(config_);
  // Each label's disparity and half its neighbours' span, once, not three 64-bit divisions a
  // pixel.
  int32_t disp[DepthConfig::kMaxLabels], half_span[DepthConfig::kMaxLabels];
  for (int32_t l = 0; l < config_.labels; ++l) disp[l] = LabelDispQ8(l);
  const uint16_t* below = book_.FitBelow();
  const uint16_t* above = book_.FitAbove();
  for (int32_t l = 1; l + 1 < config_.labels; ++l) half_span[l] = (disp[l + 1] - disp[l - 1]) / 2;
  for (int32_t y = 0; y < h; ++y) {
    uint16_t* out = disp_q8.Row(y);
    for (int32_t x = 0; x < w; ++x) {
      const int32_t p = y * w + x;
      const int32_t f = fine_.labels[p];
      int32_t d_q8 = disp[f];
      if (config_.subpixel && f > 0 && f + 1 < config_.labels) {
        const int32_t cm = below[p], c0 = fine_.cost[p], cp = above[p];
        const int32_t curvature = cm + cp - 2 * c0;
        if (cm != 0xffff && cp != 0xffff && c0 <= cm && c0 <= cp && curvature > 0) {
          const int32_t step_q8 = half_span[f];
          // Vertex at (cm - cp) / (2 * curvature) labels; |cm - cp| <= curvature keeps it
          // within half a label. Truncating division, the same on every target.
          d_q8 += ((cm - cp) * step_q8) / (2 * curvature);
        }
      }
      out[x] = static_cast<uint16_t>(d_q8 + bias);
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
  if (c.geometry == ViewGeometry::kKnownPoses) {
    if (!planes_set_) return Status(Code::kInvalidArgument, "depth: no planes set for this burst");
    planes_set_ = false;
  }
  const int32_t h = c.height;
  // Units: the costs' preparation and the first labeling, then one per move of every cycle.
  const int32_t total = 1 + c.max_cycles * c.labels;
  if (progress_ != nullptr) progress_->Report(0, total);
  data_.Prepare(views);
  smooth_ = SmoothnessFor(c);
  EdgeWeights(views[c.reference]);
  move_.Start(smooth_.trunc);
  book_.Start(smooth_.trunc);
  stats_.cycles = 0;
  stats_.moves = 0;
  stats_.cut_pixels = 0;
  stats_.coarse_energy = stats_.handover_energy = 0;
  window_ = DepthConfig::kMaxLabels;
  const bool coarse = c.coarse_step > 1 && c.max_cycles > 0;
  if (margins_.carved()) margins_.Reset();
  if (coarse && c.coarse_blocks) {
    CoarseMoves();  // ends with the pixels' labels, their row masks, costs and energy
  } else {
    WinnerTakeAll();
    for (int32_t y = 0; y < h; ++y) RowLabels(fine_, c.labels, y);
    energy_ = GridEnergy(fine_, smooth_.trunc);
    stats_.initial_energy = energy_;
  }
  book_.StartFine(fine_);
  if (coarse && !c.coarse_blocks) {
    for (int32_t alpha = 0; alpha < c.labels; alpha += c.coarse_step) {
      if (Expand(alpha)) ++stats_.moves;
    }
  }
  if (coarse) window_ = c.fine_window;
  if (progress_ != nullptr) progress_->Report(1, total);
  for (int32_t cycle = 0; cycle < c.max_cycles; ++cycle) {
    bool lowered = false;
    for (int32_t alpha = 0; alpha < c.labels; ++alpha) {
      if (Expand(alpha)) {
        lowered = true;
        ++stats_.moves;
      }
      if (progress_ != nullptr) progress_->Report(2 + cycle * c.labels + alpha, total);
    }
    ++stats_.cycles;
    if (!lowered) break;
  }
  stats_.energy = energy_;
  Refine(disp_q8);
  stats_.low_confidence = 0;
  if (margins_.carved()) {
    // The winner-take-all's label step (WinnerTakeAll, CoarsePass::Start).
    const int32_t step = c.max_cycles > 0 ? c.coarse_step : 1;
    stats_.low_confidence = margins_.Finish(fine_.labels, fine_.cost, step, views[c.reference]);
  }
  if (progress_ != nullptr) progress_->Report(total, total);
  return Status::Ok();
}

}  // namespace lb
