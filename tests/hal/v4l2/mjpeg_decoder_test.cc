#include "hal/v4l2/mjpeg_decoder.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "hal/v4l2/mjpeg_check.h"
#include "tests/hal/v4l2/jpeg_frames.h"

namespace lb {
namespace {

using jpegtest::Rgb;
using jpegtest::Sampling;

// Collects the strips into a whole picture and checks their order and size.
class PictureSink : public FrameSink {
 public:
  Rgb picture;
  FrameInfo info;
  int begun = 0, ended = 0, strips = 0, rows = 0, bad_strips = 0;
  bool fail_begin = false;

  Status BeginFrame(const FrameInfo& i) override {
    if (fail_begin) return Status(Code::kOutOfMemory, "sink full");
    ++begun;
    info = i;
    rows = 0;
    picture.width = i.width;
    picture.height = i.height;
    picture.pixels.assign(size_t(i.width) * i.height * 3, 0);
    return Status::Ok();
  }
  Status Rows(const FrameRows& r) override {
    ++strips;
    if (r.y0 != rows || r.height < 1 || r.height > MjpegDecoder::kStripRows) ++bad_strips;
    for (int32_t y = 0; y < r.height && r.y0 + y < picture.height; ++y) {
      memcpy(&picture.pixels[size_t(r.y0 + y) * picture.width * 3], r.planes[0] + r.strides[0] * y,
             size_t(picture.width) * 3);
    }
    rows = r.y0 + r.height;
    return Status::Ok();
  }
  Status EndFrame() override {
    ++ended;
    return Status::Ok();
  }
};

bool Contains(const Status& s, const char* text) {
  return std::string(s.message()).find(text) != std::string::npos;
}

struct Difference {
  double mean = 0;
  int max = 0;
};
Difference Compare(const Rgb& a, const Rgb& b) {
  Difference d;
  if (a.pixels.size() != b.pixels.size()) return {1e9, 999};
  double sum = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    const int e = std::abs(int(a.pixels[i]) - int(b.pixels[i]));
    sum += e;
    if (e > d.max) d.max = e;
  }
  d.mean = sum / double(a.pixels.size());
  return d;
}

Status DecodeInto(MjpegDecoder& decoder, const std::vector<uint8_t>& jpeg, PictureSink* sink,
                  bool* began) {
  FrameInfo info;
  info.index = 2;
  info.sequence = 7;
  return decoder.Decode(jpeg.data(), jpeg.size(), info, *sink, began);
}

TEST(MjpegDecoderTest, DecodesEachSubsamplingToTheEncodedPictureInStrips) {
  struct Case {
    int32_t w, h;
    Sampling sampling;
  };
  const Case cases[] = {{64, 48, Sampling::k422},
                        {64, 48, Sampling::k420},
                        {64, 48, Sampling::k444},
                        {50, 31, Sampling::k420},
                        {320, 240, Sampling::k422}};
  for (const Case& c : cases) {
    SCOPED_TRACE(testing::Message() << c.w << "x" << c.h << " sampling " << int(c.sampling));
    const Rgb picture = jpegtest::TestPicture(c.w, c.h, 3);
    jpegtest::EncodeOptions options;
    options.quality = 95;
    options.sampling = c.sampling;
    const std::vector<uint8_t> jpeg = jpegtest::Encode(picture, options);
    ASSERT_FALSE(jpeg.empty());
    MjpegDecoder decoder;
    ASSERT_TRUE(decoder.Configure(c.w, c.h).ok());
    PictureSink sink;
    bool began = false;
    Status s = DecodeInto(decoder, jpeg, &sink, &began);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_TRUE(began);
    EXPECT_EQ(sink.begun, 1);
    EXPECT_EQ(sink.ended, 1);
    EXPECT_EQ(sink.bad_strips, 0);
    EXPECT_EQ(sink.rows, c.h);
    EXPECT_EQ(sink.strips, (c.h + MjpegDecoder::kStripRows - 1) / MjpegDecoder::kStripRows);
    EXPECT_EQ(sink.info.format, PixelFormat::kRgb8);
    EXPECT_EQ(sink.info.index, 2);
    EXPECT_EQ(sink.info.sequence, 7u);
    // Bit for bit what libjpeg gives on its own, and within JPEG's error of the picture.
    const Rgb reference = jpegtest::DecodeWithLibjpeg(jpeg);
    EXPECT_EQ(Compare(sink.picture, reference).max, 0);
    const Difference d = Compare(sink.picture, picture);
    EXPECT_LT(d.mean, 3.0);
    EXPECT_LT(d.max, 48);
  }
}

TEST(MjpegDecoderTest, FrameWithoutHuffmanTablesDecodesWithTheStandardOnes) {
  const Rgb picture = jpegtest::TestPicture(96, 64, 5);
  const std::vector<uint8_t> jpeg = jpegtest::Encode(picture, {});
  const std::vector<uint8_t> bare = jpegtest::WithoutHuffmanTables(jpeg);
  ASSERT_GT(jpegtest::CountHeaderMarkers(jpeg, 0xC4), 0);
  ASSERT_EQ(jpegtest::CountHeaderMarkers(bare, 0xC4), 0);
  ASSERT_LT(bare.size(), jpeg.size());
  MjpegDecoder decoder;
  ASSERT_TRUE(decoder.Configure(96, 64).ok());
  // Twice: the first frame makes the standard tables, the second finds them.
  for (int i = 0; i < 2; ++i) {
    PictureSink sink;
    bool began = false;
    Status s = DecodeInto(decoder, bare, &sink, &began);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_EQ(Compare(sink.picture, jpegtest::DecodeWithLibjpeg(jpeg)).max, 0);
  }
}

TEST(MjpegDecoderTest, RestartMarkersAndRepeatedTablesDecode) {
  const Rgb picture = jpegtest::TestPicture(64, 48, 9);
  jpegtest::EncodeOptions options;
  options.restart_rows = 1;
  std::vector<uint8_t> jpeg = jpegtest::Encode(picture, options);
  // Forty more copies of the tables before the scan: the permanent tables are reused, so the
  // arena holds no more than for the plain frame.
  std::vector<uint8_t> tables = jpegtest::HeaderSegments(jpeg, 0xDB);
  const std::vector<uint8_t> huffman = jpegtest::HeaderSegments(jpeg, 0xC4);
  tables.insert(tables.end(), huffman.begin(), huffman.end());
  ASSERT_GT(huffman.size(), 0u);
  std::vector<uint8_t> padded(jpeg.begin(), jpeg.begin() + 2);
  for (int i = 0; i < 40; ++i) padded.insert(padded.end(), tables.begin(), tables.end());
  padded.insert(padded.end(), jpeg.begin() + 2, jpeg.end());

  MjpegDecoder decoder;
  ASSERT_TRUE(decoder.Configure(64, 48).ok());
  PictureSink sink;
  bool began = false;
  Status s = DecodeInto(decoder, jpeg, &sink, &began);
  ASSERT_TRUE(s.ok()) << s.message();
  const size_t peak = decoder.arena_peak();
  s = DecodeInto(decoder, padded, &sink, &began);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(Compare(sink.picture, jpegtest::DecodeWithLibjpeg(jpeg)).max, 0);
  EXPECT_EQ(decoder.arena_peak(), peak);
}

// The arena's formula holds for the widest frames in every subsampling, and repeated frames use
// the same memory each time.
TEST(MjpegDecoderTest, ArenaHoldsWideFramesAndDoesNotGrow) {
  for (Sampling sampling : {Sampling::k420, Sampling::k422, Sampling::k444, Sampling::k1x4}) {
    for (int32_t width : {16, 1920, 4096}) {
      SCOPED_TRACE(testing::Message() << width << " px, sampling " << int(sampling));
      const Rgb picture = jpegtest::TestPicture(width, 32, 1);
      jpegtest::EncodeOptions options;
      options.sampling = sampling;
      const std::vector<uint8_t> jpeg = jpegtest::Encode(picture, options);
      MjpegDecoder decoder;
      ASSERT_TRUE(decoder.Configure(width, 32).ok());
      PictureSink sink;
      bool began = false;
      ASSERT_TRUE(DecodeInto(decoder, jpeg, &sink, &began).ok());
      const size_t peak = decoder.arena_peak();
      const uint64_t calls = decoder.arena_allocations();
      ASSERT_TRUE(DecodeInto(decoder, jpeg, &sink, &began).ok());
      EXPECT_EQ(decoder.arena_peak(), peak);
      EXPECT_GT(calls, 10u);
      // The second frame makes no permanent tables: fewer calls than the first.
      EXPECT_LT(decoder.arena_allocations() - calls, calls);
      EXPECT_EQ(decoder.arena_bytes(), MjpegDecoder::ArenaBytes(width));
      // Room to spare even for the tallest layout.
      EXPECT_LT(peak, decoder.arena_bytes() * 2 / 3) << "peak " << peak;
    }
  }
}

// Frames the structural walk refuses before any row reaches the sink.
TEST(MjpegDecoderTest, CorruptFramesAreRefusedBeforeTheSinkWithTheirReason) {
  const Rgb picture = jpegtest::TestPicture(64, 48, 2);
  const std::vector<uint8_t> good = jpegtest::Encode(picture, {});
  const size_t scan = jpegtest::ScanStart(good);
  ASSERT_GT(scan, 0u);
  std::vector<uint8_t> garbage(3000);
  uint32_t state = 99;
  for (uint8_t& b : garbage)
    b = static_cast<uint8_t>((state = state * 1664525u + 1013904223u) >> 24);
  std::vector<uint8_t> marker_in_scan = good;
  marker_in_scan[scan + 40] = 0xFF;
  marker_in_scan[scan + 41] = 0xC0;
  jpegtest::EncodeOptions progressive;
  progressive.progressive = true;

  struct Case {
    const char* name;
    std::vector<uint8_t> frame;
    Code code;
    const char* says;
  };
  const Case cases[] = {
      {"empty", {}, Code::kCorruptData, "empty frame (0 bytes)"},
      {"cut in the scan",
       {good.begin(), good.begin() + good.size() * 6 / 10},
       Code::kCorruptData,
       "truncated: the data ends inside the scan, with no end marker,"},
      {"cut in the header", {good.begin(), good.begin() + 100}, Code::kCorruptData, "truncated"},
      {"garbage", garbage, Code::kCorruptData, "no JPEG start marker"},
      {"no SOI",
       {good.begin() + 2, good.end()},
       Code::kCorruptData,
       "no JPEG start marker (the frame begins ff e0)"},
      {"another size", jpegtest::Encode(jpegtest::TestPicture(32, 24, 2), {}), Code::kCorruptData,
       "the frame header says 32x24, the mode is 64x48"},
      {"marker in the scan", marker_in_scan, Code::kCorruptData, "marker 0xffc0 inside the scan"},
      {"progressive", jpegtest::Encode(picture, progressive), Code::kUnsupported,
       "progressive JPEG (SOF2)"},
  };
  MjpegDecoder decoder;
  ASSERT_TRUE(decoder.Configure(64, 48).ok());
  for (const Case& c : cases) {
    PictureSink sink;
    bool began = true;
    Status s = DecodeInto(decoder, c.frame, &sink, &began);
    EXPECT_EQ(s.code(), c.code) << c.name << ": " << s.message();
    EXPECT_TRUE(Contains(s, c.says)) << c.name << ": " << s.message();
    EXPECT_FALSE(began) << c.name;
    EXPECT_EQ(sink.begun, 0) << c.name;
    // The same words from the walk alone.
    EXPECT_STREQ(CheckMjpegFrame(c.frame.data(), c.frame.size(), 64, 48).message(), s.message());
  }
  // And the decoder is whole afterwards.
  PictureSink sink;
  bool began = false;
  ASSERT_TRUE(DecodeInto(decoder, good, &sink, &began).ok());
  EXPECT_EQ(Compare(sink.picture, jpegtest::DecodeWithLibjpeg(good)).max, 0);
}

// Entropy data cut short with the end marker still there passes the walk; libjpeg warns of a
// premature end (and would fill grey), which must fail the frame, not pass a bad picture on.
TEST(MjpegDecoderTest, LibjpegWarningIsACorruptFrame) {
  const std::vector<uint8_t> good = jpegtest::Encode(jpegtest::TestPicture(64, 64, 4), {});
  const size_t scan = jpegtest::ScanStart(good);
  std::vector<uint8_t> cut(good.begin(), good.begin() + scan + (good.size() - scan) / 3);
  cut.push_back(0xFF);
  cut.push_back(0xD9);
  ASSERT_TRUE(CheckMjpegFrame(cut.data(), cut.size(), 64, 64).ok());
  MjpegDecoder decoder;
  ASSERT_TRUE(decoder.Configure(64, 64).ok());
  PictureSink sink;
  bool began = false;
  Status s = DecodeInto(decoder, cut, &sink, &began);
  EXPECT_EQ(s.code(), Code::kCorruptData);
  EXPECT_TRUE(Contains(s, "Corrupt JPEG data: premature end of data segment")) << s.message();
  EXPECT_TRUE(Contains(s, "rows went to the sink")) << s.message();
  EXPECT_TRUE(began);
  EXPECT_EQ(sink.ended, 0);
  EXPECT_LT(sink.rows, 64);
  ASSERT_TRUE(DecodeInto(decoder, good, &sink, &began).ok());
}

TEST(MjpegDecoderTest, SinkErrorIsPassedOnAndConfigureKeepsOrRebuilds) {
  const std::vector<uint8_t> jpeg = jpegtest::Encode(jpegtest::TestPicture(64, 48, 2), {});
  MjpegDecoder decoder;
  PictureSink sink;
  bool began = false;
  EXPECT_EQ(DecodeInto(decoder, jpeg, &sink, &began).code(), Code::kInternal);
  EXPECT_EQ(decoder.Configure(0, 48).code(), Code::kInvalidArgument);
  ASSERT_TRUE(decoder.Configure(64, 48).ok());
  sink.fail_begin = true;
  Status s = DecodeInto(decoder, jpeg, &sink, &began);
  EXPECT_EQ(s.code(), Code::kOutOfMemory);
  EXPECT_STREQ(s.message(), "sink full");
  EXPECT_TRUE(began);
  sink.fail_begin = false;
  const size_t bytes = decoder.arena_bytes();
  ASSERT_TRUE(decoder.Configure(64, 48).ok());
  EXPECT_GT(decoder.arena_allocations(), 0u);  // kept
  ASSERT_TRUE(decoder.Configure(640, 48).ok());
  EXPECT_EQ(decoder.arena_allocations(), 0u);  // made anew
  EXPECT_GT(decoder.arena_bytes(), bytes);
  EXPECT_EQ(DecodeInto(decoder, jpeg, &sink, &began).code(), Code::kCorruptData);
}

}  // namespace
}  // namespace lb
