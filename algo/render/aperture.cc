#include "algo/render/aperture.h"

#include <cmath>

#include "algo/core/sin_cos.h"
#include "algo/render/render_stage.h"

namespace lb {

ApertureShape::ApertureShape(const Aperture& a) {
  blades_ = a.blades >= 3 && a.blades <= kMaxBlades ? a.blades : 0;
  curvature_ =
      blades_ == 0 ? 1.0 : (a.curvature < 0.0f ? 0.0 : (a.curvature > 1.0f ? 1.0 : a.curvature));
  if (blades_ == 0) return;
  double s = 0.0, c = 0.0;
  SinCosDeg(180.0 / blades_, &s, &c);
  apothem_ = c;
  // Rotation 0: the first blade's flat edge faces +x.
  for (int32_t i = 0; i < blades_; ++i) {
    SinCosDeg(a.rotation_deg + 360.0 * i / blades_, &ny_[i], &nx_[i]);
  }
}

bool ApertureShape::Contains(double x, double y, double radius) const {
  const double d2 = x * x + y * y;
  if (curvature_ >= 1.0) return d2 <= radius * radius;
  if (d2 == 0.0) return true;
  const double d = std::sqrt(d2);  // IEEE sqrt is exact-rounded everywhere
  double m = -1.0;
  for (int32_t i = 0; i < blades_; ++i) {
    const double p = (x * nx_[i] + y * ny_[i]) / d;
    m = p > m ? p : m;
  }
  // Radial blend between the polygon's boundary (apothem / cos) and the circle.
  const double rho = (1.0 - curvature_) * radius * apothem_ / m + curvature_ * radius;
  return d <= rho;
}

namespace {

constexpr int32_t kSamples = 16;  // per pixel side

// Q8 coverage of the cell centred at (cx, cy) by the shape reflected through the origin.
int32_t Coverage(const ApertureShape& shape, double radius, int32_t cx, int32_t cy) {
  // The shape lies inside its circumscribed circle: a cell beyond it is empty.
  const double nx = cx > 0 ? cx - 0.5 : (cx < 0 ? -cx - 0.5 : 0.0);
  const double ny = cy > 0 ? cy - 0.5 : (cy < 0 ? -cy - 0.5 : 0.0);
  if (nx * nx + ny * ny >= radius * radius) return 0;
  bool all = true;
  for (int32_t corner = 0; corner < 4 && all; ++corner) {
    all = shape.Contains(-(cx + ((corner & 1) ? 0.5 : -0.5)), -(cy + ((corner & 2) ? 0.5 : -0.5)),
                         radius);
  }
  if (all) return 256;  // the shape is convex: four corners inside cover the cell
  int32_t count = 0;
  for (int32_t sy = 0; sy < kSamples; ++sy) {
    const double y = cy - 0.5 + (sy + 0.5) / kSamples;
    for (int32_t sx = 0; sx < kSamples; ++sx) {
      const double x = cx - 0.5 + (sx + 0.5) / kSamples;
      count += shape.Contains(-x, -y, radius) ? 1 : 0;
    }
  }
  return count * 256 / (kSamples * kSamples);
}

}  // namespace

uint32_t BuildKernel(const ApertureShape& shape, float radius, int32_t half, KernelRow* rows) {
  for (int32_t i = 0; i <= 2 * half; ++i) rows[i] = KernelRow{};
  if (radius < 0.5f) {
    rows[half] = KernelRow{0, 0, 256, 0, 0};
    return 256;
  }
  uint32_t total = 0;
  int32_t cov[2 * 128 + 3];
  for (int32_t dy = -half; dy <= half; ++dy) {
    int32_t first = half + 1, last = -half - 1;
    for (int32_t dx = -half; dx <= half; ++dx) {
      cov[dx + half] = Coverage(shape, radius, dx, dy);
      if (cov[dx + half] > 0) {
        first = dx < first ? dx : first;
        last = dx;
      }
    }
    KernelRow& row = rows[dy + half];
    if (first > last) continue;  // an empty row
    row.left = static_cast<int16_t>(first + 1);
    row.right = static_cast<int16_t>(last - 1);
    row.wl = static_cast<int16_t>(cov[first + half]);
    row.wr = static_cast<int16_t>(first == last ? 0 : cov[last + half]);
    if (row.right < row.left) row.right = static_cast<int16_t>(row.left - 1);
    int32_t sum = 0;
    for (int32_t dx = row.left; dx <= row.right; ++dx) sum += cov[dx + half];
    const int32_t n = row.right - row.left + 1;
    row.w = static_cast<int16_t>(n > 0 ? (sum + n / 2) / n : 0);
    total += static_cast<uint32_t>(row.w * n + row.wl + row.wr);
  }
  return total;
}

}  // namespace lb
