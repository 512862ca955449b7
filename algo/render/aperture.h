// Aperture kernels: the shape a defocused point takes (a disc, or an n-blade iris with rotation
// and curved blades), stored as one row span per kernel row so a layer can be blurred with row
// prefix sums: per kernel row, the cells [left, right] weigh `w`, the cells left-1 and right+1
// weigh `wl` and `wr` (the anti-aliased ends). Weights are Q8 pixel coverage (256 = covered),
// measured on a 16x16 grid of samples per pixel. Built at Begin time (float allowed there).
#pragma once

#include <cstdint>

namespace lb {

struct Aperture;  // render_stage.h

struct KernelRow {
  int16_t left = 0, right = -1;   // the fully weighted span, may be empty (right < left)
  int16_t w = 0, wl = 0, wr = 0;  // Q8 coverage of the span cells and of the two end cells
};

// Kernel rows run from dy = -half to half; every cell lies within [-half, half] in x.
inline int32_t KernelHalf(float radius) {
  // A cell at distance |dx| is touched when |dx| - 0.5 < radius.
  int32_t h = 0;
  while (static_cast<float>(h) + 0.5f < radius) ++h;
  return h;
}

// Shape test with precomputed blade normals (no libm transcendental calls, so the kernel is the
// same on every platform).
class ApertureShape {
 public:
  static constexpr int32_t kMaxBlades = 12;
  explicit ApertureShape(const Aperture& aperture);
  // Is (x, y), relative to the centre, inside the shape of circumradius `radius`?
  bool Contains(double x, double y, double radius) const;

 private:
  int32_t blades_ = 0;
  double curvature_ = 1.0;
  double apothem_ = 1.0;  // cos(pi / blades): the inradius of the unit polygon
  double nx_[kMaxBlades] = {}, ny_[kMaxBlades] = {};
};

// Fills rows[0 .. 2*half] for the gather kernel of a point blurred to `radius` px (the shape
// reflected through its centre, so a gather equals a scatter for any blade count) and returns
// the total weight (sum of all cell weights, Q8). A radius below 0.5 px gives the identity.
uint32_t BuildKernel(const ApertureShape& shape, float radius, int32_t half, KernelRow* rows);

}  // namespace lb
