#include "firmware/codecs/png_writer.h"

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "firmware/codecs/image_file.h"

namespace lb {
namespace {

// The one PNG writer's output read back through the one PNG reader, as a file would be.
TEST(PngWriterTest, RgbReadsBackExactly) {
  const int32_t w = 23, h = 19;
  std::vector<uint8_t> rgb(static_cast<size_t>(w) * h * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<uint8_t>(i * 37 + (i >> 5));
  std::vector<uint8_t> png;
  ASSERT_TRUE(EncodeRgbPng(MakeView(rgb.data(), w, h, 3), &png).ok());
  ImageFileInfo info;
  std::vector<uint8_t> pixels;
  ASSERT_TRUE(ReadImageMemory(png.data(), png.size(), "rgb.png", &info, &pixels).ok());
  EXPECT_EQ(info.format, PixelFormat::kRgb8);
  EXPECT_EQ(info.width, w);
  EXPECT_EQ(info.height, h);
  EXPECT_EQ(pixels, rgb);
}

TEST(PngWriterTest, Gray16ReadsBackAsNativeSamples) {
  const int32_t w = 9, h = 5;
  std::vector<uint16_t> v(static_cast<size_t>(w) * h);
  for (size_t i = 0; i < v.size(); ++i) v[i] = static_cast<uint16_t>(i * 1499);
  std::vector<uint8_t> png;
  ASSERT_TRUE(EncodeGrayPng(MakeView(v.data(), w, h), 16, &png).ok());
  ImageFileInfo info;
  std::vector<uint8_t> pixels;
  ASSERT_TRUE(ReadImageMemory(png.data(), png.size(), "g.png", &info, &pixels).ok());
  EXPECT_EQ(info.format, PixelFormat::kGray16);
  ASSERT_EQ(pixels.size(), v.size() * 2);
  EXPECT_EQ(memcmp(pixels.data(), v.data(), pixels.size()), 0);
}

TEST(PngWriterTest, WrongShapesAreRefused) {
  std::vector<uint8_t> png = {1, 2, 3};
  std::vector<uint8_t> rgb(12);
  EXPECT_EQ(EncodeRgbPng(MakeView(rgb.data(), 4, 1, 1), &png).code(), Code::kInvalidArgument);
  EXPECT_TRUE(png.empty());
  std::vector<uint16_t> v(4);
  EXPECT_EQ(EncodeGrayPng(MakeView(v.data(), 2, 2), 12, &png).code(), Code::kInvalidArgument);
  EXPECT_EQ(EncodeRgbPng(ConstImageU8{}, &png).code(), Code::kInvalidArgument);
}

}  // namespace
}  // namespace lb
