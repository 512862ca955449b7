// The depth image of a refocusable JPEG as other writers store it: every PNG colour type with
// equal channels (Google Camera's Lens Blur writes 8-bit RGBA), 8 and 16 bit, and JPEG, all read
// as the same depth; a colour image is refused naming the file.
#include "firmware/refocusable/depth_image.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "firmware/refocusable/refocusable_reader.h"
#include "tests/firmware/codecs/test_images.h"
#include "tests/firmware/refocusable/refocusable_test_util.h"

namespace lb {
namespace {

using test::Bytes;
using test::RefocusSample;

// PNG colour types (the PNG specification's numbers) and their channels.
enum ColourType { kGrey = 0, kRgb = 2, kGreyAlpha = 4, kRgba = 6 };

int Channels(int type) { return type == kGrey ? 1 : type == kGreyAlpha ? 2 : type == kRgb ? 3 : 4; }

// The grey values as a PNG of `type`: grey repeated in every colour channel, alpha opaque.
Bytes DepthPng(const GrayPng& grey, int type, int bits) {
  test::PngSpec spec;
  spec.width = grey.width;
  spec.height = grey.height;
  spec.color_type = type;
  spec.bit_depth = bits;
  const int channels = Channels(type);
  const bool alpha = type == kGreyAlpha || type == kRgba;
  for (size_t i = 0; i < grey.values.size(); ++i) {
    for (int c = 0; c < channels; ++c) {
      const uint16_t v = alpha && c == channels - 1 ? (bits == 16 ? 65535 : 255) : grey.values[i];
      if (bits == 16) spec.rows.push_back(static_cast<uint8_t>(v >> 8));
      spec.rows.push_back(static_cast<uint8_t>(v));
    }
  }
  Bytes png;
  EXPECT_TRUE(test::EncodePng(spec, &png));
  return png;
}

// The sample photo with `image` as its depth image.
std::vector<uint8_t> WithDepth(RefocusSample s, const Bytes& image, const char* mime) {
  s.xmp.depth.data = image;
  s.xmp.depth.mime = mime;
  std::vector<JpegSegment> segments;
  EXPECT_TRUE(BuildXmpSegments(s.xmp, &segments).ok());
  return test::WriteRefocusJpeg(s, segments);
}

Status Read(const std::vector<uint8_t>& jpeg, RefocusableImage* out) {
  return ReadRefocusable(jpeg.data(), jpeg.size(), "phone.jpg", out);
}

struct Variant {
  int type;
  int bits;
};

class ColourTypes : public ::testing::TestWithParam<Variant> {};

// What a user checks: the same photo with its depth stored in another colour type refocuses on
// the same depth.
TEST_P(ColourTypes, GiveTheSameDepthAsGrey) {
  const Variant v = GetParam();
  const RefocusSample s = test::MakeRefocusSample(false, v.bits);
  RefocusableImage grey;
  ASSERT_TRUE(Read(test::WriteRefocusJpeg(s, s.segments), &grey).ok());
  std::vector<uint16_t> want;
  DisparityRange want_range;
  ASSERT_TRUE(DisparityFromDepth(grey, &want, &want_range).ok());

  RefocusableImage r;
  const Status status = Read(WithDepth(s, DepthPng(grey.depth, v.type, v.bits), "image/png"), &r);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(r.depth.bits, v.bits);
  EXPECT_EQ(r.depth.values, grey.depth.values);
  std::vector<uint16_t> got;
  DisparityRange range;
  ASSERT_TRUE(DisparityFromDepth(r, &got, &range).ok());
  EXPECT_EQ(got, want);
}

INSTANTIATE_TEST_SUITE_P(DepthImage, ColourTypes,
                         ::testing::Values(Variant{kGrey, 8}, Variant{kGrey, 16},
                                           Variant{kGreyAlpha, 8}, Variant{kGreyAlpha, 16},
                                           Variant{kRgb, 8}, Variant{kRgb, 16}, Variant{kRgba, 8},
                                           Variant{kRgba, 16}));

TEST(DepthImage, ColourWhoseChannelsDifferIsRefusedNamingTheFile) {
  const RefocusSample s = test::MakeRefocusSample(false, 8);
  RefocusableImage grey;
  ASSERT_TRUE(Read(test::WriteRefocusJpeg(s, s.segments), &grey).ok());
  for (const int type : {kRgb, kRgba}) {
    const GrayPng& shifted = grey.depth;
    test::PngSpec spec;
    spec.width = shifted.width;
    spec.height = shifted.height;
    spec.color_type = type;
    spec.bit_depth = 8;
    for (size_t i = 0; i < shifted.values.size(); ++i) {
      for (int c = 0; c < Channels(type); ++c) {
        // One pixel's green differs from its red and blue: no channel can be the depth.
        const int bump = i == 37 && c == 1 ? 40 : 0;
        spec.rows.push_back(static_cast<uint8_t>(c == 3 ? 255 : (shifted.values[i] + bump) % 256));
      }
    }
    Bytes png;
    ASSERT_TRUE(test::EncodePng(spec, &png));
    RefocusableImage r;
    const Status status = Read(WithDepth(s, png, "image/png"), &r);
    ASSERT_FALSE(status.ok());
    const std::string message = status.message();
    EXPECT_EQ(message.rfind("phone.jpg: GDepth:Data: ", 0), 0u) << message;
    EXPECT_NE(message.find("R, G and B differ"), std::string::npos) << message;
    EXPECT_TRUE(r.depth.values.empty());
  }
}

TEST(DepthImage, JpegDepthIsRead) {
  const RefocusSample s = test::MakeRefocusSample(false, 8);
  RefocusableImage grey;
  ASSERT_TRUE(Read(test::WriteRefocusJpeg(s, s.segments), &grey).ok());
  std::vector<uint8_t> pixels, rgb;
  for (const uint16_t v : grey.depth.values) {
    pixels.push_back(static_cast<uint8_t>(v));
    rgb.insert(rgb.end(), 3, static_cast<uint8_t>(v));
  }
  for (const int components : {1, 3}) {
    Bytes jpg;
    ASSERT_TRUE(test::EncodeJpeg(grey.depth.width, grey.depth.height, components,
                                 components == 1 ? pixels.data() : rgb.data(), 95, false, &jpg));
    RefocusableImage r;
    const Status status = Read(WithDepth(s, jpg, "image/jpeg"), &r);
    ASSERT_TRUE(status.ok()) << components << " components: " << status.message();
    EXPECT_EQ(r.xmp.depth.mime, "image/jpeg");
    ASSERT_EQ(r.depth.values.size(), grey.depth.values.size());
    int worst = 0;
    for (size_t i = 0; i < r.depth.values.size(); ++i) {
      worst = std::max(worst, std::abs(r.depth.values[i] - grey.depth.values[i]));
    }
    EXPECT_LE(worst, 8) << "JPEG is lossy, but a smooth depth survives it";
  }
  // A colour photo is not a depth map, however it is stored.
  std::vector<uint8_t> colour(rgb.size());
  for (size_t i = 0; i < colour.size(); ++i) colour[i] = static_cast<uint8_t>(i % 3 * 100);
  Bytes jpg;
  ASSERT_TRUE(
      test::EncodeJpeg(grey.depth.width, grey.depth.height, 3, colour.data(), 95, false, &jpg));
  RefocusableImage r;
  const Status status = Read(WithDepth(s, jpg, "image/jpeg"), &r);
  EXPECT_NE(std::string(status.message()).find("R, G and B differ"), std::string::npos)
      << status.message();
}

TEST(DepthImage, HeaderSaysWhatTheFileStores) {
  GrayPng grey;
  grey.width = 5;
  grey.height = 3;
  grey.values.assign(15, 100);
  DepthImageHeader h;
  const Bytes rgba = DepthPng(grey, kRgba, 8);
  ASSERT_TRUE(ProbeDepthImage(rgba.data(), rgba.size(), "image/png", "d", &h).ok());
  EXPECT_EQ(h.width, 5);
  EXPECT_EQ(h.height, 3);
  EXPECT_EQ(h.bits, 8);
  EXPECT_STREQ(h.colour, "RGBA");
  const Bytes grey16 = DepthPng(grey, kGrey, 16);
  ASSERT_TRUE(ProbeDepthImage(grey16.data(), grey16.size(), "image/png", "d", &h).ok());
  EXPECT_EQ(h.bits, 16);
  EXPECT_STREQ(h.colour, "grey");
  EXPECT_FALSE(ProbeDepthImage(grey16.data(), grey16.size(), "image/gif", "d", &h).ok());
}

TEST(DepthImage, ASmallerMapIsResampledKeepingItsValues) {
  // Two flat halves, near on the left and far on the right, scaled 3x.
  std::vector<uint16_t> in(4 * 2);
  for (int32_t i = 0; i < 8; ++i) in[i] = i % 4 < 2 ? 4000 : 1000;
  std::vector<uint16_t> out(12 * 6);
  ResampleDisparity(MakeView<const uint16_t>(in.data(), 4, 2), MakeView(out.data(), 12, 6));
  for (int32_t y = 0; y < 6; ++y) {
    EXPECT_EQ(out[y * 12 + 0], 4000);  // the flat parts stay flat
    EXPECT_EQ(out[y * 12 + 11], 1000);
    for (int32_t x = 1; x < 12; ++x) EXPECT_LE(out[y * 12 + x], out[y * 12 + x - 1]);
  }
}

TEST(DepthImage, ScaledDisparityIsInTheFilesOwnUnits) {
  const RefocusSample s = test::MakeRefocusSample(false, 16);
  RefocusableImage r;
  ASSERT_TRUE(Read(test::WriteRefocusJpeg(s, s.segments), &r).ok());
  std::vector<uint16_t> one, three;
  DisparityRange range_one, range_three;
  ASSERT_TRUE(ScaledDisparityFromDepth(r, 1.0, &one, &range_one).ok());
  EXPECT_EQ(one, s.disp_q8);  // the product's own units: exactly what was written
  ASSERT_TRUE(ScaledDisparityFromDepth(r, 3.0, &three, &range_three).ok());
  ASSERT_EQ(three.size(), one.size());
  for (size_t i = 0; i < one.size(); ++i) EXPECT_NEAR(three[i], 3 * one[i], 2) << i;
  EXPECT_NEAR(range_three.max_q8, 3 * range_one.max_q8, 2);
}

TEST(DepthImage, PhoneFocusAndNoOriginalAreRead) {
  RefocusSample s = test::MakeRefocusSample(false, 8);
  s.xmp.image.clear();  // no GImage
  s.xmp.focus = {0.013350779, 16.577824, 0.5208333, 0.58125};
  std::vector<JpegSegment> segments;
  ASSERT_TRUE(BuildXmpSegments(s.xmp, &segments).ok());
  RefocusableImage r;
  const Status status = Read(test::WriteRefocusJpeg(s, segments), &r);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_TRUE(r.xmp.image.empty());
  ASSERT_TRUE(r.xmp.has_focus);
  EXPECT_DOUBLE_EQ(r.xmp.focus.blur_at_infinity, 0.013350779);
  EXPECT_DOUBLE_EQ(r.xmp.focus.focal_distance, 16.577824);
  EXPECT_DOUBLE_EQ(r.xmp.focus.focal_point_x, 0.5208333);
  EXPECT_DOUBLE_EQ(r.xmp.focus.focal_point_y, 0.58125);
}

}  // namespace
}  // namespace lb
