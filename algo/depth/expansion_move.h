// The graph and the cut of one alpha-expansion move over one rectangle of a grid
// (expansion_move.cc): which nodes the move can change, the 2-label graph over them, and the
// minimum cut that settles them. It owns the max-flow solver and the rows the graph is built
// from; the grid, its labels and the D of the move come from the caller.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/arena.h"
#include "algo/depth/depth_config.h"
#include "algo/depth/grid_maxflow.h"
#include "algo/depth/move_grid.h"

namespace lb {

class ExpansionMove {
 public:
  // Carves the solver for the fine grid (with spare_bytes of room left Spare on the coarse
  // grid's graphs) and the rows of the graph's build.
  void Carve(Arena& arena, const DepthConfig& config, size_t spare_bytes);
  // Before the moves of a Compute, with its truncation (DepthStage::SmoothnessFor).
  void Start(int32_t smooth_trunc);
  // Cuts rectangle r of g's move to alpha, over the nodes with a label within `window` of
  // alpha in their 3x3 neighbourhood (all of them for a window of labels - 1 or more): every
  // node of r is then kKeep or kTake, and g.row_took marks the rows where one takes alpha. The
  // nodes of the ring around r keep their labels. Needs g.cost_alpha over r (the nodes the move
  // may free) and g.cost. Returns the nodes left free for the cut.
  int32_t Cut(MoveGrid& g, int32_t alpha, const MoveRect& r, int32_t window);

  GridMaxflow& solver() { return maxflow_; }

 private:
  enum : int32_t { kPairRight = 0, kPairDown = 1, kHigh = 2, kRowFree = 1, kRowTake = 2 };
  int32_t ClassifyRow(MoveGrid& g, int32_t alpha, int32_t y, int32_t x0, int32_t x1, int32_t e0,
                      int32_t e1);
  static uint8_t StatesRow(const uint8_t* f, const uint16_t* wr, const uint16_t* wd,
                           const uint16_t* wu, const int32_t* er, const int32_t* ed,
                           const int32_t* eu, const uint16_t* ca, const uint16_t* cc,
                           const uint8_t* near, int32_t alpha, int32_t k, uint8_t full, int32_t x0,
                           int32_t x1, int32_t* hi, uint8_t* state);
  void PairsDown(const MoveGrid& g, int32_t alpha, int32_t y, int32_t x0, int32_t x1);
  int32_t BuildRow(const MoveGrid& g, const MoveRect& r, int32_t y, int32_t node_row);
  static void BuildTerms(const uint8_t* st, const uint8_t* up, const uint8_t* down,
                         const int32_t* er, const int32_t* ed, const int32_t* eu, const int32_t* hi,
                         int32_t x0, int32_t x1, int32_t r0, int32_t r1, int32_t* balance,
                         int32_t* cap_right, int32_t* cap_down);
  void FreeSpan(const MoveGrid& g, const MoveRect& r, int32_t y, bool any);
  void Reach(const MoveRect& r, int32_t y, int32_t* x0, int32_t* x1) const;
  // A row of zeros (width int32, or 2 * width uint16) where the first row's pairs up would be.
  const int32_t* ZeroRow() const { return move_rows_ + 9 * width_; }
  int32_t* Ring(int32_t y, int32_t kind) { return move_rows_ + ((y % 3) * 3 + kind) * width_; }
  bool Full() const { return window_ >= labels_ - 1; }

  GridMaxflow maxflow_;
  int32_t width_ = 0;                         // the fine grid's: the stride of the rows below
  int32_t labels_ = 0;                        // DepthConfig::labels
  int32_t trunc_ = 1;                         // the Compute's truncation, in labels
  int32_t window_ = DepthConfig::kMaxLabels;  // of the cut in progress
  // Three rings of pass 1's terms per row (kPairRight, kPairDown, kHigh; row y % 3), ZeroRow,
  // and pass 1's near marks.
  int32_t* move_rows_ = nullptr;
  uint8_t* keep_row_ = nullptr;   // width x kKeep: the state of the rows around a rectangle
  int32_t* free_span_ = nullptr;  // per row, the free nodes of the rectangle being cut (FreeSpan)
};

}  // namespace lb
