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
#include "algo/depth/coarse_pass.h"
#include "algo/depth/confidence.h"
#include "algo/depth/data_term.h"
#include "algo/depth/depth_config.h"
#include "algo/depth/expansion_move.h"
#include "algo/depth/grid_maxflow.h"
#include "algo/depth/move_book.h"
#include "algo/depth/move_grid.h"
#include "algo/motion/camera.h"
#include "algo/motion/plane_homography.h"

namespace lb {

struct DepthStats {
  int32_t labels = 0;
  int32_t cycles = 0;          // expansion cycles run
  int32_t moves = 0;           // expansion moves that lowered the energy
  int64_t cut_pixels = 0;      // nodes (pixels or blocks) left free for the cuts, summed
  int64_t initial_energy = 0;  // energy of the winner-take-all labels
  // coarse_blocks: the energy of the coarse pass's labels as its moves tracked it on the blocks,
  // and recomputed on the pixels that take them (the two agree: coarse_pass.cc).
  int64_t coarse_energy = 0;
  int64_t handover_energy = 0;
  int64_t energy = 0;      // final energy
  size_t arena_bytes = 0;  // bytes this stage carved from the arena
  // Pixels whose confidence is below kLowConfidence (0 without the map).
  int64_t low_confidence = 0;
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
  // The weight and truncation a Compute uses: the configuration's, stated for labels
  // kSmoothSpacingQ8 apart, carried to its own label spacing (the truncation within 1..64, the
  // weight within MaxSmoothWeight of it, and above 0 unless the configuration's is 0).
  struct Smoothness {
    int32_t weight = 0;
    int32_t trunc = 1;
  };
  static Smoothness SmoothnessFor(const DepthConfig& config);

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
  // After Compute, with config().confidence: how sure each pixel's depth is, 0..255 (255: sure;
  // confidence.h), row stride = width; nullptr without it.
  const uint8_t* confidence() const { return margins_.confidence; }
  static constexpr uint8_t kLowConfidence = LabelMargins::kLow;
  // After Compute and until the next one: memory of the stage that no later call reads (the
  // census of the views, at least 6 bytes a pixel), for a caller's scratch; labels() and
  // confidence() lie outside it. SpareBytes says its size before Configure.
  uint8_t* spare() const { return data_.census_block(); }
  static size_t SpareBytes(const DepthConfig& config);
  int32_t LabelDispQ8(int32_t label) const { return LabelDispQ8(config_, label); }
  // The disparity of a label, Q8.8, for any valid configuration.
  static int32_t LabelDispQ8(const DepthConfig& config, int32_t label);
  // What the output map adds to every disparity so that it fits 16 unsigned bits: 0 for a range
  // that starts at 0 or above, -disp_min_q8 for a signed one.
  static int32_t MapBiasQ8(int32_t disp_min_q8) { return disp_min_q8 < 0 ? -disp_min_q8 : 0; }
  static int32_t MapBiasQ8(const DepthConfig& config) { return MapBiasQ8(config.disp_min_q8); }

 private:
  friend struct DepthStageProbe;
  Status Carve(Arena& arena);
  void EdgeWeights(const ConstImageU8& ref);
  LabelTerm Term() { return LabelTerm{data_, config_, planes_}; }
  void LabelCosts(int32_t label, uint16_t* out);  // D of one label for the whole image
  void WinnerTakeAll();
  // The coarse pass (coarse_pass.h): its start, the full moves over the blocks, and the pixels'
  // labels, costs and energy from them.
  void CoarseMoves();
  // One alpha-expansion move on the grid of the moves in progress (the blocks during
  // CoarseMoves, else the pixels); returns true when it lowered the energy.
  bool Expand(int32_t alpha);
  void Refine(ImageU16 disp_q8);

  DepthConfig config_;
  Smoothness smooth_;  // the Compute's, from SmoothnessFor
  ProgressSink* progress_ = nullptr;
  DepthStats stats_;
  DataTerm data_;
  MoveGrid fine_;         // the pixels
  ExpansionMove move_;    // the graph and the cut, and the solver
  MoveBook book_;         // where the moves look and what they leave behind
  CoarsePass coarse_;     // the blocks, in the memory of the book's fit costs
  LabelMargins margins_;  // the confidence map and what it is made from
  bool on_coarse_ = false;
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
  static void KeepWinners(DepthStage& stage, bool on) { stage.coarse_.KeepWinners(on); }
  static int32_t HandoverKept(const DepthStage& stage) { return stage.coarse_.handover_kept(); }
  // Whether the winner-take-all may take one stripe per worker (the same bits either way), and
  // how many the last Compute's took (0 without carried rings).
  static void StripedWinners(DepthStage& stage, bool on) { stage.coarse_.StripedWinners(on); }
  static int32_t WinnerStripes(const DepthStage& stage) { return stage.coarse_.winner_stripes(); }
  // Garbage in every max-flow node before the next move (GridMaxflowProbe::Poison).
  static void PoisonSolver(DepthStage& stage, uint8_t byte) {
    GridMaxflowProbe::Poison(stage.move_.solver(), byte);
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
    *label = stage.book_.prev_label();
    return stage.fine_.prev_alpha;
  }
  static constexpr uint16_t kNotComputed = MoveGrid::kNotComputed;
  // D of one label for every pixel (row stride = width), from scratch.
  static void Costs(DepthStage& stage, int32_t label, uint16_t* out) {
    stage.LabelCosts(label, out);
  }
};

}  // namespace lb
