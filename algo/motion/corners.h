// Corner detection on the reference's level-0 grey image: the Harris response
// det(S) - trace(S)^2 / 16 of the structure tensor S summed over a 5x5 box of central-difference
// gradients, computed row by row with a ring of 5 box-summed rows (no full-frame buffers). The
// image is cut into square cells and each cell keeps its strongest pixel, so the points cover
// the frame evenly (the bundle adjustment needs depth spread over the whole view, not 300
// corners on one brick wall).
//
// Scaling: gradients are -255..255, products <= 65025, a 5x5 sum <= 1.63e6 (int32), det and
// trace^2 <= 2.7e12 (int64).
#pragma once

#include <cstdint>

#include "algo/core/arena.h"
#include "algo/core/image.h"
#include "algo/core/status.h"

namespace lb {

struct Corner {
  int32_t x = 0, y = 0;  // level-0 pixel
  int64_t response = 0;
};

class CornerDetector {
 public:
  // Border kept clear of corners, so the tracker's windows start inside the image.
  static constexpr int32_t kBorder = 16;

  Status Carve(int32_t width, int32_t height, int32_t cell, Arena& arena);
  int32_t max_corners() const { return cells_x_ * cells_y_; }

  // Writes up to max_corners() corners whose response is at least `min_response` and at least
  // 1/`relative_div` of the frame's strongest; returns how many.
  int32_t Detect(const ConstImageU8& grey, int64_t min_response, int32_t relative_div, Corner* out);

 private:
  int32_t width_ = 0, height_ = 0, cell_ = 0, cells_x_ = 0, cells_y_ = 0;
  int32_t* ring_ = nullptr;  // 5 rows x 3 products x width: horizontal 5-sums
  Corner* best_ = nullptr;   // per cell
};

}  // namespace lb
