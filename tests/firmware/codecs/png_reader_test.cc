#include <png.h>

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "firmware/codecs/image_file.h"
#include "tests/firmware/codecs/recording_sink.h"
#include "tests/firmware/codecs/test_images.h"

namespace lb {
namespace {

using test::Bytes;
using test::PngSpec;

Bytes Encode(const PngSpec& spec) {
  Bytes out;
  EXPECT_TRUE(test::EncodePng(spec, &out));
  return out;
}

Status Read(const Bytes& bytes, ImageFileInfo* info, std::vector<uint8_t>* pixels) {
  return ReadImageMemory(bytes.data(), bytes.size(), "x.png", info, pixels);
}

PngSpec Rgb8(int width, int height, bool interlaced) {
  PngSpec spec{width, height, PNG_COLOR_TYPE_RGB, 8, interlaced, {}, {}};
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < 3; ++c) spec.rows.push_back(test::Smooth(x, y, c));
    }
  }
  return spec;
}

TEST(PngReader, ReadsRgb8InStrips) {
  const PngSpec spec = Rgb8(7, 37, false);
  const std::string path = ::testing::TempDir() + "rgb8.png";
  ASSERT_TRUE(test::WriteFile(path, Encode(spec)));
  test::RecordingSink sink;
  ASSERT_TRUE(StreamImageFile(path.c_str(), 1, sink).ok()) << sink.error;
  ASSERT_EQ(sink.frames.size(), 1u);
  EXPECT_EQ(sink.frames[0].info.format, PixelFormat::kRgb8);
  EXPECT_EQ(sink.frames[0].info.width, 7);
  EXPECT_EQ(sink.frames[0].info.height, 37);
  EXPECT_EQ(sink.frames[0].strip_heights, (std::vector<int32_t>{16, 16, 5}));
  EXPECT_EQ(sink.frames[0].pixels, spec.rows);
}

TEST(PngReader, ReadsInterlacedImagesExactly) {
  const PngSpec spec = Rgb8(13, 21, true);
  test::RecordingSink sink;
  const std::string path = ::testing::TempDir() + "adam7.png";
  ASSERT_TRUE(test::WriteFile(path, Encode(spec)));
  ASSERT_TRUE(StreamImageFile(path.c_str(), 0, sink).ok()) << sink.error;
  EXPECT_EQ(sink.frames[0].strip_heights, (std::vector<int32_t>{16, 5}));
  EXPECT_EQ(sink.frames[0].pixels, spec.rows);
}

TEST(PngReader, Reads16BitGrayAsNativeEndian) {
  PngSpec spec{3, 1, PNG_COLOR_TYPE_GRAY, 16, false, {}, {0x12, 0x34, 0xff, 0x00, 0x00, 0x07}};
  ImageFileInfo info;
  std::vector<uint8_t> pixels;
  ASSERT_TRUE(Read(Encode(spec), &info, &pixels).ok());
  EXPECT_EQ(info.format, PixelFormat::kGray16);
  EXPECT_EQ(test::Sample16(pixels, 0), 0x1234);
  EXPECT_EQ(test::Sample16(pixels, 1), 0xff00);
  EXPECT_EQ(test::Sample16(pixels, 2), 0x0007);
}

TEST(PngReader, StripsAlphaAndExpandsPaletteAndLowBitDepths) {
  ImageFileInfo info;
  std::vector<uint8_t> pixels;
  PngSpec rgba{2, 1, PNG_COLOR_TYPE_RGB_ALPHA, 8, false, {}, {1, 2, 3, 99, 4, 5, 6, 0}};
  ASSERT_TRUE(Read(Encode(rgba), &info, &pixels).ok());
  EXPECT_EQ(info.format, PixelFormat::kRgb8);
  EXPECT_EQ(pixels, (std::vector<uint8_t>{1, 2, 3, 4, 5, 6}));

  PngSpec gray_alpha{2, 1, PNG_COLOR_TYPE_GRAY_ALPHA, 8, false, {}, {10, 255, 20, 0}};
  ASSERT_TRUE(Read(Encode(gray_alpha), &info, &pixels).ok());
  EXPECT_EQ(info.format, PixelFormat::kGray8);
  EXPECT_EQ(pixels, (std::vector<uint8_t>{10, 20}));

  // 2-bit palette indices 0 1 2 packed in one byte: 00 01 10 xx.
  PngSpec palette{3, 1, PNG_COLOR_TYPE_PALETTE, 2, false, {9, 8, 7, 1, 2, 3, 200, 100, 50}, {0x18}};
  ASSERT_TRUE(Read(Encode(palette), &info, &pixels).ok());
  EXPECT_EQ(info.format, PixelFormat::kRgb8);
  EXPECT_EQ(pixels, (std::vector<uint8_t>{9, 8, 7, 1, 2, 3, 200, 100, 50}));

  PngSpec bits{9, 1, PNG_COLOR_TYPE_GRAY, 1, false, {}, {0xa5, 0x80}};  // 1010 0101 1
  ASSERT_TRUE(Read(Encode(bits), &info, &pixels).ok());
  EXPECT_EQ(info.format, PixelFormat::kGray8);
  EXPECT_EQ(pixels, (std::vector<uint8_t>{255, 0, 255, 0, 0, 255, 0, 255, 255}));
}

TEST(PngReader, IgnoresTransparencyChunks) {
  ImageFileInfo info;
  std::vector<uint8_t> pixels;
  PngSpec palette{2, 1, PNG_COLOR_TYPE_PALETTE, 8, false, {9, 8, 7, 1, 2, 3}, {0, 1}, true};
  Status s = Read(Encode(palette), &info, &pixels);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(info.format, PixelFormat::kRgb8);
  EXPECT_EQ(pixels, (std::vector<uint8_t>{9, 8, 7, 1, 2, 3}));

  PngSpec gray{2, 1, PNG_COLOR_TYPE_GRAY, 4, false, {}, {0x0f}, true};
  s = Read(Encode(gray), &info, &pixels);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(pixels, (std::vector<uint8_t>{0, 255}));

  PngSpec rgb{1, 1, PNG_COLOR_TYPE_RGB, 16, false, {}, {0, 0, 0, 0, 0, 0}, true};
  s = Read(Encode(rgb), &info, &pixels);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(info.format, PixelFormat::kRgb16);
  EXPECT_EQ(pixels, std::vector<uint8_t>(6, 0));
}

TEST(PngReader, BrokenCrcInIdatIsAnError) {
  Bytes bytes = Encode(Rgb8(8, 8, false));
  const long idat = test::FindPngChunk(bytes, "IDAT");
  ASSERT_GT(idat, 0);
  const size_t length = (size_t{bytes[static_cast<size_t>(idat) + 2]} << 8) | bytes[idat + 3];
  bytes[static_cast<size_t>(idat) + 8 + length] ^= 0x01;  // the stored CRC's first byte
  ImageFileInfo info;
  std::vector<uint8_t> pixels;
  const Status s = Read(bytes, &info, &pixels);
  EXPECT_EQ(s.code(), Code::kCorruptData);
  EXPECT_STREQ(s.message(), "x.png: PNG IDAT: CRC error");
}

TEST(PngReader, BrokenCrcInAncillaryChunkIsAnErrorToo) {
  Bytes bytes = Encode(Rgb8(4, 4, false));
  // A tEXt chunk with a wrong CRC before IEND.
  const Bytes text = {0, 0, 0, 3, 't', 'E', 'X', 't', 'a', 0, 'b', 0xde, 0xad, 0xbe, 0xef};
  const long iend = test::FindPngChunk(bytes, "IEND");
  ASSERT_GT(iend, 0);
  bytes.insert(bytes.begin() + iend, text.begin(), text.end());
  ImageFileInfo info;
  std::vector<uint8_t> pixels;
  const Status s = Read(bytes, &info, &pixels);
  EXPECT_EQ(s.code(), Code::kCorruptData);
  EXPECT_STREQ(s.message(), "x.png: PNG tEXt: CRC error");
}

TEST(PngReader, TruncatedDataIsAnError) {
  Bytes bytes = Encode(Rgb8(16, 16, false));
  for (size_t keep : {size_t{20}, bytes.size() / 2, bytes.size() - 1}) {
    const Bytes cut(bytes.begin(), bytes.begin() + static_cast<long>(keep));
    ImageFileInfo info;
    std::vector<uint8_t> pixels;
    const Status s = Read(cut, &info, &pixels);
    EXPECT_EQ(s.code(), Code::kCorruptData) << keep;
    EXPECT_EQ(std::string(s.message()),
              "x.png: truncated: PNG data ends after " + std::to_string(keep) + " bytes");
  }
}

}  // namespace
}  // namespace lb
