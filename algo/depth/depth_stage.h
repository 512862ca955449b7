// Depth stage: from the working-resolution views of a burst to a disparity map of the reference
// view. Disparity is in working-resolution pixels per view step, Q8.8 (`dispQ8`): a point at
// disparity d appears at x - k*d in the view k steps to the right of the reference and at
// x + k*d in the view k steps to its left (the views are rectified and equally spaced).
// Signed: a converged rig (a light field, a hand that turns toward the subject) has its zero at
// the focus plane, and the points behind it have negative disparities. The map is unsigned: it
// holds d + MapBiasQ8, the bias lifting the farthest label of a signed range to 0.
//
// Plane sweep (ViewGeometry::kKnownPoses, for handheld bursts): label l is instead a
// fronto-parallel plane of the reference camera, given per view as its plane-induced homography
// (SetPlanes, planes.h), and view v is sampled at H_vl(x, y) (warp_cost.h). The output stays
// LabelDispQ8(l): the caller picks disp_min_q8..disp_max_q8 proportional to the planes' inverse
// depths.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/arena.h"
#include "algo/core/image.h"
#include "algo/core/progress.h"
#include "algo/core/status.h"
#include "algo/depth/data_term.h"
#include "algo/depth/grid_maxflow.h"
#include "algo/motion/camera.h"
#include "algo/motion/plane_homography.h"

namespace lb {

struct DepthConfig {
  static constexpr int32_t kMaxViews = 16;
  static constexpr int32_t kMaxLabels = 256;
  static constexpr int32_t kMinSize = 8;  // working width and height

  int32_t width = 0;  // working resolution
  int32_t height = 0;
  int32_t views = 0;
  int32_t reference = 0;  // index of the reference among the views
  int32_t labels = 0;     // number of disparity planes
  // Disparity of label 0 and of the last label, px per view step, Q8.8: -65535..65535, at
  // most 65535 apart.
  int32_t disp_min_q8 = 0;
  int32_t disp_max_q8 = 0;
  ViewGeometry geometry = ViewGeometry::kRectified;  // or kKnownPoses

  // Data term (see data_term.h).
  int32_t color_trunc = 45;   // truncation of |dR|+|dG|+|dB|, 1..765
  int32_t census_weight = 4;  // cost per differing census bit, 0..10
  // Smoothness V(a, b) = w_pq * min(|a - b|, smooth_trunc) over label indices: truncated linear,
  // Potts when smooth_trunc is 1. w_pq is smooth_weight where the reference is flat and
  // smooth_weight * edge_weight_q8 / 256 across a colour edge (largest channel step above
  // edge_threshold), so label changes prefer image edges.
  int32_t smooth_weight = 96;   // 0..4096, times smooth_trunc at most 16383
  int32_t smooth_trunc = 8;     // 1..64
  int32_t edge_threshold = 16;  // 0..255
  int32_t edge_weight_q8 = 64;  // 0..256
  int32_t max_cycles = 1;       // expansion cycles over every label, 0..32 (0: winner-take-all)
  // Coarse to fine: with coarse_step > 1, one pass of full moves over every coarse_step-th
  // label comes first, and the cycles' moves then free only pixels whose label is within
  // fine_window of alpha (a restricted move: still an exact cut over the pixels it frees). The
  // coarse pass settles the layout, the fine moves its sub-pixel steps, over far smaller graphs.
  // What 4 and 2 cost in bad pixels against full moves over every label, and save in time, is
  // measured on the Middlebury sets: README, Performance, "Depth".
  int32_t coarse_step = 4;  // 1..16; 1: every move is a full move
  int32_t fine_window = 2;  // 1..255
  // The coarse pass labels 2x2 blocks of pixels (its data costs the blocks' sums, its pair
  // weights the sums across block edges, so it minimises the same energy over block-constant
  // labels) on a quarter of the nodes; the fine moves then also free pixels next to a label
  // within fine_window, which moves the block edges onto the image's.
  bool coarse_blocks = true;
  bool subpixel = true;  // parabola fit between labels for the output
  // Workers the data term carves rings for (task_runner.h), 1..kMaxWorkers.
  int32_t workers = 1;
};

struct DepthStats {
  int32_t labels = 0;
  int32_t cycles = 0;          // expansion cycles run
  int32_t moves = 0;           // expansion moves that lowered the energy
  int64_t cut_pixels = 0;      // nodes (pixels or blocks) left free for the cuts, summed
  int64_t initial_energy = 0;  // energy of the winner-take-all labels
  // coarse_blocks: the energy of the coarse pass's labels as its moves tracked it on the blocks,
  // and recomputed on the pixels that take them (the two agree: coarse_grid.cc).
  int64_t coarse_energy = 0;
  int64_t handover_energy = 0;
  int64_t energy = 0;      // final energy
  size_t arena_bytes = 0;  // bytes this stage carved from the arena
};

class DepthStage {
 public:
  // Checks a configuration without touching memory.
  static Status Validate(const DepthConfig& config);
  // Bytes of arena that Configure will carve for this configuration.
  static size_t RequiredBytes(const DepthConfig& config);
  // The largest smooth_weight Validate takes with this smooth_trunc (at most 4096): an arc of a
  // move's graph carries at most w_pq * 2 * smooth_trunc, and a block pair's weight on the coarse
  // grid is two pixel pairs', within the solver's 16-bit arcs.
  static int32_t MaxSmoothWeight(int32_t smooth_trunc) {
    const int32_t arcs = GridMaxflow::kMaxArc / (4 * (smooth_trunc > 0 ? smooth_trunc : 1));
    return arcs < 4096 ? arcs : 4096;
  }

  Status Configure(const DepthConfig& config, Arena& arena);
  // Where the data term runs its tasks (borrowed; nullptr: on the caller), with at most
  // config.workers workers. The output does not depend on it.
  void SetRunner(TaskRunner* runner) { data_.SetRunner(runner); }
  // Told after each expansion move of Compute (borrowed; nullptr: nobody).
  void SetProgress(ProgressSink* progress) { progress_ = progress; }

  // kKnownPoses only, after Configure and before each Compute (a Compute consumes them, so a new
  // burst cannot run on the last one's poses): homographies[v * labels + l] is label l's plane
  // seen from view v (the reference's entries are ignored), copied into the arena.
  Status SetPlanes(const PlaneHomography* homographies);
  // A new label range for the next bursts (kKnownPoses: each burst's own, from its tracked points),
  // within Validate's limits; the memory does not depend on it.
  Status SetDisparityRange(int32_t disp_min_q8, int32_t disp_max_q8);

  // `views[i]` are RGB8 working-resolution images, left to right. Writes dispQ8 + MapBiasQ8 for
  // every pixel of the reference view into `disp_q8` (width x height, one channel).
  Status Compute(const ConstImageU8* views, ImageU16 disp_q8);

  const DepthStats& stats() const { return stats_; }
  const DepthConfig& config() const { return config_; }

  // After Compute: the label map of the reference view (row stride = width), which the depth
  // order votes on (auto_geometry.h).
  const uint8_t* labels() const { return fine_.labels; }
  int32_t LabelDispQ8(int32_t label) const { return LabelDispQ8(config_, label); }
  // The disparity of a label, Q8.8, for any valid configuration.
  static int32_t LabelDispQ8(const DepthConfig& config, int32_t label);
  // What the output map adds to every disparity so that it fits 16 unsigned bits: 0 for a range
  // that starts at 0 or above, -disp_min_q8 for a signed one.
  static int32_t MapBiasQ8(int32_t disp_min_q8) { return disp_min_q8 < 0 ? -disp_min_q8 : 0; }
  static int32_t MapBiasQ8(const DepthConfig& config) { return MapBiasQ8(config.disp_min_q8); }

 private:
  friend struct DepthStageProbe;
  // The rectangles of a move: one for the whole grid, or, for a restricted move, one per run
  // of rows near a label within the window of alpha, over the columns near such labels.
  struct Rect {
    int32_t x0, x1, y0, y1;
  };
  // A grid of labels the moves work on: the image's pixels, or the coarse pass's 2x2 blocks.
  struct Grid {
    int32_t width = 0, height = 0;
    uint8_t* labels = nullptr;
    uint16_t* cost = nullptr;          // D_p(f_p) of the current labels
    uint16_t* cost_alpha = nullptr;    // D_p(alpha) of the move in progress
    uint16_t* prev_alpha = nullptr;    // D of the previous move's label, prev_label_
    uint16_t* weight_right = nullptr;  // w_pq to the right neighbour
    uint16_t* weight_down = nullptr;
    uint8_t* state = nullptr;  // per node in a move: free for the cut, or fixed
    // Per row, the labels present (bit l of word l / 64), and the columns whose D the move in
    // progress (span) and the one before (prev_span) computed: [x0, x1) as two entries.
    uint64_t* row_labels = nullptr;
    int32_t* label_count = nullptr;  // per row, how many nodes hold each label (labels per row)
    int32_t* span = nullptr;
    int32_t* prev_span = nullptr;
    // Per row, the columns from the first to the last label within the window of the move in
    // progress ([x0, x1) as two entries, x0 >= x1 when none): ComputeNear and pass 1.
    int32_t* near_span = nullptr;
    // The rectangles of the move in progress (move_rects.cc), at most rect_capacity; their cut
    // is exact however they are split.
    Rect* rects = nullptr;
    int32_t rect_count = 0, rect_capacity = 0;
    // Fine grid: where the D in cost_alpha and in prev_alpha were computed (they swap with
    // them), at most written_capacity each; a count of -1: anywhere.
    Rect* written = nullptr;
    Rect* prev_written = nullptr;
    int32_t written_count = 0, prev_written_count = 0, written_capacity = 0;
    uint8_t* row_took = nullptr;  // per row, 1 when a pixel of it takes alpha (CutRect, Record)
  };
  void CarveGrid(Arena& arena, Grid& g, int32_t width, int32_t height, bool prev_alpha);
  Grid& grid() { return on_coarse_ ? coarse_ : fine_; }
  int64_t GridEnergy(const Grid& g) const;

  Status Carve(Arena& arena);
  void EdgeWeights(const ConstImageU8& ref);
  // kKnownPoses: points the data term at one label's planes (a no-op for rectified shifts).
  void UseLabelPlanes(int32_t label) {
    if (config_.geometry == ViewGeometry::kKnownPoses)
      data_.SetPlanes(planes_ + label * config_.views);
  }
  // The planes of one label for a data term call that takes them (nullptr: rectified shifts).
  const PlaneHomography* LabelPlanes(int32_t label) const {
    return config_.geometry == ViewGeometry::kKnownPoses ? planes_ + label * config_.views
                                                         : nullptr;
  }
  void LabelCosts(int32_t label, uint16_t* out);  // D of one label for the whole image
  void WinnerTakeAll();
  // The coarse pass (coarse_grid.cc): block weights, block costs, the best coarse label of
  // each block, the full moves over the blocks, and the pixels' labels and costs from them.
  void BlockWeights();
  // ring: the label's carried 3-sums (DataTerm::ComputeRowsCarried) when `blocks` is a band of
  // whole block rows, `continues` when the band before it was the label's last call.
  // With a ring it touches nothing shared but the data term's scratch of `worker`: the
  // winner-take-all's stripes run it side by side.
  void BlockCosts(int32_t label, const Rect& blocks, uint16_t* out, uint16_t* ring = nullptr,
                  bool continues = false, int32_t worker = 0);
  void CoarseWinnerTakeAll();
  // Where the coarse pass keeps, in the max-flow's spare, each coarse label's block D, `stripes`
  // winner-take-all rings per coarse label, and the winners' pixel D and labels (byte offsets;
  // end: all of it). Carve makes that much room for the most stripes the workers can take.
  struct CoarseRoom {
    size_t block_bytes, rings_at, rings_end, winners_at, labels_at, end;
  };
  CoarseRoom CoarseLayout(int32_t stripes) const;
  // The most stripes of block rows the winner-take-all may take with `workers` workers.
  int32_t CoarseStripes(int32_t workers) const;
  void KeepWinners(const Rect& blocks, const uint16_t* block_costs);
  // The winner-take-all over the block rows of `stripe`, going down them in bands with its
  // own rings (one per coarse label, carried from band to band); `worker`: whose data term
  // scratch it uses.
  void WinnersOfStripe(const Rect& stripe, uint16_t* rings, int32_t worker);
  uint16_t* CoarseCosts(int32_t label) {
    return block_costs_ +
           static_cast<size_t>(label / config_.coarse_step) * coarse_.width * coarse_.height;
  }
  void CoarsePass();
  void FineFromBlocks();
  // One alpha-expansion move (expansion_move.cc) on grid(); returns true when it lowered the
  // energy.
  bool Expand(int32_t alpha);
  int32_t MoveRects(int32_t alpha);
  int32_t SplitRect(int32_t i, int32_t count, int32_t lo, int32_t hi);
  void ComputeNear(int32_t disp_q8);
  // Notes in a D buffer's record (list, *count of capacity; -1: anywhere) that it holds D over r:
  // MoveRects clears it there before the buffer is used again. A rectangle over the columns of
  // the last one, right below it, extends that one.
  static void NoteWritten(Rect* list, int32_t* count, int32_t capacity, const Rect& r) {
    Rect* last = *count > 0 ? list + *count - 1 : nullptr;
    if (last != nullptr && last->y1 == r.y0 && last->x0 == r.x0 && last->x1 == r.x1) {
      last->y1 = r.y1;
    } else if (list != nullptr && *count >= 0 && *count < capacity) {
      list[(*count)++] = r;
    } else {
      *count = -1;
    }
  }
  // Notes that the fine grid's cost_alpha holds D over r.
  void Written(const Rect& r) {
    NoteWritten(fine_.written, &fine_.written_count, fine_.written_capacity, r);
  }
  void CutRect(int32_t alpha, const Rect& r);
  int32_t ClassifyRow(int32_t alpha, int32_t y, int32_t x0, int32_t x1, int32_t e0, int32_t e1);
  // The winner-take-all's step: where d is below the best so far (cost), d and `label` become
  // the best (coarse_grid.cc).
  static void TakeBetter(const uint16_t* d, int32_t n, uint8_t label, uint16_t* cost,
                         uint8_t* labels);
  static uint8_t StatesRow(const uint8_t* f, const uint16_t* wr, const uint16_t* wd,
                           const uint16_t* wu, const int32_t* er, const int32_t* ed,
                           const int32_t* eu, const uint16_t* ca, const uint16_t* cc,
                           const uint8_t* near, int32_t alpha, int32_t k, uint8_t full, int32_t x0,
                           int32_t x1, int32_t* hi, uint8_t* state);
  void NearColumns(const Rect& r, int32_t y, int32_t* x0, int32_t* x1) const;
  void PairsDown(int32_t alpha, int32_t y, int32_t x0, int32_t x1);
  int32_t BuildRow(const Rect& r, int32_t y, int32_t node_row);
  static void BuildTerms(const uint8_t* st, const uint8_t* up, const uint8_t* down,
                         const int32_t* er, const int32_t* ed, const int32_t* eu, const int32_t* hi,
                         int32_t x0, int32_t x1, int32_t r0, int32_t r1, int32_t* balance,
                         int32_t* cap_right, int32_t* cap_down);
  void FreeSpan(const Rect& r, int32_t y, bool any);
  void Reach(const Rect& r, int32_t y, int32_t* x0, int32_t* x1) const;
  void RowLabels(Grid& g, int32_t y);  // counts row y's labels, from scratch
  // Node (x, y) of g leaves label `from` for `to`: row y's counts and label mask follow.
  static void MoveLabel(Grid& g, int32_t labels, int32_t y, int32_t from, int32_t to) {
    int32_t* count = g.label_count + y * labels;
    uint64_t* m = g.row_labels + 4 * y;
    if (--count[from] == 0) m[from >> 6] &= ~(uint64_t{1} << (from & 63));
    if (count[to]++ == 0) m[to >> 6] |= uint64_t{1} << (to & 63);
  }
  enum : int32_t { kPairRight = 0, kPairDown = 1, kHigh = 2, kRowFree = 1, kRowTake = 2 };
  // A row of zeros (width int32, or 2 * width uint16) where the first row's pairs up would be.
  const int32_t* ZeroRow() const { return move_rows_ + 9 * config_.width; }
  int32_t* Ring(int32_t y, int32_t kind) {
    return move_rows_ + ((y % 3) * 3 + kind) * config_.width;
  }
  int64_t Record(int32_t alpha);  // returns the energy change
  void RecordNeighbours(int32_t alpha, const uint8_t* st, const uint8_t* f, const uint16_t* ca,
                        uint16_t* below, uint16_t* above, int32_t x0, int32_t x1);
  void Refine(ImageU16 disp_q8);

  DepthConfig config_;
  ProgressSink* progress_ = nullptr;
  DepthStats stats_;
  DataTerm data_;
  GridMaxflow maxflow_;
  Grid fine_;    // the pixels
  Grid coarse_;  // the coarse pass's blocks, in the memory of below_ and above_
  bool on_coarse_ = false;
  // The coarse pass's block D of every coarse label, kept from its winner-take-all for its moves
  // in storage the max-flow does not touch on the blocks' graphs; nullptr when it does not fit.
  uint16_t* block_costs_ = nullptr;
  // The winner-take-all's winners for the hand-over, in the max-flow's spare when there is room
  // (else nullptr): each block's label and its pixels' D at it (indexed as the fine grid).
  uint8_t* winner_labels_ = nullptr;
  uint16_t* winner_costs_ = nullptr;
  bool keep_winners_ = true;     // off: the hand-over computes every D (DepthStageProbe)
  bool striped_winners_ = true;  // off: the winner-take-all in one stripe (DepthStageProbe)
  int16_t winner_stripes_ = 0;   // the stripes the last winner-take-all took (<= kMaxWorkers)
  int32_t handover_kept_ = 0;    // pixels whose D the last hand-over took from the winners
  enum : uint8_t { kFree = 0, kKeep = 1, kTake = 2 };
  // A pixel's D in fine_.cost_alpha or prev_alpha where its move did not compute it: no D is
  // this large (DataTerm::kMaxCost).
  static constexpr uint16_t kNotComputed = 0xffff;
  // In below_ during Record: D(f - 1) is wanted from PastCosts.
  static constexpr uint16_t kWanted = 0xfffe;
  void PastCosts(int32_t label);
  int32_t* want_span_ = nullptr;  // per row, the columns where below_ holds kWanted ([w, 0): none)
  int32_t* move_rows_ = nullptr;  // the moves' row ring and rows (expansion_move.cc)
  uint8_t* keep_row_ = nullptr;   // width x kKeep: the state of the rows around a rectangle
  int32_t* free_span_ = nullptr;  // per row, the free pixels of the rectangle being cut (FreeSpan)
  uint8_t* split_ = nullptr;      // max(width, height) + 2 bytes: SplitRect's column or row marks
  // Per row, the runs of columns whose D a restricted move or the hand-over computes.
  RowRuns* runs_ = nullptr;
  uint8_t* run_marks_ = nullptr;  // 2 * (width + 2) bytes: the columns those runs hold
  // The labels near alpha that a restricted move computes D next to (MoveRects).
  int32_t near_lo_ = 0, near_hi_ = 0;
  int32_t smooth_[DepthConfig::kMaxLabels] = {};  // min(d, smooth_trunc) for a label distance d
  int32_t prev_label_ = -1;
  uint16_t* below_ = nullptr;  // D_p(f_p - 1), 0xffff when not seen
  uint16_t* above_ = nullptr;  // D_p(f_p + 1)
  int64_t energy_ = 0;
  int32_t window_ = DepthConfig::kMaxLabels;  // the move in progress frees labels this near alpha
  PlaneHomography* planes_ = nullptr;         // kKnownPoses: [label * views + view]
  bool planes_set_ = false;
};

// The stage's insides for its tests (tests/algo/depth), valid after Compute; nothing in the
// product calls them. The energy the moves tracked, one more expansion move (applied whatever it
// gives; true when it lowered the energy) restricted to pixels with a label within `window` of
// alpha in their 3x3 neighbourhood, and the energy of any label map recomputed from scratch
// (slow: D for every label).
struct DepthStageProbe {
  static int64_t TrackedEnergy(const DepthStage& stage) { return stage.energy_; }
  // Whether the hand-over may take the winner-take-all's D where a block kept its label (when
  // there is room to keep them), and how many pixels the last Compute's took.
  static void KeepWinners(DepthStage& stage, bool on) { stage.keep_winners_ = on; }
  static int32_t HandoverKept(const DepthStage& stage) { return stage.handover_kept_; }
  // Whether the winner-take-all may take one stripe per worker (the same bits either way), and
  // how many the last Compute's took (0 without carried rings).
  static void StripedWinners(DepthStage& stage, bool on) { stage.striped_winners_ = on; }
  static int32_t WinnerStripes(const DepthStage& stage) { return stage.winner_stripes_; }
  // Garbage in every max-flow node before the next move (GridMaxflowProbe::Poison).
  static void PoisonSolver(DepthStage& stage, uint8_t byte) {
    GridMaxflowProbe::Poison(stage.maxflow_, byte);
  }
  static bool ExpandMove(DepthStage& stage, int32_t alpha,
                         int32_t window = DepthConfig::kMaxLabels) {
    stage.window_ = window;
    return stage.Expand(alpha);
  }
  static int64_t Energy(DepthStage& stage, const uint8_t* labels);
  // What the last move kept for the next one's sub-label fit: the D of its label (*label; -1:
  // none) per pixel, kNotComputed where it has none.
  static const uint16_t* KeptCosts(const DepthStage& stage, int32_t* label) {
    *label = stage.prev_label_;
    return stage.fine_.prev_alpha;
  }
  static constexpr uint16_t kNotComputed = DepthStage::kNotComputed;
  // D of one label for every pixel (row stride = width), from scratch.
  static void Costs(DepthStage& stage, int32_t label, uint16_t* out) {
    stage.LabelCosts(label, out);
  }
};

}  // namespace lb
