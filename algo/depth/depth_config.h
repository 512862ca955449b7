// The depth stage's configuration (depth_stage.h describes the stage and its units).
#pragma once

#include <cstdint>

#include "algo/motion/camera.h"

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
  // color_trunc + 24 * census_weight is at most 254: the data term prices a sample outside its
  // view one above the worst match, to know the views that do not see a pixel.
  int32_t color_trunc = 45;   // truncation of |dR|+|dG|+|dB|, 1..254
  int32_t census_weight = 4;  // cost per differing census bit, 0..10
  // Smoothness V(a, b) = w_pq * min(|a - b|, smooth_trunc) over label indices: truncated linear,
  // Potts when smooth_trunc is 1. w_pq is smooth_weight where the reference is flat and
  // smooth_weight * edge_weight_q8 / 256 across a colour edge (largest channel step above
  // edge_threshold), so label changes prefer image edges.
  // Both are stated for labels kSmoothSpacingQ8 (a quarter px per view step) apart. The stage
  // holds the cost of a step of disparity, not of a label, whatever the range and the label
  // count: labels half as far apart get half the weight and twice the truncation
  // (DepthStage::SmoothnessFor). Otherwise a burst with little parallax, which gets finer
  // labels, would be smoothed harder than one with more.
  static constexpr int32_t kSmoothSpacingQ8 = 64;

  int32_t smooth_weight = 96;   // 0..4096, times smooth_trunc at most 16383
  int32_t smooth_trunc = 8;     // 1..64
  int32_t edge_threshold = 16;  // 0..255
  int32_t edge_weight_q8 = 64;  // 0..256
  int32_t max_cycles = 1;       // expansion cycles over every label, 0..32 (0: winner-take-all)
  // Coarse to fine: with coarse_step > 1, one pass of full moves over every coarse_step-th
  // label comes first, and the cycles' moves then free only pixels whose label is within
  // fine_window of alpha (a restricted move: still an exact cut over the pixels it frees). The
  // coarse pass settles the layout, the fine moves its sub-pixel steps, over far smaller graphs.
  // What 4 and 2 cost in bad pixels against full moves over every label, and save in time, on
  // the Middlebury sets: docs/accuracy.md and docs/performance.md.
  int32_t coarse_step = 4;  // 1..16; 1: every move is a full move
  int32_t fine_window = 2;  // 1..255
  // The coarse pass labels 2x2 blocks of pixels (its data costs the blocks' sums, its pair
  // weights the sums across block edges, so it minimises the same energy over block-constant
  // labels) on a quarter of the nodes; the fine moves then also free pixels next to a label
  // within fine_window, which moves the block edges onto the image's.
  bool coarse_blocks = true;
  bool subpixel = true;  // parabola fit between labels for the output
  // The confidence map (confidence.h): kept from the winner-take-all's costs, a few bytes a
  // pixel of arena and a few per cent of the stage's time; the disparity map is the same either
  // way. Every photo carries it (GDepth:Confidence, Dynamic Depth's confidence item).
  bool confidence = true;
  // Workers the data term carves rings for (task_runner.h), 1..kMaxWorkers.
  int32_t workers = 1;
};

}  // namespace lb
