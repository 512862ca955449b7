// The bookkeeping of the expansion moves: where a move looks (its rectangles, move_rects.cc), the
// D a restricted move computes near its labels, and what a move leaves behind (move_record.cc):
// the switches applied to the grid, the energy change, and for the fine grid the D of each
// pixel's labels either side that the sub-label fit reads (FitBelow, FitAbove).
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/arena.h"
#include "algo/depth/data_term.h"
#include "algo/depth/depth_config.h"
#include "algo/depth/move_grid.h"

namespace lb {

class MoveBook {
 public:
  // Carves the rows for the configuration. SetFitMemory lends the memory of the fit's D
  // (2 * width * height uint16), which the coarse pass uses before the fine moves.
  void Carve(Arena& arena, const DepthConfig& config);
  void SetFitMemory(uint16_t* fit);
  // Before the moves of a Compute, with its truncation (DepthStage::SmoothnessFor), and before
  // the fine grid's moves (after the coarse pass): nothing recorded, no D computed.
  void Start(int32_t smooth_trunc);
  void StartFine(MoveGrid& fine);

  // The rectangles of g that the move to alpha looks at (g.rects; returns their count): the
  // whole grid, or for a window below labels - 1 the runs of rows next to a label within
  // `window` of alpha, split. On the fine grid (`fine`) it first clears what the move before
  // last computed in the D buffer this move takes.
  int32_t MoveRects(MoveGrid& g, int32_t alpha, int32_t window, bool fine);
  // A restricted move's D (cost_alpha) where it may free pixels, over the whole fine grid.
  void ComputeNear(MoveGrid& fine, const LabelTerm& term, int32_t disp_q8);
  // Notes that the fine grid's cost_alpha holds D over r.
  static void Written(MoveGrid& fine, const MoveRect& r) {
    NoteWritten(fine.written, &fine.written_count, fine.written_capacity, r);
  }
  // After the cuts of the move to alpha: applies the switches to g and returns the energy
  // change.
  int64_t Record(MoveGrid& g, int32_t alpha, bool fine, const LabelTerm& term);

  // Per pixel of the fine grid, D(f_p - 1) and D(f_p + 1), 0xffff when not seen.
  const uint16_t* FitBelow() const { return below_; }
  const uint16_t* FitAbove() const { return above_; }
  // The label whose D the fine grid's prev_alpha holds (-1: none), and forgetting it.
  int32_t prev_label() const { return prev_label_; }
  void ForgetPrevious() { prev_label_ = -1; }
  // Per row, runs of columns, and 2 * (width + 2) bytes of marks to make them from: scratch
  // between the moves (the coarse pass's hand-over uses them too).
  RowRuns* runs() { return runs_; }
  uint8_t* run_marks() { return run_marks_; }

 private:
  int32_t SplitRect(MoveGrid& g, int32_t i, int32_t count, int32_t lo, int32_t hi);
  static void RecordNeighbours(int32_t alpha, const uint8_t* st, const uint8_t* f,
                               const uint16_t* ca, uint16_t* below, uint16_t* above, int32_t x0,
                               int32_t x1);
  void PastCosts(MoveGrid& fine, const LabelTerm& term, int32_t label);

  // In below_ during Record: D(f - 1) is wanted from PastCosts.
  static constexpr uint16_t kWanted = 0xfffe;
  int32_t width_ = 0, height_ = 0, labels_ = 0;
  bool subpixel_ = true;
  int32_t smooth_[DepthConfig::kMaxLabels] = {};  // min(d, the truncation) for a label distance d
  uint16_t* below_ = nullptr;                     // D_p(f_p - 1), 0xffff when not seen
  uint16_t* above_ = nullptr;                     // D_p(f_p + 1)
  int32_t* want_span_ = nullptr;  // per row, the columns where below_ holds kWanted ([w, 0): none)
  uint8_t* split_ = nullptr;      // max(width, height) + 2 bytes: SplitRect's column or row marks
  // Per row, the runs of columns whose D a restricted move or the hand-over computes.
  RowRuns* runs_ = nullptr;
  uint8_t* run_marks_ = nullptr;  // 2 * (width + 2) bytes: the columns those runs hold
  // The labels near alpha that a restricted move computes D next to (MoveRects).
  int32_t near_lo_ = 0, near_hi_ = 0;
  int32_t prev_label_ = -1;
};

}  // namespace lb
