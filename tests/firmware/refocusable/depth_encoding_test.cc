#include "firmware/refocusable/depth_encoding.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace lb {
namespace {

TEST(DepthEncodingTest, SixteenBitsGiveEveryDisparityBack) {
  for (const DisparityRange range : {DisparityRange{0, 16 << 8}, DisparityRange{300, 4000},
                                     DisparityRange{1, 65535}, DisparityRange{0, 2}}) {
    const int32_t lo = range.min_q8 > 0 ? range.min_q8 : 1;
    for (int32_t d = lo; d <= range.max_q8; ++d) {
      ASSERT_EQ(DecodeRangeInverse(EncodeRangeInverse(d, range, 16), range, 16), d)
          << "range " << range.min_q8 << ".." << range.max_q8;
    }
  }
}

TEST(DepthEncodingTest, NearIsZeroFarIsFullScaleAndOutsideClamps) {
  const DisparityRange range{256, 4096};
  EXPECT_EQ(EncodeRangeInverse(4096, range, 16), 0);
  EXPECT_EQ(EncodeRangeInverse(256, range, 16), 65535);
  EXPECT_EQ(EncodeRangeInverse(256, range, 8), 255);
  EXPECT_EQ(EncodeRangeInverse(9000, range, 16), 0);
  EXPECT_EQ(EncodeRangeInverse(0, range, 8), 255);
  EXPECT_EQ(DecodeRangeInverse(0, range, 8), 4096);
  EXPECT_EQ(DecodeRangeInverse(255, range, 8), 256);
}

// The integer encoding is the format's RangeInverse formula on depth = 1 / disparity.
TEST(DepthEncodingTest, AgreesWithTheFormatsFormulas) {
  const DisparityRange range{128, 5000};
  double near_depth, far_depth;
  ASSERT_TRUE(DepthNearFar(range, &near_depth, &far_depth).ok());
  for (int bits : {8, 16}) {
    const double top = bits == 8 ? 255.0 : 65535.0;
    for (int32_t d = range.min_q8; d <= range.max_q8; d += 7) {
      const double depth = 256.0 / d;
      const double dn = (far_depth - near_depth * far_depth / depth) / (far_depth - near_depth);
      const uint16_t v = EncodeRangeInverse(d, range, bits);
      EXPECT_NEAR(v, dn * top, 0.5 + 1e-6) << d;
      // Decoding: depth = far * near / (far - dn * (far - near)).
      const double dn_back = v / top;
      const double depth_back =
          far_depth * near_depth / (far_depth - dn_back * (far_depth - near_depth));
      EXPECT_NEAR(DecodeRangeInverse(v, range, bits), 256.0 / depth_back, 0.5 + 1e-6);
    }
  }
}

TEST(DepthEncodingTest, EightBitsAreMonotonicWithinHalfAStep) {
  const DisparityRange range{0, 16 << 8};
  const double step = (range.max_q8 - 1) / 255.0;
  uint16_t last = 255;
  for (int32_t d = 1; d <= range.max_q8; ++d) {
    const uint16_t v = EncodeRangeInverse(d, range, 8);
    EXPECT_LE(v, last);
    last = v;
    EXPECT_LE(std::abs(DecodeRangeInverse(v, range, 8) - d), step / 2 + 1);
  }
}

TEST(DepthEncodingTest, NearFarSurviveTheXmpTextAndComeBack) {
  for (const DisparityRange range : {DisparityRange{0, 4096}, DisparityRange{77, 12345}}) {
    double near_depth, far_depth;
    ASSERT_TRUE(DepthNearFar(range, &near_depth, &far_depth).ok());
    char text[2][40];
    snprintf(text[0], sizeof(text[0]), "%.9g", near_depth);
    snprintf(text[1], sizeof(text[1]), "%.9g", far_depth);
    DisparityRange back;
    ASSERT_TRUE(DisparityRangeFromNearFar(atof(text[0]), atof(text[1]), &back).ok());
    EXPECT_EQ(back.max_q8, range.max_q8);
    EXPECT_EQ(back.min_q8, range.min_q8);  // a range reaching infinity reads back as 0
  }
}

TEST(DepthEncodingTest, FocalDepthUsesTheSameUnitsAsNearAndFar) {
  double near_depth, far_depth;
  ASSERT_TRUE(DepthNearFar({64, 2048}, &near_depth, &far_depth).ok());
  EXPECT_DOUBLE_EQ(DepthForDisparity(2048), near_depth);
  EXPECT_DOUBLE_EQ(DepthForDisparity(64), far_depth);
  EXPECT_DOUBLE_EQ(DepthForDisparity(512), 0.5);  // 2 px per view step
  EXPECT_DOUBLE_EQ(DepthForDisparity(0), 256.0);
}

TEST(DepthEncodingTest, BadRangesAndMapsAreRejected) {
  double n, f;
  EXPECT_FALSE(DepthNearFar({10, 10}, &n, &f).ok());
  EXPECT_FALSE(DepthNearFar({-1, 10}, &n, &f).ok());
  EXPECT_FALSE(DepthNearFar({5, 2}, &n, &f).ok());
  DisparityRange r;
  EXPECT_FALSE(DisparityRangeFromNearFar(2.0, 1.0, &r).ok());
  EXPECT_FALSE(DisparityRangeFromNearFar(0.0, 1.0, &r).ok());
  EXPECT_FALSE(DisparityRangeFromNearFar(1.0, INFINITY, &r).ok());
  EXPECT_FALSE(DisparityRangeFromNearFar(NAN, 1.0, &r).ok());
  std::vector<uint16_t> a(12), b(12);
  EXPECT_FALSE(
      EncodeDepthMap(MakeView(a.data(), 4, 3), {0, 256}, 12, MakeView(b.data(), 4, 3)).ok());
  EXPECT_FALSE(
      EncodeDepthMap(MakeView(a.data(), 4, 3), {0, 256}, 8, MakeView(b.data(), 3, 4)).ok());
  EXPECT_TRUE(EncodeDepthMap(MakeView(a.data(), 4, 3), {0, 256}, 8, MakeView(b.data(), 4, 3)).ok());
}

TEST(DepthEncodingTest, MapsRoundTripThroughStridedViews) {
  const int32_t w = 5, h = 3, stride = 8;
  std::vector<uint16_t> disp(stride * h, 0xDEAD), values(stride * h), back(stride * h, 0);
  for (int32_t y = 0; y < h; ++y) {
    for (int32_t x = 0; x < w; ++x)
      disp[y * stride + x] = static_cast<uint16_t>(100 + 37 * (x + w * y));
  }
  const DisparityRange range{64, 1024};
  ImageU16 dv{disp.data(), w, h, 1, stride}, vv{values.data(), w, h, 1, stride},
      bv{back.data(), w, h, 1, stride};
  ASSERT_TRUE(EncodeDepthMap(dv, range, 16, vv).ok());
  ASSERT_TRUE(DecodeDepthMap(vv, range, 16, bv).ok());
  for (int32_t y = 0; y < h; ++y) {
    for (int32_t x = 0; x < w; ++x) EXPECT_EQ(back[y * stride + x], disp[y * stride + x]);
    EXPECT_EQ(back[y * stride + w], 0);  // padding untouched
  }
}

}  // namespace
}  // namespace lb
