#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "firmware/codecs/image_file.h"
#include "tests/firmware/codecs/recording_sink.h"
#include "tests/firmware/codecs/test_images.h"

namespace lb {
namespace {

using test::Bytes;
using test::EncodePnm;

Status Read(const Bytes& bytes, ImageFileInfo* info, std::vector<uint8_t>* pixels) {
  return ReadImageMemory(bytes.data(), bytes.size(), "frames/b.ppm", info, pixels);
}

TEST(PnmReader, ReadsRgb8WithCommentsBetweenEveryField) {
  std::vector<uint16_t> samples;
  for (int i = 0; i < 4 * 3 * 3; ++i) samples.push_back(static_cast<uint16_t>(i * 7));
  const Bytes bytes = EncodePnm("P6", 4, 3, 255, samples, " # made by hand\n\t# twice\r ");
  ImageFileInfo info;
  std::vector<uint8_t> pixels;
  ASSERT_TRUE(Read(bytes, &info, &pixels).ok());
  EXPECT_EQ(info.format, PixelFormat::kRgb8);
  EXPECT_EQ(info.width, 4);
  EXPECT_EQ(info.height, 3);
  EXPECT_EQ(pixels, std::vector<uint8_t>(samples.begin(), samples.end()));
}

TEST(PnmReader, Reads16BitBigEndianAsNative) {
  const std::vector<uint16_t> samples = {0, 1, 0x1234, 0xfedc, 65535, 300};
  const Bytes bytes = EncodePnm("P5", 3, 2, 65535, samples);
  ImageFileInfo info;
  std::vector<uint8_t> pixels;
  ASSERT_TRUE(Read(bytes, &info, &pixels).ok());
  EXPECT_EQ(info.format, PixelFormat::kGray16);
  ASSERT_EQ(pixels.size(), 12u);
  for (size_t i = 0; i < samples.size(); ++i) EXPECT_EQ(test::Sample16(pixels, i), samples[i]);
}

TEST(PnmReader, RescalesOtherMaxvalsToFullScale) {
  ImageFileInfo info;
  std::vector<uint8_t> pixels;
  ASSERT_TRUE(Read(EncodePnm("P5", 3, 1, 1023, {0, 512, 1023}), &info, &pixels).ok());
  EXPECT_EQ(info.format, PixelFormat::kGray16);
  EXPECT_EQ(test::Sample16(pixels, 0), 0);
  EXPECT_EQ(test::Sample16(pixels, 1), 32800);  // 512 * 65535 / 1023 = 32799.97
  EXPECT_EQ(test::Sample16(pixels, 2), 65535);

  ASSERT_TRUE(Read(EncodePnm("P6", 1, 1, 15, {0, 7, 15}), &info, &pixels).ok());
  EXPECT_EQ(info.format, PixelFormat::kRgb8);
  EXPECT_EQ(pixels, (std::vector<uint8_t>{0, 119, 255}));
}

TEST(PnmReader, StreamsInStripsAndIgnoresTrailingJunk) {
  std::vector<uint16_t> samples(5 * 40);
  for (size_t i = 0; i < samples.size(); ++i) samples[i] = static_cast<uint16_t>(i % 251);
  Bytes bytes = EncodePnm("P5", 5, 40, 255, samples);
  bytes.insert(bytes.end(), {'j', 'u', 'n', 'k'});
  const std::string path = ::testing::TempDir() + "strips.pgm";
  ASSERT_TRUE(test::WriteFile(path, bytes));
  test::RecordingSink sink;
  ASSERT_TRUE(StreamImageFile(path.c_str(), 3, sink).ok()) << sink.error;
  ASSERT_EQ(sink.frames.size(), 1u);
  EXPECT_EQ(sink.frames[0].info.index, 3);
  EXPECT_EQ(sink.frames[0].strip_heights, (std::vector<int32_t>{16, 16, 8}));
  EXPECT_TRUE(sink.frames[0].ended);
  EXPECT_EQ(sink.frames[0].pixels, std::vector<uint8_t>(samples.begin(), samples.end()));
}

TEST(PnmReader, TruncatedDataIsAnErrorNamingTheFileAndTheCount) {
  Bytes bytes = EncodePnm("P6", 20, 20, 255, std::vector<uint16_t>(20 * 20 * 3, 9));
  bytes.resize(bytes.size() - 100);
  ImageFileInfo info;
  std::vector<uint8_t> pixels;
  const Status s = Read(bytes, &info, &pixels);
  EXPECT_EQ(s.code(), Code::kCorruptData);
  EXPECT_STREQ(s.message(), "frames/b.ppm: truncated: 1100 of 1200 pixel bytes");
  EXPECT_TRUE(pixels.empty());
}

TEST(PnmReader, RejectsBadHeaders) {
  struct Case {
    std::string bytes;
    Code code;
    const char* says;
  };
  const Case cases[] = {
      {"P7\n1 1\n255\n", Code::kUnsupported, "P7 is not supported"},
      {"P3\n1 1\n255\n1 2 3", Code::kUnsupported, "P3 is not supported"},
      {"Px\n1 1\n255\n", Code::kCorruptData, "bad magic"},
      {"P6\n20000 10\n255\n", Code::kUnsupported, "20000x10 is larger than 16384x16384"},
      {"P6\n0 10\n255\n", Code::kCorruptData, "bad image size 0x10"},
      {"P6\n99999999999 1\n255\n", Code::kCorruptData, "width is absurd"},
      {"P6\n2 2\n0\n", Code::kCorruptData, "maxval 0 is outside 1..65535"},
      {"P6\n2 2\n70000\n", Code::kCorruptData, "maxval 70000 is outside 1..65535"},
      {"P6\n2 x\n255\n", Code::kCorruptData, "where the height should be"},
      {"P6\n2 2", Code::kCorruptData, "truncated PNM header (no height)"},
      {"P6\n2 2\n255", Code::kCorruptData, "truncated PNM header (no maxval)"},
      {"P6\n2 2\n255x", Code::kCorruptData, "after maxval"},
      {"P62 2\n255\n", Code::kCorruptData, "where the width should be"},
  };
  for (const Case& c : cases) {
    const Bytes bytes(c.bytes.begin(), c.bytes.end());
    ImageFileInfo info;
    const Status s =
        ProbeImageMemory(bytes.data(), bytes.size(), "x.pnm", &info, ImageFileType::kPnm);
    EXPECT_EQ(s.code(), c.code) << c.bytes << ": " << s.message();
    EXPECT_NE(std::string(s.message()).find("x.pnm: "), std::string::npos) << s.message();
    EXPECT_NE(std::string(s.message()).find(c.says), std::string::npos) << s.message();
  }
}

TEST(PnmReader, SampleAboveMaxvalIsAnError) {
  ImageFileInfo info;
  std::vector<uint8_t> pixels;
  const Status s = Read(EncodePnm("P5", 2, 1, 100, {50, 101}), &info, &pixels);
  EXPECT_EQ(s.code(), Code::kCorruptData);
  EXPECT_STREQ(s.message(), "frames/b.ppm: sample 101 exceeds maxval 100 in row 0");
}

}  // namespace
}  // namespace lb
