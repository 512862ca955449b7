#include "algo/motion/plane_homography.h"

namespace lb {
namespace {

// 3x3 row-major products, written out so no library sums in its own order.
void Mul(const double a[9], const double b[9], double out[9]) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      out[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
    }
  }
}

// H on continuous coordinates.
void Continuous(const CameraIntrinsics& k, const ViewMotion& mo, double rho, double h[9]) {
  double a[9];
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) a[3 * i + j] = mo.rotation[i][j];
    a[3 * i + 2] += rho * mo.translation[i];
  }
  const double kk[9] = {k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1};
  const double ki[9] = {1 / k.fx, 0, -k.cx / k.fx, 0, 1 / k.fy, -k.cy / k.fy, 0, 0, 1};
  double t[9];
  Mul(a, ki, t);
  Mul(kk, t, h);
}

int64_t Round(double v) { return static_cast<int64_t>(v >= 0 ? v + 0.5 : v - 0.5); }

}  // namespace

PlaneHomography MakePlaneHomography(const CameraIntrinsics& k, const ViewMotion& motion,
                                    double inv_depth) {
  double hc[9], h[9], t[9];
  Continuous(k, motion, inv_depth, hc);
  // Index coordinates: continuous = index + 0.5 on both sides.
  const double shift[9] = {1, 0, 0.5, 0, 1, 0.5, 0, 0, 1};
  const double unshift[9] = {1, 0, -0.5, 0, 1, -0.5, 0, 0, 1};
  Mul(hc, shift, t);
  Mul(unshift, t, h);
  const double xc = k.cx - 0.5, yc = k.cy - 0.5;
  const double den = h[6] * xc + h[7] * yc + h[8];
  PlaneHomography out;
  const double scale = static_cast<double>(int64_t{1} << PlaneHomography::kFrac) / den;
  for (int i = 0; i < 9; ++i) out.m[i] = Round(h[i] * scale);
  return out;
}

void ProjectPlane(const CameraIntrinsics& k, const ViewMotion& motion, double inv_depth, double x,
                  double y, double* vx, double* vy) {
  double h[9];
  Continuous(k, motion, inv_depth, h);
  const double d = h[6] * x + h[7] * y + h[8];
  *vx = (h[0] * x + h[1] * y + h[2]) / d;
  *vy = (h[3] * x + h[4] * y + h[5]) / d;
}

}  // namespace lb
