// Grey image pyramids for corner detection and tracking. Level 0 is the working-resolution luma
// (BT.601, from core/color.h) smoothed by a 3x3 binomial: bilinear interpolation of a sharp
// (aliased) image smooths it, so without the prefilter a window sampled between pixels would
// match best at whole-pixel shifts ("pixel locking", a bias shared by every point of a view when
// the whole frame moves by the same fraction). Each next level is the 2x2 box mean of the one
// below, rounded half up, with odd sizes dropping the last column/row. All uint8: no precision is
// lost that the tracker's Q8 bilinear sampling could use.
#pragma once

#include <cstdint>

#include "algo/core/arena.h"
#include "algo/core/image.h"
#include "algo/core/status.h"

namespace lb {

class GreyPyramid {
 public:
  static constexpr int32_t kMaxLevels = 6;

  // Carves `levels` images for a width x height level 0 (planning arenas only count).
  Status Carve(int32_t width, int32_t height, int32_t levels, Arena& arena);
  // Fills every level from an RGB8 (3 channels) or grey (1 channel) view of the level-0 size.
  Status Build(const ConstImageU8& view);

  int32_t levels() const { return levels_; }
  const ImageU8& level(int32_t i) const { return level_[i]; }

 private:
  ImageU8 grey_;  // luma before the prefilter
  ImageU8 level_[kMaxLevels];
  int32_t levels_ = 0;
};

// Mean absolute central-difference gradient |dx| + |dy| of a grey image, Q4 (interior pixels).
// A frame much below the burst's typical value is blurred (motion blur or focus).
int32_t SharpnessQ4(const ConstImageU8& grey);

}  // namespace lb
