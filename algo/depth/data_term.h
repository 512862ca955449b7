// Multi-view data term D_p(label): photo-consistency of reference pixel p with every other view
// when p lies on the label's disparity plane.
//
// Per view: the view is sampled at x - k * d (k = view index minus reference index) with linear
// interpolation (the shift is the same for the whole image, so one Q8 fraction per view and
// label); the pixel cost is a truncated absolute colour difference plus a census (5x5, 24 bits)
// Hamming distance interpolated the same way, capped at 255. Costs are summed over 3x3 per view.
// Across views: the mean of the best half of the views that see p, so views in which p is
// occluded (about half of them at most, on one side) do not dominate. A sample outside its view
// costs one more than the worst match (DataTerm::invalid_cost), so a window of nine of them is
// told apart: that view does not see p at this label and is left out. Counting it at a high
// price instead made every label that shifts more views past the frame dearer, and pushed the
// frame's edges far.
//
// Range: pixel cost 0..255, window sum 0..2295, D (a mean of window sums) 0..2295, uint16.
// No costs are stored: each call computes the rows it is asked for, through a 3-row ring.
// Threads: a large request is cut into bands of rows, one task each (task_runner.h); a band
// starts its ring one row above itself, so every row's D is the same whoever computes it.
//
// Every kernel has a plain C reference (data_term_ref.cc, and warp_cost.cc for the plane
// sweep's pixel costs); SIMD twins give the same bits: AVX2 on x86-64 (data_term_avx2.cc and
// warp_cost_avx2.cc, when the CPU has it, else the C cost kernel compiled for SSSE3) and NEON on
// ARM (data_term_neon.cc, warp_cost_neon.cc), chosen once in Carve (data_term_kernels.h). Each
// twin the CPU has is forced and compared with the reference kernel by kernel by
// tests/algo/depth/data_term_kernels_test.cc and plane_kernels_test.cc, and as a whole by
// data_term_test.cc.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/arena.h"
#include "algo/core/image.h"
#include "algo/core/task_runner.h"
#include "algo/motion/plane_homography.h"

namespace lb {
namespace dtk {
struct RectRow;
}  // namespace dtk

// Runs of columns of one row, ascending and disjoint: [x[2k], x[2k + 1]) for k < count.
struct RowRuns {
  static constexpr int32_t kMax = 4;
  // Narrower runs are widened to this (within the row): the SIMD kernels' step, where narrow
  // rows take the C ones.
  static constexpr int32_t kMinWidth = 34;
  int32_t count = 0;
  int32_t x[2 * kMax] = {};

  // The columns of lo..hi-1 whose mark is 0 or 1 (mark indexed by x), as runs joined across
  // gaps under `join` columns (DataTerm::RunJoin) and widened to kMinWidth within 0..width-1;
  // past kMax runs, the last takes in the rest. The runs cover every marked column.
  void FromMarks(const uint8_t* mark, int32_t lo, int32_t hi, int32_t width, int32_t join);

 private:
  void Add(int32_t lo, int32_t hi, int32_t width, int32_t join);
};

struct DataTermParams {
  int32_t color_trunc = 45;   // truncation of the summed |dR|+|dG|+|dB|, 0..765
  int32_t census_weight = 4;  // cost per differing census bit (24 bits), 0..10
};

class DataTerm {
 public:
  static constexpr int32_t kMaxCost = 2295;  // 9 * 255
  static constexpr int32_t kCensusBits = 24;

  // Carves the census images, and row rings for each of `workers` workers, for `views` views of
  // width x height, and picks the SIMD kernels when the CPU has them.
  void Carve(Arena& arena, int32_t width, int32_t height, int32_t views, int32_t workers = 1);
  // Where Prepare and ComputeRect run their tasks (borrowed; nullptr: on the caller). At most
  // the carved number of workers.
  void SetRunner(TaskRunner* runner);
  TaskRunner& runner() const { return *runner_; }
  // The SIMD kernels (when `on` and the CPU has them) or the C reference; returns which is used.
  bool UseSimd(bool on);
  void SetParams(const DataTermParams& params, int32_t reference);

  // Computes the census of every view. `views` stay borrowed until the next Prepare.
  void Prepare(const ConstImageU8* views);

  // D for rows y0..y1-1 at disparity dispQ8 (px per view step) into out (row stride in elements).
  void ComputeRows(int32_t disp_q8, int32_t y0, int32_t y1, uint16_t* out, ptrdiff_t stride) {
    ComputeRect(disp_q8, 0, width_, y0, y1, out, stride);
  }
  // The same for columns x0..x1-1 only, out still pointing at (0, y0): the values are those of
  // ComputeRows, bit for bit.
  void ComputeRect(int32_t disp_q8, int32_t x0, int32_t x1, int32_t y0, int32_t y1, uint16_t* out,
                   ptrdiff_t stride);
  // ComputeRows on the caller's thread (with worker 0's scratch: no task of this term may run
  // meanwhile), its 3-sums kept in `ring` (CarriedRingSize() entries, the caller's): a call that
  // `continues` the one before on the same ring (the same disparity or planes, its y0 that call's
  // y1) takes that call's last two rows of 3-sums instead of computing them again. For callers that
  // go down the image in bands, label by label (the winner-take-all): the bands stay short enough
  // for the views' rows to stay in cache, and none pays the two rows a band's start otherwise
  // costs.
  void ComputeRowsCarried(int32_t disp_q8, const PlaneHomography* planes, int32_t y0, int32_t y1,
                          bool continues, uint16_t* ring, uint16_t* out, ptrdiff_t stride,
                          int32_t worker = 0);
  size_t CarriedRingSize() const { return static_cast<size_t>(3) * (views_ - 1) * width_; }
  // Rows y0..y1-1, each over its own runs of columns (runs[y], indexed by absolute row), out
  // still pointing at (0, y0); the values of ComputeRows, bit for bit, and nothing written
  // outside the runs. For callers whose rows need different columns (a restricted move): the
  // ring's 3-sums of a row cover only the runs of the rows that read them, and a band pays its 2
  // starting rows once rather than per run.
  void ComputeRuns(int32_t disp_q8, const RowRuns* runs, int32_t y0, int32_t y1, uint16_t* out,
                   ptrdiff_t stride);
  // Runs of a row closer than this are best joined: a run costs every view's kernel set-up on
  // each of its rows, about what this many columns cost (the plane sweep's columns cost more).
  int32_t RunJoin() const { return planes_ != nullptr ? 16 : 64; }

  // Plane sweep (warp_cost.h): the homography of each view for the label of the next ComputeRows
  // calls (borrowed; disp_q8 is then ignored), or nullptr for the rectified shifts.
  void SetPlanes(const PlaneHomography* per_view) { planes_ = per_view; }

  // What an out-of-image sample costs: one more than the worst match (color_trunc + 24 *
  // census_weight), at most 255. DepthConfig keeps that sum below 255; above, the worst matches
  // cost as much as the outside and a window of them counts as not seeing.
  int32_t invalid_cost() const { return invalid_cost_; }
  // Census of a view: per row, three planes of `width` bytes (neighbours 0-7, 8-15, 16-23 in
  // raster order, the first one in the top bit).
  const uint8_t* census(int32_t view) const { return census_[view]; }
  // The census images' memory, one block at the start of what Carve took: Prepare rewrites all
  // of it, so between a caller's last ComputeRows and the next Prepare it is free to lend.
  uint8_t* census_block() const { return census_[0]; }
  size_t census_block_bytes() const { return census_bytes_; }

  struct Kernels;

 private:
  // One worker's rings.
  struct Scratch {
    uint8_t* luma = nullptr;       // 5 rows of one view's luma (+/-128), 2 replicated pixels a side
    uint8_t* pixel = nullptr;      // one row of pixel costs, 1 replicated pixel a side
    uint16_t* hsum = nullptr;      // per other view, 3 rows of horizontal 3-sums
    int32_t* ref_lanes = nullptr;  // plane sweep: the reference row as the kernel's lanes
  };
  // The plane sweep's pixel costs of columns x0..x1-1 of row y (out indexed by x).
  // ref_lanes: the prepared reference row (PrepareRefLanes), or nullptr.
  void PixelCostRow(const PlaneHomography* planes, int32_t view, int32_t y, int32_t x0, int32_t x1,
                    uint8_t* out, const int32_t* ref_lanes) const;
  // The plane sweep: reference row y's lanes (warp_cost.h: RefLanes) into s.ref_lanes for the
  // columns every view's WindowRow(y, x0, x1) reads, when the kernel wants them.
  void PrepareRefLanes(const Scratch& s, const PlaneHomography* planes, int32_t y, int32_t x0,
                       int32_t x1) const;
  // Asks for the view rows that reference row y's columns x0..x1-1 will read; the rectified
  // shifts' sample columns from `shifts` (StartRows), which the plane sweep does not read.
  void PrefetchRow(int32_t y, int32_t x0, int32_t x1, const dtk::RectRow& shifts) const;
  // The plane sweep's 3-sums of one view's row y, columns x0..x1-1.
  void WindowRow(const Scratch& s, const PlaneHomography* planes, int32_t view, int32_t y,
                 int32_t x0, int32_t x1, uint16_t* hsum) const;
  // Every other view's 3-sums of row y (clamped to the image), columns x0..x1-1, into
  // row->hsum[j] (other view j): the plane sweep view by view, the rectified shifts by one kernel
  // call (Kernels::rect_row) with `row` set up by StartRows for the label.
  void StartRows(int32_t disp_q8, dtk::RectRow* row) const;
  void WindowRows(const Scratch& s, const PlaneHomography* planes, int32_t y, int32_t x0,
                  int32_t x1, dtk::RectRow* row) const;
  // The view index of other view j (every view but the reference, in order).
  int32_t OtherView(int32_t j) const { return j < reference_ ? j : j + 1; }
  void CensusOfView(const Scratch& s, int32_t view);
  // ring: 3 rows of 3-sums per other view, row r in slot r mod 3; `continues`: rows y0 - 1 and
  // y0 are there already.
  void ComputeBand(const Scratch& s, const PlaneHomography* planes, uint16_t* ring, bool continues,
                   int32_t disp_q8, int32_t x0, int32_t x1, int32_t y0, int32_t y1, uint16_t* out,
                   ptrdiff_t stride) const;
  void ComputeRunBand(const Scratch& s, int32_t disp_q8, const RowRuns* runs, int32_t y0,
                      int32_t y1, uint16_t* out, ptrdiff_t stride) const;
  // How many bands a request of `rows` rows and `pixels` pixels is cut into.
  int32_t Bands(int32_t rows, int64_t pixels) const;

  int32_t width_ = 0, height_ = 0, views_ = 0, reference_ = 0;
  DataTermParams params_;
  int32_t invalid_cost_ = 255;
  const ConstImageU8* images_ = nullptr;
  const Kernels* kernels_ = nullptr;
  const PlaneHomography* planes_ = nullptr;
  uint8_t* census_[16] = {};
  size_t census_bytes_ = 0;
  Scratch scratch_[kMaxWorkers];
  int32_t workers_ = 1;
  InlineRunner inline_;
  TaskRunner* runner_ = &inline_;
};

}  // namespace lb
