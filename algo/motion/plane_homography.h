// The homography a fronto-parallel plane of the reference camera induces between the reference
// and one view: a reference point on pixel ray r at inverse depth rho is seen along
// R r + rho t, so H(rho) = K (R + rho t e3^T) K^-1. It is what the depth data term warps each
// view through, one plane per label.
//
// Fixed-point form (configure-time double, rounded once): coefficients Q30 in int64, on pixel
// *index* coordinates (pixel (i, j) is the point (i, j); the continuous centre offset of 0.5 is
// folded in), scaled so the denominator is 1 at the image centre:
//   x' = (m0 x + m1 y + m2) / (m6 x + m7 y + m8),  y' = (m3 x + m4 y + m5) / (...)
// Map() evaluates it for integer pixels with two int64 divisions, rounded half away from zero to
// Q16 view coordinates: exact to 2^-16 px up to the coefficient rounding (~|x| 2^-30 px).
// Per row the three sums are linear in x, so a caller may step them by m0, m3, m6 per pixel.
// Range: |x|, |y| < 2^15 in, |x'|, |y'| < 2^14 out and a denominator within 2^-10..4 of the
// centre's (else Map reports false, as it does for a point behind the view's camera).
#pragma once

#include <cstdint>

#include "algo/motion/camera.h"

namespace lb {

struct PlaneHomography {
  static constexpr int kFrac = 30;
  int64_t m[9] = {};

  // (x, y) reference pixel index -> view position in pixel-index coordinates, Q16.
  bool Map(int32_t x, int32_t y, int32_t* x_q16, int32_t* y_q16) const {
    const int64_t den = m[6] * x + m[7] * y + m[8];
    const int64_t nx = m[0] * x + m[1] * y + m[2];
    const int64_t ny = m[3] * x + m[4] * y + m[5];
    if (den < (int64_t{1} << 20) || den >= (int64_t{1} << 32)) return false;
    const int64_t lim = den << 14;
    if (nx >= lim || -nx >= lim || ny >= lim || -ny >= lim) return false;
    *x_q16 = Div(nx, den);
    *y_q16 = Div(ny, den);
    return true;
  }

 private:
  static int32_t Div(int64_t n, int64_t den) {
    const int64_t a = n < 0 ? -n : n;
    const int64_t q = ((a << 16) + (den >> 1)) / den;  // a < den 2^14: no overflow
    return static_cast<int32_t>(n < 0 ? -q : q);
  }
};

// H(inv_depth) for one view, with inv_depth in the units of the motion result (see
// motion_stage.h). The identity motion gives the identity for every plane.
PlaneHomography MakePlaneHomography(const CameraIntrinsics& k, const ViewMotion& motion,
                                    double inv_depth);

// The same map in double on continuous coordinates (for tests and references).
void ProjectPlane(const CameraIntrinsics& k, const ViewMotion& motion, double inv_depth, double x,
                  double y, double* vx, double* vy);

}  // namespace lb
