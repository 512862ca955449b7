// Takes back the near side's overreach at depth edges ("foreground fattening").
//
// The data term compares 3x3 sums of a 5x5 census, so a pixel's cost sees up to 3 px around it,
// and the coarse pass labels 2x2 blocks: a background pixel that close to a nearer surface
// matches that surface's motion too, and the near side spreads over the far one by up to the
// cost's reach. It never goes the other way, so the fix looks only the one way: a pixel with a
// surface farther than itself by more than an edge step (EdgeStepQ8) within reach takes the median
// of its window weighted by colour likeness to itself, when that median is farther (smaller) than
// its own. A surface's pixels vote for it by their colour; the window stays centred at the borders,
// so a slanted surface's median is its centre.
//
// Weights: 256 * exp(-d / kColourScale) over d = |dR| + |dG| + |dB| against the centre, in a
// table built at compile time; the median by a weighted quickselect. Integer-only per pixel.
// From one map into another, in bands of rows, one task each (task_runner.h): the same bits for
// any number of workers; a row of column minima per worker, carved once. What it gains and
// costs, and the variants measured: docs/accuracy.md.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/arena.h"
#include "algo/core/image.h"
#include "algo/core/task_runner.h"
#include "algo/depth/depth_config.h"

namespace lb {

class FatteningTrim {
 public:
  static constexpr int32_t kRadius = 4;        // the data term's 3 px reach and the 2x2 blocks
  static constexpr int32_t kColourScale = 16;  // levels of |dR| + |dG| + |dB|
  // A depth edge: a step over a quarter px per view step (the spacing of labels the smoothness
  // is stated for) and over one of the map's labels, so the labels' noise and the terraces a
  // slope makes of them are not edges.
  static int32_t LabelStepQ8(const DepthConfig& c) {
    return c.labels > 1 ? (c.disp_max_q8 - c.disp_min_q8) / (c.labels - 1) : 0;
  }
  static int32_t EdgeStepQ8(int32_t label_step_q8) {
    return label_step_q8 > DepthConfig::kSmoothSpacingQ8 ? label_step_q8
                                                         : DepthConfig::kSmoothSpacingQ8;
  }

  static size_t RequiredBytes(int32_t width, int32_t workers);
  void Carve(Arena& arena, int32_t width, int32_t workers);
  // Where Run runs its bands (borrowed; nullptr: on the caller). At most the carved workers.
  void SetRunner(TaskRunner* runner);

  // `out` from `in` (px per view step, Q8.8, larger is nearer, labels `label_step_q8` apart; the
  // same size, apart in memory), guided by `reference` (RGB8, that size); returns the pixels
  // moved. Widths up to the carved one.
  int64_t Run(const ConstImageU8& reference, ConstImageU16 in, ImageU16 out, int32_t label_step_q8);

 private:
  int64_t Rows(const ConstImageU8& reference, ConstImageU16 in, ImageU16 out, int32_t edge,
               int32_t y0, int32_t y1, int32_t worker) const;

  InlineRunner inline_;
  TaskRunner* runner_ = &inline_;
  int32_t width_ = 0, workers_ = 0;
  uint16_t* column_min_[kMaxWorkers] = {};  // per worker: the least of `in` over the window's rows
};

}  // namespace lb
