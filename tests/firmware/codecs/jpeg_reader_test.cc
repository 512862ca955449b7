#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "firmware/codecs/image_file.h"
#include "tests/firmware/codecs/recording_sink.h"
#include "tests/firmware/codecs/test_images.h"

namespace lb {
namespace {

using test::Bytes;

std::vector<uint8_t> Pattern(int width, int height, int components) {
  std::vector<uint8_t> pixels;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < components; ++c) pixels.push_back(test::Smooth(x, y, c));
    }
  }
  return pixels;
}

Bytes Encode(int width, int height, int components, bool progressive = false) {
  Bytes out;
  const std::vector<uint8_t> pixels = Pattern(width, height, components);
  EXPECT_TRUE(test::EncodeJpeg(width, height, components, pixels.data(), 95, progressive, &out));
  return out;
}

int MaxDifference(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  if (a.size() != b.size()) return 1000;
  int worst = 0;
  for (size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::abs(a[i] - b[i]));
  return worst;
}

Status Read(const Bytes& bytes, ImageFileInfo* info, std::vector<uint8_t>* pixels) {
  return ReadImageMemory(bytes.data(), bytes.size(), "x.jpg", info, pixels);
}

TEST(JpegReader, ReadsRgbInStripsCloseToTheOriginal) {
  const std::string path = ::testing::TempDir() + "rgb.jpg";
  ASSERT_TRUE(test::WriteFile(path, Encode(24, 40, 3)));
  test::RecordingSink sink;
  ASSERT_TRUE(StreamImageFile(path.c_str(), 2, sink).ok()) << sink.error;
  ASSERT_EQ(sink.frames.size(), 1u);
  EXPECT_EQ(sink.frames[0].info.index, 2);
  EXPECT_EQ(sink.frames[0].info.format, PixelFormat::kRgb8);
  EXPECT_EQ(sink.frames[0].info.width, 24);
  EXPECT_EQ(sink.frames[0].info.height, 40);
  EXPECT_EQ(sink.frames[0].strip_heights, (std::vector<int32_t>{16, 16, 8}));
  // Quality 95 on a smooth gradient: chroma subsampling and rounding cost a few levels.
  EXPECT_LE(MaxDifference(sink.frames[0].pixels, Pattern(24, 40, 3)), 6);
}

// The caller's strip (the web page's engine): the same pixels as a read that allocates, and an
// image larger than the caller takes refused before any row reaches the sink.
TEST(JpegReader, StreamsIntoTheCallersStrip) {
  const Bytes jpeg = Encode(24, 40, 3);
  ImageFileInfo info;
  std::vector<uint8_t> expected;
  ASSERT_TRUE(Read(jpeg, &info, &expected).ok());
  std::vector<uint8_t> strip(ImageStripBytes(24, PixelFormat::kRgb8));
  ImageReadMemory memory;
  memory.strip = strip.data();
  memory.strip_bytes = strip.size();
  memory.max_width = 24;
  memory.max_height = 40;
  test::RecordingSink sink;
  Status s = StreamImageMemory(jpeg.data(), jpeg.size(), "x.jpg", 1, sink, memory);
  ASSERT_TRUE(s.ok()) << s.message() << sink.error;
  ASSERT_EQ(sink.frames.size(), 1u);
  EXPECT_EQ(sink.frames[0].info.index, 1);
  EXPECT_EQ(sink.frames[0].pixels, expected);

  for (int32_t side : {0, 1}) {
    ImageReadMemory small = memory;
    (side == 0 ? small.max_width : small.max_height) -= 1;
    test::RecordingSink refused;
    s = StreamImageMemory(jpeg.data(), jpeg.size(), "x.jpg", 0, refused, small);
    EXPECT_EQ(s.code(), Code::kOutOfMemory) << s.message();
    EXPECT_TRUE(refused.frames.empty());
  }
  ImageReadMemory narrow = memory;
  narrow.strip_bytes -= 1;
  test::RecordingSink refused;
  s = StreamImageMemory(jpeg.data(), jpeg.size(), "x.jpg", 0, refused, narrow);
  EXPECT_EQ(s.code(), Code::kOutOfMemory) << s.message();
  EXPECT_TRUE(refused.frames.empty());
}

// The thumbnails' read: from an open descriptor, a JPEG decoded at the smallest M/8 that is
// still at least the width asked for, and still the picture (its mean level per quarter).
TEST(JpegReader, ADescriptorReadShrinksAJpegInTheDecoder) {
  const std::string path = ::testing::TempDir() + "scaled.jpg";
  ASSERT_TRUE(test::WriteFile(path, Encode(160, 96, 3)));
  ImageFileInfo whole_info;
  std::vector<uint8_t> whole;
  ASSERT_TRUE(ReadImageFile(path.c_str(), &whole_info, &whole).ok());
  const struct {
    int32_t min_width, width, height;
  } kCases[] = {{20, 20, 12},   {21, 40, 24}, {80, 80, 48},
                {159, 160, 96}, {0, 160, 96}, {500, 160, 96}};
  for (const auto& c : kCases) {
    const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
    ASSERT_GE(fd, 0);
    test::RecordingSink sink;
    const Status s = StreamImageDescriptor(fd, "scaled.jpg", c.min_width, sink);
    close(fd);
    ASSERT_TRUE(s.ok()) << s.message() << sink.error;
    ASSERT_EQ(sink.frames.size(), 1u);
    const auto& f = sink.frames[0];
    EXPECT_EQ(f.info.width, c.width) << c.min_width;
    EXPECT_EQ(f.info.height, c.height) << c.min_width;
    // Each quadrant's mean against the whole image's (a gradient: the quadrants differ).
    for (int32_t q = 0; q < 4; ++q) {
      const auto mean = [&](const std::vector<uint8_t>& px, int32_t w, int32_t h) {
        double sum = 0;
        const int32_t x0 = (q % 2) * w / 2, y0 = (q / 2) * h / 2;
        for (int32_t y = y0; y < y0 + h / 2; ++y)
          for (int32_t x = x0; x < x0 + w / 2; ++x) sum += px[(y * w + x) * 3];
        return sum / (w / 2 * (h / 2));
      };
      EXPECT_NEAR(mean(f.pixels, c.width, c.height), mean(whole, 160, 96), 3.0)
          << c.min_width << ", quadrant " << q;
    }
  }
  const int closed = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  close(closed);
  test::RecordingSink none;
  EXPECT_EQ(StreamImageDescriptor(closed, "gone.jpg", 20, none).code(), Code::kIoError);
}

TEST(JpegReader, ReadsGrayAndProgressive) {
  ImageFileInfo info;
  std::vector<uint8_t> pixels;
  ASSERT_TRUE(Read(Encode(17, 9, 1), &info, &pixels).ok());
  EXPECT_EQ(info.format, PixelFormat::kGray8);
  EXPECT_LE(MaxDifference(pixels, Pattern(17, 9, 1)), 3);

  const Status s = Read(Encode(33, 18, 3, true), &info, &pixels);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(info.format, PixelFormat::kRgb8);
  EXPECT_LE(MaxDifference(pixels, Pattern(33, 18, 3)), 6);
}

TEST(JpegReader, TruncatedJpegIsAnErrorNotGreyPadding) {
  const Bytes bytes = Encode(64, 64, 3);
  for (size_t keep : {size_t{100}, bytes.size() / 2, bytes.size() - 2}) {
    const Bytes cut(bytes.begin(), bytes.begin() + static_cast<long>(keep));
    ImageFileInfo info;
    std::vector<uint8_t> pixels;
    const Status s = Read(cut, &info, &pixels);
    EXPECT_EQ(s.code(), Code::kCorruptData) << keep;
    EXPECT_EQ(std::string(s.message()),
              "x.jpg: truncated: JPEG data ends after " + std::to_string(keep) + " bytes");
    EXPECT_TRUE(pixels.empty());
  }
}

TEST(JpegReader, CorruptEntropyDataIsAnError) {
  Bytes bytes = Encode(64, 64, 3);
  // Garbage markers in the middle of the scan: libjpeg would only warn and carry on.
  for (size_t i = bytes.size() / 2; i < bytes.size() / 2 + 16; i += 2) {
    bytes[i] = 0xff;
    bytes[i + 1] = 0xd3;
  }
  ImageFileInfo info;
  std::vector<uint8_t> pixels;
  const Status s = Read(bytes, &info, &pixels);
  EXPECT_EQ(s.code(), Code::kCorruptData);
  EXPECT_EQ(std::string(s.message()).rfind("x.jpg: JPEG ", 0), 0u) << s.message();
}

TEST(JpegReader, CmykIsRejectedClearly) {
  ImageFileInfo info;
  const Bytes bytes = Encode(8, 8, 4);
  const Status s = ProbeImageMemory(bytes.data(), bytes.size(), "print.jpg", &info);
  EXPECT_EQ(s.code(), Code::kUnsupported);
  EXPECT_STREQ(s.message(), "print.jpg: CMYK JPEG is not supported (save it as RGB)");
}

TEST(ImageFile, DetectsTheFormatByMagicNotByName) {
  const std::string path = ::testing::TempDir() + "really_a_jpeg.png";
  ASSERT_TRUE(test::WriteFile(path, Encode(8, 8, 1)));
  ImageFileInfo info;
  std::vector<uint8_t> pixels;
  ASSERT_TRUE(ReadImageFile(path.c_str(), &info, &pixels).ok());
  EXPECT_EQ(info.format, PixelFormat::kGray8);
  EXPECT_EQ(pixels.size(), 64u);

  const std::string text = ::testing::TempDir() + "notes.jpg";
  ASSERT_TRUE(test::WriteFile(text, {'h', 'e', 'l', 'l', 'o'}));
  const Status s = ProbeImageFile(text.c_str(), &info);
  EXPECT_EQ(s.code(), Code::kUnsupported);
  EXPECT_EQ(std::string(s.message()),
            text + ": not a PPM, PGM, PNG or JPEG file (starts 68 65 6c 6c)");
}

TEST(ImageFile, MissingAndEmptyFilesAreErrorsNamingThem) {
  ImageFileInfo info;
  Status s = ProbeImageFile("missing/a.ppm", &info);
  EXPECT_EQ(s.code(), Code::kNotFound);
  EXPECT_STREQ(s.message(), "missing/a.ppm: no such file or directory");

  const std::string empty = ::testing::TempDir() + "empty.ppm";
  ASSERT_TRUE(test::WriteFile(empty, {}));
  s = ProbeImageFile(empty.c_str(), &info);
  EXPECT_EQ(s.code(), Code::kCorruptData);
  EXPECT_EQ(std::string(s.message()), empty + ": empty file");
}

}  // namespace
}  // namespace lb
