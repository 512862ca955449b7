// The coarse pass of coarse-to-fine depth (DepthConfig::coarse_blocks, coarse_pass.cc): a grid of
// 2x2 pixel blocks, its weights and its winner-take-all labels over every coarse_step-th label
// (Start), the D of a move's label on the blocks (MoveCosts, for the stage's moves over the
// blocks), and the hand-over of the blocks' labels to the pixels (Finish).
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/arena.h"
#include "algo/depth/confidence.h"
#include "algo/depth/data_term.h"
#include "algo/depth/depth_config.h"
#include "algo/depth/grid_maxflow.h"
#include "algo/depth/move_grid.h"

namespace lb {

class CoarsePass {
 public:
  // Bytes the pass keeps in the solver's spare for the configuration (its block D, rings and
  // winners), given the data term's carried ring size: the room to carve for the most stripes
  // the workers can take.
  static size_t SpareBytes(const DepthConfig& config, size_t ring_size);
  // Carves the block grid for the configuration.
  void CarveGrid(Arena& arena, const DepthConfig& config);
  MoveGrid& grid() { return grid_; }

  // The block weights from the fine grid's, each block's best coarse label and its D, from the
  // solver's spare when there is room; the grid is then ready for the moves.
  void Start(const MoveGrid& fine, const LabelTerm& term, GridMaxflow& solver);
  // D of alpha for the blocks of a move's rectangle r, in grid().cost_alpha (the fine grid's
  // cost_alpha is scratch).
  void MoveCosts(int32_t alpha, const MoveRect& r, MoveGrid& fine, const LabelTerm& term);
  // After the moves: every pixel of `fine` takes its block's label, with its D and row labels.
  // runs and marks: scratch (MoveBook::runs, run_marks).
  void Finish(MoveGrid& fine, const LabelTerm& term, RowRuns* runs, uint8_t* marks);

  // Whether the hand-over may take the winner-take-all's D where a block kept its label, and
  // the pixels the last one took (DepthStageProbe).
  void KeepWinners(bool on) { keep_winners_ = on; }
  int32_t handover_kept() const { return handover_kept_; }
  // Whether the winner-take-all may take one stripe per worker, and the stripes the last one
  // took (0 without carried rings).
  void StripedWinners(bool on) { striped_winners_ = on; }
  int32_t winner_stripes() const { return winner_stripes_; }
  // Where the winner-take-all leaves each pixel's two lowest D (borrowed; nullptr: nowhere).
  void SetMargins(LabelMargins* margins) { margins_ = margins; }

 private:
  // Where the pass keeps, in the max-flow's spare, each coarse label's block D, `stripes`
  // winner-take-all rings per coarse label, and the winners' pixel D and labels (byte offsets;
  // end: all of it).
  struct Room {
    size_t block_bytes, rings_at, rings_end, winners_at, labels_at, end;
  };
  static Room Layout(const DepthConfig& config, size_t ring_size, int32_t stripes);
  // The most stripes of block rows the winner-take-all may take with `workers` workers.
  static int32_t Stripes(const DepthConfig& config, int32_t workers);
  void BlockWeights(const MoveGrid& fine);
  // ring: the label's carried 3-sums (DataTerm::ComputeRowsCarried) when `blocks` is a band of
  // whole block rows, `continues` when the band before it was the label's last call.
  // With a ring it touches nothing shared but the data term's scratch of `worker`: the
  // winner-take-all's stripes run it side by side.
  void BlockCosts(const MoveGrid& fine, const LabelTerm& term, int32_t label,
                  const MoveRect& blocks, uint16_t* out, uint16_t* ring = nullptr,
                  bool continues = false, int32_t worker = 0);
  void WinnerTakeAll(const MoveGrid& fine, const LabelTerm& term, GridMaxflow& solver);
  // The winner-take-all over the block rows of `stripe`, going down them in bands with its
  // own rings (one per coarse label, carried from band to band); `worker`: whose data term
  // scratch it uses.
  void WinnersOfStripe(const MoveGrid& fine, const LabelTerm& term, const MoveRect& stripe,
                       uint16_t* rings, int32_t worker);
  void KeepWinnerCosts(const MoveGrid& fine, const MoveRect& b, const uint16_t* block_costs);
  uint16_t* CoarseCosts(int32_t label, int32_t coarse_step) {
    return block_costs_ + static_cast<size_t>(label / coarse_step) * grid_.width * grid_.height;
  }
  void FineFromBlocks(MoveGrid& fine, const LabelTerm& term, RowRuns* runs, uint8_t* marks);

  // The pixels' D of `label` over the block rows of `rows`, as BlockCosts left them in the fine
  // grid's cost_alpha, into the margins.
  void TakeMargins(const MoveGrid& fine, const MoveRect& rows, int32_t label, int32_t step);

  MoveGrid grid_;  // the blocks
  LabelMargins* margins_ = nullptr;
  // The grid's own cost_alpha, while the moves point it at block_costs_.
  uint16_t* scratch_ = nullptr;
  // The block D of every coarse label, kept from the winner-take-all for the moves in storage
  // the max-flow does not touch on the blocks' graphs; nullptr when it does not fit.
  uint16_t* block_costs_ = nullptr;
  // The winner-take-all's winners for the hand-over, in the max-flow's spare when there is room
  // (else nullptr): each block's label and its pixels' D at it (indexed as the fine grid).
  uint8_t* winner_labels_ = nullptr;
  uint16_t* winner_costs_ = nullptr;
  bool keep_winners_ = true;     // off: the hand-over computes every D
  bool striped_winners_ = true;  // off: the winner-take-all in one stripe
  int16_t winner_stripes_ = 0;   // the stripes the last winner-take-all took (<= kMaxWorkers)
  int32_t handover_kept_ = 0;    // pixels whose D the last hand-over took from the winners
};

}  // namespace lb
