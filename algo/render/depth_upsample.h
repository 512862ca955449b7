// Edge-aware depth upsampling: the working-resolution disparity to one value per full-resolution
// pixel, guided by the full-resolution reference (a joint bilateral upsampling). A pixel takes
// the weighted mean of the 3x3 working disparities around it; each weight is a spatial term
// (distance to that working pixel's centre) times a range term (how close the pixel's colour is
// to the mean colour of that working pixel's block), so a depth edge snaps to the image edge it
// belongs to: hair and thin objects keep their depth. Blocks whose 3x3 disparities agree are
// copied, and smooth ones (a slanted surface) use the spatial term alone. Fixed point: weights
// Q8, the mean by integer division (exact).
#pragma once

#include <cstdint>

#include "algo/core/arena.h"
#include "algo/core/image.h"
#include "algo/core/task_runner.h"

namespace lb {

class DepthUpsampler {
 public:
  // Carves the guide rows and the weight tables (tables are filled when the arena is real).
  // `workers` (1..kMaxWorkers) rows may be upsampled at once, each worker with guide rows of
  // its own.
  void Carve(Arena& arena, int32_t width, int32_t height, int32_t scale, int32_t working_width,
             int32_t working_height, int32_t workers = 1);
  // `confidence` (optional, the disparity's size, 255 sure): on a depth edge an unsure
  // neighbour counts for less than a sure one of the same colour.
  // `one_side`: a pixel on a depth edge takes one side's depth (EdgeValue), for a map that is
  // kept; without, the weighted mean of both, which a render at full size shows as the soft
  // transition a pixel the edge crosses has.
  void Begin(const ConstPlanarU8& ref, ConstImageU16 disp_q8, ConstImageU8 confidence = {},
             bool one_side = false);
  // Disparity (Q8.8, working px per view step) of every pixel of full-resolution row y. Rows of
  // different workers may be made at once; the values do not depend on which worker made them.
  // With `step` > 1 only columns phase + k * step are made, into disp_q8[k] (a coarser grid's
  // samples, depth_refine.h).
  void Row(int32_t y, uint16_t* disp_q8, int32_t worker = 0, int32_t step = 1, int32_t phase = 0);

  static constexpr int32_t kRangeSigma = 16;  // colour distance (|dY|+|dCb|+|dCr|) of weight 1/4
  // Blocks whose 3x3 disparities span at most smooth_q8() are a smooth surface: the colour term
  // is skipped there. It is a share of the map's range (a slanted surface's label steps grow
  // with the map's size, and a phone's units are its own), at least kSmoothQ8 (a quarter px).
  static constexpr int32_t kSmoothQ8 = 64;
  static constexpr int32_t kSmoothShare = 32;
  // An unsure neighbour's weight: (confidence + kConfidenceFloor) / 256 of a sure one's.
  static constexpr int32_t kConfidenceFloor = 32;
  int32_t smooth_q8() const { return smooth_q8_; }

 private:
  struct Guide {
    int32_t tag = -1;
    uint8_t* yuv = nullptr;  // 3 x working_width: mean Y, Cb, Cr of each block
  };
  // One worker's cache of the rows around the row it makes.
  struct Cache {
    Guide guide[4];
    uint8_t* uniform = nullptr;  // per working pixel of row uniform_tag: how its 3x3 agree
    uint32_t* sums = nullptr;    // GuideRow's column sums: width luma, then 2 x chroma width
    int32_t uniform_tag = -1;
  };
  const uint8_t* GuideRow(Cache& c, int32_t wy);
  uint16_t EdgeValue(const uint32_t* w, const int32_t* d, uint16_t fallback) const;
  static uint16_t MeanValue(const uint32_t* w, const int32_t* d, uint16_t fallback);
  const uint8_t* UniformRow(Cache& c, int32_t wy);

  int32_t width_ = 0, height_ = 0, scale_ = 1, ww_ = 0, wh_ = 0, workers_ = 1;
  int32_t smooth_q8_ = kSmoothQ8;
  bool one_side_ = false;
  ConstPlanarU8 ref_;
  ConstImageU16 disp_;
  ConstImageU8 confidence_;
  Cache cache_[kMaxWorkers];
  enum : uint8_t { kEdge = 0, kSmooth = 1, kFlat = 2 };
  uint16_t* spatial_q8_ = nullptr;  // [f * 3 + o]: offset o-1 seen from sub-position f
  uint16_t* range_q8_ = nullptr;    // [colour distance 0..765]
};

}  // namespace lb
