#include "firmware/codecs/png_reader.h"
#include "firmware/codecs/png_writer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "firmware/codecs/image_file.h"

namespace lb {
namespace {

std::vector<uint16_t> Ramp(int32_t w, int32_t h, int bits) {
  std::vector<uint16_t> v(static_cast<size_t>(w) * h);
  for (size_t i = 0; i < v.size(); ++i)
    v[i] = static_cast<uint16_t>((static_cast<uint32_t>(i) * 2654435761u) >> (32 - bits));
  return v;
}

TEST(PngMemoryTest, EightAndSixteenBitsRoundTripExactly) {
  for (int bits : {8, 16}) {
    const std::vector<uint16_t> v = Ramp(37, 21, bits);
    std::vector<uint8_t> png;
    ASSERT_TRUE(EncodeGrayPng(MakeView(v.data(), 37, 21), bits, &png).ok());
    EXPECT_EQ(png[24], bits);  // IHDR bit depth
    EXPECT_EQ(png[25], 0);     // colour type grey
    GrayPng out;
    Status status = DecodeGrayPng(png.data(), png.size(), "t", 100, 37, 21, &out);
    ASSERT_TRUE(status.ok()) << status.message();
    EXPECT_EQ(out.width, 37);
    EXPECT_EQ(out.height, 21);
    EXPECT_EQ(out.bits, bits);
    EXPECT_EQ(out.values, v);
  }
}

TEST(PngMemoryTest, DefectsAreReportedNotCrashed) {
  const std::vector<uint16_t> v = Ramp(20, 10, 16);
  std::vector<uint8_t> png;
  ASSERT_TRUE(EncodeGrayPng(MakeView(v.data(), 20, 10), 16, &png).ok());
  GrayPng out;
  Status wrong = DecodeGrayPng(png.data(), png.size(), "depth", 100, 21, 10, &out);
  EXPECT_FALSE(wrong.ok());
  EXPECT_NE(std::string(wrong.message()).find("20x10, expected 21x10"), std::string::npos)
      << wrong.message();
  EXPECT_FALSE(DecodeGrayPng(png.data(), png.size(), "depth", 16, 0, 0, &out).ok());  // too big
  EXPECT_FALSE(DecodeGrayPng(png.data(), 7, "depth", 100, 0, 0, &out).ok());
  for (size_t cut : {size_t{20}, size_t{40}, png.size() / 2, png.size() - 1}) {
    Status status = DecodeGrayPng(png.data(), cut, "depth", 100, 0, 0, &out);
    EXPECT_FALSE(status.ok()) << cut;
    EXPECT_EQ(std::string(status.message()).rfind("depth: ", 0), 0u) << status.message();
  }
  std::vector<uint8_t> flipped = png;
  flipped[flipped.size() / 2] ^= 0x55;  // inside the image data: CRC or zlib error
  EXPECT_FALSE(DecodeGrayPng(flipped.data(), flipped.size(), "depth", 100, 0, 0, &out).ok());
}

// Into the caller's memory: the same values as the vector door; an image larger than the
// memory is kOutOfMemory with nothing written past it.
TEST(PngMemoryTest, IntoFixedMemoryGivesTheSameValues) {
  for (int bits : {8, 16}) {
    const std::vector<uint16_t> v = Ramp(37, 21, bits);
    std::vector<uint8_t> png;
    ASSERT_TRUE(EncodeGrayPng(MakeView(v.data(), 37, 21), bits, &png).ok());
    std::vector<uint16_t> values(37 * 21 + 1, 0xBEEF);
    std::vector<uint8_t> strip(ImageStripBytes(37, PixelFormat::kGray16));
    GrayPngBuffer out;
    out.values = values.data();
    out.capacity = 37 * 21;
    out.strip = strip.data();
    out.strip_bytes = strip.size();
    Status status = DecodeGrayPngInto(png.data(), png.size(), "t", 100, 37, 21, &out);
    ASSERT_TRUE(status.ok()) << status.message();
    EXPECT_EQ(out.width, 37);
    EXPECT_EQ(out.height, 21);
    EXPECT_EQ(out.bits, bits);
    EXPECT_EQ(std::vector<uint16_t>(values.begin(), values.end() - 1), v);
    EXPECT_EQ(values.back(), 0xBEEF);

    std::fill(values.begin(), values.end(), 0xBEEF);
    out.capacity = 37 * 21 - 1;
    status = DecodeGrayPngInto(png.data(), png.size(), "t", 100, 0, 0, &out);
    EXPECT_EQ(status.code(), Code::kOutOfMemory) << status.message();
    EXPECT_EQ(out.width, 0);
    EXPECT_EQ(std::count(values.begin(), values.end(), 0xBEEF), 37 * 21 + 1);

    out.capacity = values.size();
    out.strip_bytes = strip.size() / 2;  // rows wider than the caller's strip
    status = DecodeGrayPngInto(png.data(), png.size(), "t", 100, 0, 0, &out);
    EXPECT_EQ(status.code(), bits == 16 ? Code::kOutOfMemory : Code::kOk) << status.message();
  }
}

// The depth image is plain grey: a colour, alpha or interlaced PNG is refused before a pixel
// is decoded, by the same reader that reads the frames.
TEST(PngMemoryTest, OnlyPlainGreyIsADepthImage) {
  std::vector<uint8_t> rgb(4 * 3 * 3, 7), png;
  ASSERT_TRUE(EncodeRgbPng(MakeView(rgb.data(), 4, 3, 3), &png).ok());
  GrayPng out;
  const Status colour = DecodeGrayPng(png.data(), png.size(), "depth", 100, 0, 0, &out);
  EXPECT_STREQ(colour.message(), "depth: PNG: not a greyscale image without alpha");
  EXPECT_TRUE(out.values.empty());
  EXPECT_EQ(out.width, 0);
  const uint8_t not_png[] = "P5\n1 1\n255\n";
  EXPECT_STREQ(DecodeGrayPng(not_png, sizeof(not_png), "depth", 100, 0, 0, &out).message(),
               "depth: not a PNG");
}

}  // namespace
}  // namespace lb
