#include "algo/core/color.h"

#include <gtest/gtest.h>

#include <cstdlib>

namespace lb {
namespace {

TEST(Color, GreyRoundTripsThroughYCbCr) {
  for (int v = 0; v < 256; v += 17) {
    const uint8_t rgb[3] = {static_cast<uint8_t>(v), static_cast<uint8_t>(v),
                            static_cast<uint8_t>(v)};
    uint8_t y, cb, cr;
    RowRgb8ToY(rgb, 1, &y);
    RowsRgb8ToCbCr420(rgb, rgb, 1, &cb, &cr);
    EXPECT_EQ(y, v);
    EXPECT_EQ(cb, 128);
    EXPECT_EQ(cr, 128);
  }
}

TEST(Color, SaturatedColoursRoundTripWithinTwoLevels) {
  const uint8_t colours[][3] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {200, 120, 30}};
  for (const auto& c : colours) {
    uint8_t y, cb, cr, back[3];
    RowRgb8ToY(c, 1, &y);
    RowsRgb8ToCbCr420(c, c, 1, &cb, &cr);
    YCbCrToRgb8(y, cb, cr, back);
    for (int k = 0; k < 3; ++k) EXPECT_LE(std::abs(back[k] - c[k]), 2) << k;
  }
}

TEST(Color, YuyvLimitedRangeMapsToFullRange) {
  const uint8_t yuyv[4] = {16, 128, 235, 128};  // black then white, no chroma
  uint8_t rgb[6];
  RowToRgb8(PixelFormat::kYuyv, yuyv, nullptr, 2, rgb);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(rgb[k], 0);
    EXPECT_EQ(rgb[3 + k], 255);
  }
}

TEST(Color, Nv12AndBgrAndSixteenBit) {
  const uint8_t y[2] = {235, 16}, uv[2] = {128, 128};
  uint8_t rgb[6];
  RowToRgb8(PixelFormat::kNv12, y, uv, 2, rgb);
  EXPECT_EQ(rgb[0], 255);
  EXPECT_EQ(rgb[3], 0);
  const uint8_t bgr[3] = {1, 2, 3};
  RowToRgb8(PixelFormat::kBgr8, bgr, nullptr, 1, rgb);
  EXPECT_EQ(rgb[0], 3);
  EXPECT_EQ(rgb[2], 1);
  const uint16_t g16[2] = {65535, 32896};  // 32896 = 128.5 of 255 -> 128 or 129
  RowToRgb8(PixelFormat::kGray16, reinterpret_cast<const uint8_t*>(g16), nullptr, 2, rgb);
  EXPECT_EQ(rgb[0], 255);
  EXPECT_NEAR(rgb[3], 128, 1);
}

}  // namespace
}  // namespace lb
