#include "algo/render/aperture.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "algo/render/render_stage.h"

namespace lb {
namespace {

struct Built {
  int32_t half = 0;
  std::vector<KernelRow> rows;
  uint32_t total = 0;
  // Q8 weight of cell (dx, dy) as the gather applies it.
  int32_t At(int32_t dx, int32_t dy) const {
    if (dy < -half || dy > half) return 0;
    const KernelRow& r = rows[dy + half];
    if (dx >= r.left && dx <= r.right) return r.w;
    if (dx == r.left - 1) return r.wl;
    if (dx == r.right + 1) return r.wr;
    return 0;
  }
};

Built Build(const Aperture& a, float radius) {
  Built b;
  b.half = KernelHalf(radius);
  b.rows.resize(2 * b.half + 1);
  b.total = BuildKernel(ApertureShape(a), radius, b.half, b.rows.data());
  return b;
}

TEST(Aperture, SmallRadiusIsTheIdentity) {
  const Built b = Build(Aperture{}, 0.25f);
  EXPECT_EQ(b.half, 0);
  EXPECT_EQ(b.total, 256u);
  EXPECT_EQ(b.At(0, 0), 256);
}

TEST(Aperture, DiscAreaAndSymmetry) {
  for (float r : {1.0f, 2.5f, 7.0f, 16.0f, 32.0f}) {
    const Built b = Build(Aperture{}, r);
    const double area = b.total / 256.0;
    EXPECT_NEAR(area, M_PI * r * r, 0.02 * M_PI * r * r + 0.5) << r;
    uint32_t sum = 0;
    for (int32_t dy = -b.half; dy <= b.half; ++dy) {
      for (int32_t dx = -b.half; dx <= b.half; ++dx) {
        sum += b.At(dx, dy);
        // Row spans approximate coverage: mirror cells agree within the row-mean rounding.
        EXPECT_NEAR(b.At(dx, dy), b.At(-dx, dy), 40) << r << " " << dx << "," << dy;
        EXPECT_EQ(b.At(dx, dy), b.At(dx, -dy)) << r;
      }
    }
    EXPECT_EQ(sum, b.total);
    EXPECT_EQ(b.At(0, 0), 256);
    EXPECT_EQ(b.At(b.half + 1, 0), 0);
  }
}

TEST(Aperture, HexagonHasAPolygonsAreaAndCurvatureRoundsIt) {
  Aperture hex{6, 0.0f, 0.0f};
  const float r = 20.0f;
  const double hex_area = 1.5 * std::sqrt(3.0) * r * r;  // circumradius r
  EXPECT_NEAR(Build(hex, r).total / 256.0, hex_area, 0.02 * hex_area);
  hex.curvature = 1.0f;
  EXPECT_NEAR(Build(hex, r).total / 256.0, M_PI * r * r, 0.02 * M_PI * r * r);
  hex.curvature = 0.5f;
  const double half_way = Build(hex, r).total / 256.0;
  EXPECT_GT(half_way, hex_area * 1.02);
  EXPECT_LT(half_way, M_PI * r * r * 0.98);
}

TEST(Aperture, TriangleIsReflectedForTheGatherAndRotates) {
  // A triangle with a flat edge facing +x has a vertex at -x; the gather kernel is the point
  // reflection, so its vertex points +x: far cells on +x are covered, on -x they are not.
  const Aperture tri{3, 0.0f, 0.0f};
  const Built b = Build(tri, 12.0f);
  EXPECT_GT(b.At(10, 0), 128);
  EXPECT_EQ(b.At(-10, 0), 0);
  const Aperture turned{3, 180.0f, 0.0f};
  const Built t = Build(turned, 12.0f);
  EXPECT_EQ(t.At(10, 0), 0);
  EXPECT_GT(t.At(-10, 0), 128);
}

}  // namespace
}  // namespace lb
