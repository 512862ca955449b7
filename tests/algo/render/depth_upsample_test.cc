#include "algo/render/depth_upsample.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <vector>

namespace lb {
namespace {

// A dark red region (disparity 2) left of column 29 and above row 21, bright green (disparity 6)
// elsewhere; both textured. The depth edge falls inside working pixels (scale 4), so copying
// the nearest working value puts a column and a row of pixels on the wrong side.
TEST(DepthUpsample, DepthEdgesFollowImageEdges) {
  const int32_t w = 64, h = 48, s = 4, ww = w / s, wh = h / s;
  const int32_t cw = w / 2, ch = h / 2;
  std::vector<uint8_t> y(w * h), cb(cw * ch), cr(cw * ch);
  auto near_side = [](int32_t x, int32_t yy) { return x >= 29 || yy >= 21; };
  for (int32_t j = 0; j < h; ++j) {
    for (int32_t i = 0; i < w; ++i)
      y[j * w + i] = (near_side(i, j) ? 150 : 60) + (i * 7 + j * 3) % 11;
  }
  for (int32_t j = 0; j < ch; ++j) {
    for (int32_t i = 0; i < cw; ++i) {
      const bool n = near_side(2 * i, 2 * j) && near_side(2 * i + 1, 2 * j + 1);
      cb[j * cw + i] = n ? 80 : 110;
      cr[j * cw + i] = n ? 90 : 190;
    }
  }
  std::vector<uint16_t> disp(ww * wh);
  for (int32_t j = 0; j < wh; ++j) {
    for (int32_t i = 0; i < ww; ++i)
      disp[j * ww + i] = near_side(i * s + 2, j * s + 2) ? 6 << 8 : 2 << 8;
  }
  ConstPlanarU8 ref;
  ref.count = 3;
  ref.planes[0] = MakeView(y.data(), w, h).AsConst();
  ref.planes[1] = MakeView(cb.data(), cw, ch).AsConst();
  ref.planes[2] = MakeView(cr.data(), cw, ch).AsConst();

  Arena plan;
  DepthUpsampler up;
  up.Carve(plan, w, h, s, ww, wh);
  std::vector<uint8_t> block(plan.used() + 64);
  Arena arena(block.data() + (64 - reinterpret_cast<uintptr_t>(block.data()) % 64), plan.used());
  up.Carve(arena, w, h, s, ww, wh);
  ASSERT_FALSE(arena.overflowed());
  up.Begin(ref, MakeView(disp.data(), ww, wh).AsConst());

  int32_t wrong = 0, wrong_nearest = 0;
  std::vector<uint16_t> row(w);
  for (int32_t j = 0; j < h; ++j) {
    up.Row(j, row.data());
    for (int32_t i = 0; i < w; ++i) {
      const int32_t truth = near_side(i, j) ? 6 << 8 : 2 << 8;
      wrong += std::abs(row[i] - truth) > 128;
      wrong_nearest += std::abs(disp[(j / s) * ww + i / s] - truth) > 128;
      if (std::abs(i - 29) > 4 && std::abs(j - 21) > 4) {
        EXPECT_EQ(row[i], truth) << i << "," << j;
      }
    }
  }
  EXPECT_GT(wrong_nearest, 40);
  EXPECT_LE(wrong * 10, wrong_nearest) << wrong << " vs " << wrong_nearest;
}

}  // namespace
}  // namespace lb
