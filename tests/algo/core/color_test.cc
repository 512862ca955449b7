#include "algo/core/color.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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
  RowToRgb8(PixelFormat::kYuyv, YuvRange::kLimited, yuyv, nullptr, nullptr, 2, rgb);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(rgb[k], 0);
    EXPECT_EQ(rgb[3 + k], 255);
  }
}

TEST(Color, Nv12AndBgrAndSixteenBit) {
  const uint8_t y[2] = {235, 16}, uv[2] = {128, 128};
  uint8_t rgb[6];
  RowToRgb8(PixelFormat::kNv12, YuvRange::kLimited, y, uv, nullptr, 2, rgb);
  EXPECT_EQ(rgb[0], 255);
  EXPECT_EQ(rgb[3], 0);
  const uint8_t bgr[3] = {1, 2, 3};
  RowToRgb8(PixelFormat::kBgr8, YuvRange::kLimited, bgr, nullptr, nullptr, 1, rgb);
  EXPECT_EQ(rgb[0], 3);
  EXPECT_EQ(rgb[2], 1);
  const uint16_t g16[2] = {65535, 32896};  // 32896 = 128.5 of 255 -> 128 or 129
  RowToRgb8(PixelFormat::kGray16, YuvRange::kLimited, reinterpret_cast<const uint8_t*>(g16),
            nullptr, nullptr, 2, rgb);
  EXPECT_EQ(rgb[0], 255);
  EXPECT_NEAR(rgb[3], 128, 1);
}

// BT.601 YUV to RGB in floating point, from the standard's definition (Kr, Kb, and the limited
// range's 219 and 224 steps): what the fixed-point rows must match within 1 LSB.
void ReferenceYuvToRgb(YuvRange range, int y, int u, int v, double rgb[3]) {
  const double kr = 0.299, kb = 0.114, kg = 1 - kr - kb;
  const bool full = range == YuvRange::kFull;
  const double yy = full ? y : (y - 16) * 255.0 / 219.0;
  const double pb = (u - 128) * (full ? 1.0 : 255.0 / 224.0);
  const double pr = (v - 128) * (full ? 1.0 : 255.0 / 224.0);
  rgb[0] = yy + 2 * (1 - kr) * pr;
  rgb[2] = yy + 2 * (1 - kb) * pb;
  rgb[1] = (yy - kr * rgb[0] - kb * rgb[2]) / kg;
  for (int k = 0; k < 3; ++k) rgb[k] = std::clamp(std::round(rgb[k]), 0.0, 255.0);
}

void ExpectNearReference(YuvRange range, int y, int u, int v, const uint8_t* got) {
  double want[3];
  ReferenceYuvToRgb(range, y, u, v, want);
  for (int k = 0; k < 3; ++k) {
    EXPECT_LE(std::abs(got[k] - want[k]), 1.0)
        << "Y " << y << " U " << u << " V " << v << " channel " << k << " full "
        << (range == YuvRange::kFull);
  }
}

// Colours from the corners of the gamut and in between, as YUV samples of either range.
constexpr uint8_t kSamples[][3] = {{16, 128, 128}, {235, 128, 128}, {81, 90, 240},   {145, 54, 34},
                                   {41, 240, 110}, {170, 166, 16},  {106, 202, 222}, {128, 60, 200},
                                   {0, 0, 0},      {255, 255, 255}, {200, 100, 180}, {60, 200, 70}};

// I420 rows: Y at full width, U and V at half width; pixel x takes chroma sample x / 2.
TEST(Color, I420MatchesTheFloatReferenceInBothRanges) {
  constexpr int kN = sizeof(kSamples) / sizeof(kSamples[0]);
  uint8_t y[2 * kN], u[kN], v[kN], rgb[6 * kN];
  for (int i = 0; i < kN; ++i) {
    y[2 * i] = kSamples[i][0];
    y[2 * i + 1] = static_cast<uint8_t>(255 - kSamples[i][0]);
    u[i] = kSamples[i][1];
    v[i] = kSamples[i][2];
  }
  for (YuvRange range : {YuvRange::kLimited, YuvRange::kFull}) {
    RowToRgb8(PixelFormat::kI420, range, y, u, v, 2 * kN, rgb);
    for (int x = 0; x < 2 * kN; ++x)
      ExpectNearReference(range, y[x], u[x / 2], v[x / 2], rgb + 3 * x);
  }
}

// The packed and semi-planar YUV formats take the range too.
TEST(Color, YuyvAndNv12MatchTheFloatReferenceInBothRanges) {
  for (YuvRange range : {YuvRange::kLimited, YuvRange::kFull}) {
    for (const auto& s : kSamples) {
      const uint8_t yuyv[4] = {s[0], s[1], static_cast<uint8_t>(255 - s[0]), s[2]};
      const uint8_t y[2] = {yuyv[0], yuyv[2]}, uv[2] = {s[1], s[2]};
      uint8_t a[6], b[6];
      RowToRgb8(PixelFormat::kYuyv, range, yuyv, nullptr, nullptr, 2, a);
      RowToRgb8(PixelFormat::kNv12, range, y, uv, nullptr, 2, b);
      for (int x = 0; x < 2; ++x) {
        ExpectNearReference(range, y[x], s[1], s[2], a + 3 * x);
        ExpectNearReference(range, y[x], s[1], s[2], b + 3 * x);
      }
    }
  }
}

// libcamera's XRGB8888 is B, G, R, X in memory and XBGR8888 R, G, B, X (DRM names a
// little-endian word): the unused byte never reaches the colour.
TEST(Color, ThirtyTwoBitRgbDropsTheUnusedByte) {
  const uint8_t bgrx[8] = {30, 120, 200, 0xAA, 255, 0, 7, 0x55};
  const uint8_t rgbx[8] = {200, 120, 30, 0x55, 7, 0, 255, 0xAA};
  const uint8_t want[6] = {200, 120, 30, 7, 0, 255};
  uint8_t rgb[6];
  RowToRgb8(PixelFormat::kBgrx8, YuvRange::kLimited, bgrx, nullptr, nullptr, 2, rgb);
  for (int k = 0; k < 6; ++k) EXPECT_EQ(rgb[k], want[k]) << k;
  RowToRgb8(PixelFormat::kRgbx8, YuvRange::kFull, rgbx, nullptr, nullptr, 2, rgb);
  for (int k = 0; k < 6; ++k) EXPECT_EQ(rgb[k], want[k]) << k;
  EXPECT_EQ(BytesPerPixel(PixelFormat::kBgrx8), 4);
  EXPECT_EQ(BytesPerPixel(PixelFormat::kI420), 1);
  EXPECT_EQ(PlaneCount(PixelFormat::kI420), 3);
  EXPECT_EQ(PlaneCount(PixelFormat::kNv12), 2);
  EXPECT_EQ(PlaneCount(PixelFormat::kRgbx8), 1);
}

}  // namespace
}  // namespace lb
