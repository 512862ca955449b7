#include "algo/motion/parallax.h"

#include <algorithm>

namespace lb {

double ParallaxPx(const ParallaxPoints& pts, const ViewMotion& mo, double* scratch) {
  const CameraIntrinsics& k = pts.measured;
  const int32_t m = pts.count;
  for (int32_t j = 0; j < m; ++j) {
    double p[2][3];
    double r[3] = {(pts.xy[2 * j] + 0.5 - k.cx) / k.fx, (pts.xy[2 * j + 1] + 0.5 - k.cy) / k.fy,
                   1.0};
    const double u = UndistortScale(pts.k1, r[0], r[1], pts.k0);
    r[0] *= u;
    r[1] *= u;
    const double ws[2] = {pts.inv_depth[j], pts.inv_depth_ref};
    for (int s = 0; s < 2; ++s) {
      for (int i = 0; i < 3; ++i) {
        p[s][i] = mo.rotation[i][0] * r[0] + mo.rotation[i][1] * r[1] + mo.rotation[i][2] * r[2] +
                  ws[s] * mo.translation[i];
      }
    }
    const double dx = pts.projected.fx * (p[0][0] / p[0][2] - p[1][0] / p[1][2]);
    const double dy = pts.projected.fy * (p[0][1] / p[0][2] - p[1][1] / p[1][2]);
    scratch[j] = __builtin_sqrt(dx * dx + dy * dy);
  }
  std::sort(scratch, scratch + m);
  return scratch[(m - 1) * 90 / 100];
}

}  // namespace lb
