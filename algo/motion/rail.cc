#include "algo/motion/rail.h"

namespace lb {

bool IsRail(const ViewMotion* motion, int32_t views, int32_t reference,
            const RailTolerance& tolerance, double axis[3]) {
  const double off_axis = tolerance.off_axis;
  if (!(off_axis > 0) || views < 3 || views > kMaxRailViews) return false;
  // The rail's direction: the translations, each turned to point the way of later frames.
  double u[3] = {0, 0, 0};
  for (int32_t v = 0; v < views; ++v) {
    const double sign = v > reference ? 1.0 : -1.0;
    if (v == reference) continue;
    for (int32_t k = 0; k < 3; ++k) u[k] += sign * motion[v].translation[k];
  }
  const double uu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
  if (!(uu > 0)) return false;
  double spacing[kMaxRailViews] = {}, mean = 0;
  for (int32_t v = 0; v < views; ++v) {
    if (v == reference) continue;
    const double* t = motion[v].translation;
    const double sign = v > reference ? 1.0 : -1.0;
    const double tt = t[0] * t[0] + t[1] * t[1] + t[2] * t[2];
    const double along = sign * (t[0] * u[0] + t[1] * u[1] + t[2] * u[2]);
    // Off the line by more than off_axis of its length (sin of the angle), or backwards.
    if (!(along > 0) || tt * uu - along * along > off_axis * off_axis * tt * uu) return false;
    spacing[v] = __builtin_sqrt(tt) / (sign * (v - reference));
    mean += spacing[v] / (views - 1);
  }
  for (int32_t v = 0; v < views; ++v) {
    if (v == reference) continue;
    const double d = spacing[v] - mean;
    if ((d < 0 ? -d : d) > tolerance.spacing * mean) return false;
  }
  // The turn small motion confuses with depth: about z x u, the axis that shifts the image
  // along the rail. Turns about the rail itself and about the optical axis show on their own.
  const double a[3] = {-u[1], u[0], 0};
  const double aa = a[0] * a[0] + a[1] * a[1];
  if (!(aa > 1e-6 * uu)) return false;  // a rail along the optical axis: nothing confused
  for (int32_t k = 0; k < 3; ++k) axis[k] = a[k] / __builtin_sqrt(aa);
  return true;
}

}  // namespace lb
