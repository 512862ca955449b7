#include "algo/motion/rail.h"

namespace lb {

bool IsRail(const ViewMotion* motion, int32_t views, int32_t reference,
            const RailTolerance& tolerance, double axis[3]) {
  const double off_axis = tolerance.off_axis;
  if (!(off_axis > 0) || views < 3 || views > kMaxRailViews) return false;
  auto dot = [](const double* a, const double* b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  };
  // The rail's direction, whatever the frames' order in the list: the translations, each
  // turned to point the way of the longest, with the sign that makes the line's largest
  // component positive.
  int32_t longest = -1;
  double longest_tt = 0;
  for (int32_t v = 0; v < views; ++v) {
    const double tt = dot(motion[v].translation, motion[v].translation);
    if (v != reference && tt > longest_tt) {
      longest_tt = tt;
      longest = v;
    }
  }
  if (longest < 0) return false;
  double u[3] = {0, 0, 0};
  for (int32_t v = 0; v < views; ++v) {
    if (v == reference) continue;
    const double* t = motion[v].translation;
    const double sign = dot(t, motion[longest].translation) < 0 ? -1.0 : 1.0;
    for (int32_t k = 0; k < 3; ++k) u[k] += sign * t[k];
  }
  int32_t major = 0;
  for (int32_t k = 1; k < 3; ++k)
    major = (u[k] < 0 ? -u[k] : u[k]) > (u[major] < 0 ? -u[major] : u[major]) ? k : major;
  if (u[major] < 0) {
    for (double& x : u) x = -x;
  }
  const double uu = dot(u, u);
  if (!(uu > 0)) return false;
  // Each frame's place along the line (the reference's 0), off it by at most off_axis of its
  // length (sin of the angle).
  double along[kMaxRailViews] = {};
  for (int32_t v = 0; v < views; ++v) {
    if (v == reference) continue;
    const double* t = motion[v].translation;
    const double tt = dot(t, t);
    along[v] = dot(t, u);
    if (!(tt > 0) || tt * uu - along[v] * along[v] > off_axis * off_axis * tt * uu) return false;
  }
  // Equal steps: each frame's distance from the reference over its steps from it, the frames
  // counted in their order along the line (the reference included, ties by list place: a frame
  // that went back onto another's place makes a step of 0).
  double spacing[kMaxRailViews] = {}, mean = 0;
  for (int32_t v = 0; v < views; ++v) {
    if (v == reference) continue;
    const double side = along[v] > 0 ? 1.0 : -1.0;
    int32_t steps = 1;
    for (int32_t w = 0; w < views; ++w) {
      const double a = side * along[w], b = side * along[v];
      steps += w != v && w != reference && a > 0 && (a < b || (a == b && w < v));
    }
    spacing[v] = side * along[v] / __builtin_sqrt(uu) / steps;
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
