// The motion stage's parallax measurement (motion_stage.h): how far the points' depths move
// them in a view, against the same rays at one inverse depth. Without translation a fit can
// still give wild depths (w t stays tiny), so this, not |t| or the depth spread alone, says
// whether a burst holds depth.
#pragma once

#include <cstdint>

#include "algo/motion/camera.h"

namespace lb {

struct ParallaxPoints {
  // Reference pixel-index positions (2 per point, the centre of pixel (i, j) at (i, j)) and
  // their inverse depths, in the units of the view's translation.
  const double* xy = nullptr;
  const double* inv_depth = nullptr;
  int32_t count = 0;
  double inv_depth_ref = 0;  // the depth every point is compared against (the median)
  // The positions are normalised with `measured` (the intrinsics the frames were given) and the
  // lens's terms k1, k0 (UndistortScale), and projected with `projected` (fx / (1 + k0)).
  CameraIntrinsics measured, projected;
  double k1 = 0, k0 = 0;
};

// The 90th percentile over the points of the distance (px) between each point seen through
// `motion` at its inverse depth and at inv_depth_ref. `scratch` holds count doubles; count >= 1.
// Double arithmetic (sqrt only, and a sort), the same bits on every target.
double ParallaxPx(const ParallaxPoints& points, const ViewMotion& motion, double* scratch);

}  // namespace lb
