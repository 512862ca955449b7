#include "algo/render/lens_model.h"

#include <gtest/gtest.h>

#include <vector>

namespace lb {
namespace {

TEST(LensModel, RadiusIsLinearInDisparityDistanceAndScalesWithAperture) {
  LensModel lens;
  lens.Set(2.8f, 4, 128, 5 << 8);
  // 0.5 * 4 view steps * (2.8 / 2.8) * scale 4 = 8 px of radius per px of disparity.
  EXPECT_EQ(lens.SignedRadiusQ4(5 << 8), 0);
  EXPECT_EQ(lens.SignedRadiusQ4(6 << 8), 8 * 16);
  EXPECT_EQ(lens.SignedRadiusQ4(7 << 8), 16 * 16);
  EXPECT_EQ(lens.SignedRadiusQ4(4 << 8), -8 * 16);    // farther than the focus: negative
  EXPECT_EQ(lens.SignedRadiusQ4((5 << 8) + 32), 16);  // 1/8 px of disparity: 1 px
  EXPECT_FLOAT_EQ(lens.radius_per_disp(), 8.0f);
  lens.Set(5.6f, 4, 128, 5 << 8);  // one stop... two stops down: half the aperture
  EXPECT_EQ(lens.SignedRadiusQ4(7 << 8), 8 * 16);
  lens.Set(1.4f, 4, 128, 5 << 8);
  EXPECT_EQ(lens.SignedRadiusQ4(6 << 8), 16 * 16);
}

TEST(LensModel, RadiusIsCappedAtTheLargestRadius) {
  LensModel lens;
  lens.Set(1.4f, 8, 32, 0);
  EXPECT_EQ(lens.SignedRadiusQ4(65535), 32 * 16);
  lens.Set(1.4f, 8, 32, 65535);
  EXPECT_EQ(lens.SignedRadiusQ4(0), -32 * 16);
}

std::vector<uint16_t> Fill(int32_t w, int32_t h, uint16_t v) {
  return std::vector<uint16_t>(static_cast<size_t>(w) * h, v);
}

TEST(FocusDisparity, MedianOfTheRegionIgnoresOutliers) {
  const int32_t w = 40, h = 30;
  std::vector<uint16_t> d = Fill(w, h, 100);
  // Region x 10..19, y 10..19 at scale 1: 70 % at 1000, 30 % wild values.
  for (int32_t y = 10; y < 20; ++y) {
    for (int32_t x = 10; x < 20; ++x) d[y * w + x] = x < 17 ? 1000 : (x == 17 ? 0 : 60000);
  }
  uint32_t hist[256];
  EXPECT_EQ(FocusDisparityQ8(MakeView(d.data(), w, h).AsConst(), 1, 10, 10, 10, 10, hist), 1000);
  // The same region named in full-resolution pixels at scale 4.
  EXPECT_EQ(FocusDisparityQ8(MakeView(d.data(), w, h).AsConst(), 4, 40, 40, 40, 40, hist), 1000);
}

TEST(FocusDisparity, ExactMedianAcrossHistogramBins) {
  const int32_t w = 9, h = 1 + 2;
  std::vector<uint16_t> d(static_cast<size_t>(w) * h);
  for (int32_t i = 0; i < w * h; ++i) d[i] = static_cast<uint16_t>(i * 301);  // crosses bins
  uint32_t hist[256];
  // Whole image: 27 values, median is the 14th = 13 * 301.
  EXPECT_EQ(FocusDisparityQ8(MakeView(d.data(), w, h).AsConst(), 1, 0, 0, w, h, hist), 13 * 301);
}

TEST(FocusDisparity, DefaultRegionIsTheCentreAndAPointIsGrown) {
  const int32_t w = 30, h = 30;
  std::vector<uint16_t> d = Fill(w, h, 50);
  for (int32_t y = 10; y < 20; ++y) {
    for (int32_t x = 10; x < 20; ++x) d[y * w + x] = 777;
  }
  d[5 * w + 25] = 999;  // a single odd pixel under the tapped point
  uint32_t hist[256];
  const ConstImageU16 view = MakeView(d.data(), w, h).AsConst();
  EXPECT_EQ(FocusDisparityQ8(view, 1, 0, 0, 0, 0, hist), 777);
  EXPECT_EQ(FocusDisparityQ8(view, 1, 25, 5, 1, 1, hist), 50);    // 3x3 around it: 8 of 9 are 50
  EXPECT_EQ(FocusDisparityQ8(view, 1, 100, -7, 1, 1, hist), 50);  // off the image: clamped
}

}  // namespace
}  // namespace lb
