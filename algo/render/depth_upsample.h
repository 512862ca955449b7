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

namespace lb {

class DepthUpsampler {
 public:
  // Carves the guide rows and the weight tables (tables are filled when the arena is real).
  void Carve(Arena& arena, int32_t width, int32_t height, int32_t scale, int32_t working_width,
             int32_t working_height);
  void Begin(const ConstPlanarU8& ref, ConstImageU16 disp_q8);
  // Disparity (Q8.8, working px per view step) of every pixel of full-resolution row y.
  void Row(int32_t y, uint16_t* disp_q8);

  static constexpr int32_t kRangeSigma = 16;  // colour distance (|dY|+|dCb|+|dCr|) of weight 1/4
  // Blocks whose 3x3 disparities span at most this (Q8, a quarter px) are a smooth surface: the
  // colour term is skipped there.
  static constexpr int32_t kSmoothQ8 = 64;

 private:
  struct Guide {
    int32_t tag = -1;
    uint8_t* yuv = nullptr;  // 3 x working_width: mean Y, Cb, Cr of each block
  };
  const uint8_t* GuideRow(int32_t wy);
  const uint8_t* UniformRow(int32_t wy);

  int32_t width_ = 0, height_ = 0, scale_ = 1, ww_ = 0, wh_ = 0;
  ConstPlanarU8 ref_;
  ConstImageU16 disp_;
  Guide guide_[4];
  enum : uint8_t { kEdge = 0, kSmooth = 1, kFlat = 2 };
  uint8_t* uniform_ = nullptr;  // per working pixel of row uniform_tag_: how its 3x3 agree
  int32_t uniform_tag_ = -1;
  uint16_t* spatial_q8_ = nullptr;  // [f * 3 + o]: offset o-1 seen from sub-position f
  uint16_t* range_q8_ = nullptr;    // [colour distance 0..765]
};

}  // namespace lb
