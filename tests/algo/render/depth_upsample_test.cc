#include "algo/render/depth_upsample.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <vector>

namespace lb {
namespace {

// A dark red region (disparity 2) left of column 29 and above row 21, bright green (disparity 6)
// elsewhere; both textured. The depth edge falls inside working pixels (scale 4), so copying
// the nearest working value puts a column and a row of pixels on the wrong side.
struct EdgeScene {
  static constexpr int32_t w = 64, h = 48, s = 4, ww = w / s, wh = h / s, cw = w / 2, ch = h / 2;
  static bool NearSide(int32_t x, int32_t y) { return x >= 29 || y >= 21; }
  static int32_t Truth(int32_t x, int32_t y) { return NearSide(x, y) ? 6 << 8 : 2 << 8; }
  std::vector<uint8_t> y = std::vector<uint8_t>(w * h), cb = std::vector<uint8_t>(cw * ch),
                       cr = std::vector<uint8_t>(cw * ch);
  std::vector<uint16_t> disp = std::vector<uint16_t>(ww * wh);
  std::vector<uint8_t> block;
  DepthUpsampler up;

  EdgeScene() {
    for (int32_t j = 0; j < h; ++j) {
      for (int32_t i = 0; i < w; ++i)
        y[j * w + i] = static_cast<uint8_t>((NearSide(i, j) ? 150 : 60) + (i * 7 + j * 3) % 11);
    }
    for (int32_t j = 0; j < ch; ++j) {
      for (int32_t i = 0; i < cw; ++i) {
        const bool n = NearSide(2 * i, 2 * j) && NearSide(2 * i + 1, 2 * j + 1);
        cb[j * cw + i] = n ? 80 : 110;
        cr[j * cw + i] = n ? 90 : 190;
      }
    }
    for (int32_t j = 0; j < wh; ++j) {
      for (int32_t i = 0; i < ww; ++i)
        disp[j * ww + i] = static_cast<uint16_t>(Truth(i * s + 2, j * s + 2));
    }
    Arena plan;
    up.Carve(plan, w, h, s, ww, wh);
    block.resize(plan.used() + Arena::kAlign);
    Arena arena(Arena::AlignUp(block.data()), plan.used());
    up.Carve(arena, w, h, s, ww, wh);
  }
  void Begin(ConstImageU8 confidence = {}, bool one_side = false) {
    ConstPlanarU8 ref;
    ref.count = 3;
    ref.planes[0] = MakeView(y.data(), w, h).AsConst();
    ref.planes[1] = MakeView(cb.data(), cw, ch).AsConst();
    ref.planes[2] = MakeView(cr.data(), cw, ch).AsConst();
    up.Begin(ref, MakeView(disp.data(), ww, wh).AsConst(), confidence, one_side);
  }
  // Pixels off the truth by more than half a px.
  int32_t Wrong() {
    int32_t wrong = 0;
    std::vector<uint16_t> row(w);
    for (int32_t j = 0; j < h; ++j) {
      up.Row(j, row.data());
      for (int32_t i = 0; i < w; ++i) wrong += std::abs(row[i] - Truth(i, j)) > 128;
    }
    return wrong;
  }
};

TEST(DepthUpsample, DepthEdgesFollowImageEdges) {
  EdgeScene e;
  e.Begin();
  int32_t wrong_nearest = 0;
  std::vector<uint16_t> row(e.w);
  for (int32_t j = 0; j < e.h; ++j) {
    e.up.Row(j, row.data());
    for (int32_t i = 0; i < e.w; ++i) {
      wrong_nearest += std::abs(e.disp[(j / e.s) * e.ww + i / e.s] - e.Truth(i, j)) > 128;
      if (std::abs(i - 29) > 4 && std::abs(j - 21) > 4) {
        EXPECT_EQ(row[i], e.Truth(i, j)) << i << "," << j;
      }
    }
  }
  const int32_t wrong = e.Wrong();
  EXPECT_GT(wrong_nearest, 40);
  EXPECT_LE(wrong * 10, wrong_nearest) << wrong << " vs " << wrong_nearest;
}

// For a map that is kept: a pixel on the edge takes one side's depth, never one in between.
TEST(DepthUpsample, OneSideLeavesNoDepthBetweenTheSides) {
  EdgeScene e;
  e.Begin({}, /*one_side=*/true);
  std::vector<uint16_t> row(e.w);
  for (int32_t j = 0; j < e.h; ++j) {
    e.up.Row(j, row.data());
    for (int32_t i = 0; i < e.w; ++i)
      EXPECT_TRUE(row[i] == 2 << 8 || row[i] == 6 << 8) << i << "," << j << ": " << row[i];
  }
  const int32_t one_side = e.Wrong();
  e.Begin();
  EXPECT_LE(one_side, e.Wrong());
}

// A coarser grid's samples (every step-th column from phase) are the full row's, in both modes.
TEST(DepthUpsample, EveryStepthColumnIsTheFullRowsSample) {
  EdgeScene e;
  for (bool one_side : {false, true}) {
    e.Begin({}, one_side);
    std::vector<uint16_t> full(e.w), part(e.w);
    for (int32_t step : {2, 3, 4}) {
      for (int32_t phase = 0; phase < step; ++phase) {
        for (int32_t j = 0; j < e.h; ++j) {
          e.up.Row(j, full.data());
          e.up.Row(j, part.data(), 0, step, phase);
          for (int32_t k = 0; k * step + phase < e.w; ++k)
            ASSERT_EQ(part[k], full[k * step + phase]) << step << " " << phase << " " << k;
        }
      }
    }
  }
}

// On a depth edge the photo does not show (one colour both sides), neighbours the depth stage
// was unsure of count for less: with the near side's pixels unsure, the edge pixels lean to the
// far side's depth.
TEST(DepthUpsample, AnUnsureNeighbourWeighsLess) {
  EdgeScene e;
  std::fill(e.y.begin(), e.y.end(), 120);
  std::fill(e.cb.begin(), e.cb.end(), 128);
  std::fill(e.cr.begin(), e.cr.end(), 128);
  auto edge_sum = [&] {
    int64_t sum = 0;
    std::vector<uint16_t> row(e.w);
    for (int32_t j = 0; j < e.h; ++j) {
      e.up.Row(j, row.data());
      for (int32_t i = 24; i < 34; ++i) sum += row[i];
    }
    return sum;
  };
  e.Begin();
  const int64_t sure = edge_sum();
  std::vector<uint8_t> confidence(e.ww * e.wh);
  for (int32_t j = 0; j < e.wh; ++j) {
    for (int32_t i = 0; i < e.ww; ++i)
      confidence[j * e.ww + i] = e.NearSide(i * e.s + 2, j * e.s + 2) ? 0 : 255;
  }
  e.Begin(MakeView(confidence.data(), e.ww, e.wh).AsConst());
  EXPECT_LT(edge_sum(), sure);
}

}  // namespace
}  // namespace lb
