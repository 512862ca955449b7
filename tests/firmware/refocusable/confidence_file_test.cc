// The depth map's confidence in a refocusable file: GDepth:Confidence (a base64 PNG in the XMP)
// and Dynamic Depth's confidence item are written from the same 8-bit map and read back equal by
// the product's reader, whichever format the depth comes from; a file without one opens as
// before, and a broken one (bad base64, an image that does not decode or is not the depth's
// size) is left out with one line saying why, the depth still read.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "firmware/codecs/png_writer.h"
#include "firmware/refocusable/dynamic_depth.h"
#include "firmware/refocusable/refocusable_reader.h"
#include "tests/firmware/refocusable/refocusable_test_util.h"

namespace lb {
namespace {

using test::RefocusSample;

// A map that is not flat, so that a transposed or shifted copy would not pass for it.
std::vector<uint8_t> ConfidencePattern(int32_t w, int32_t h) {
  std::vector<uint8_t> c(static_cast<size_t>(w) * h);
  for (int32_t y = 0; y < h; ++y) {
    for (int32_t x = 0; x < w; ++x) c[static_cast<size_t>(y) * w + x] = (x * 7 + y * 31) & 0xFF;
  }
  return c;
}

struct ConfidenceFile {
  RefocusSample sample;
  std::vector<uint8_t> confidence;  // the map, w x h
  DynamicDepthExtras extras;
  std::vector<uint8_t> bytes;  // GDepth and Dynamic Depth, the same confidence in both
};

ConfidenceFile Make(bool large) {
  ConfidenceFile f;
  f.sample = test::MakeRefocusSample(large);
  RefocusSample& s = f.sample;
  f.confidence = ConfidencePattern(s.disp_width, s.disp_height);
  EXPECT_TRUE(SetConfidence(
                  MakeView<const uint8_t>(f.confidence.data(), s.disp_width, s.disp_height), &s.xmp)
                  .ok());
  EXPECT_TRUE(SetDynamicDepth(f.extras, &s.xmp).ok());
  EXPECT_TRUE(BuildXmpSegments(s.xmp, &s.segments).ok());
  f.bytes = test::WriteRefocusJpeg(s, s.segments);
  EXPECT_TRUE(AppendDynamicDepthItems(s.xmp, f.extras, &f.bytes).ok());
  return f;
}

Status Read(const std::vector<uint8_t>& bytes, RefocusableImage* out) {
  return ReadRefocusable(bytes.data(), bytes.size(), "shot.jpg", out);
}

void ExpectConfidence(const ConfidenceFile& f, const RefocusableImage& r) {
  EXPECT_TRUE(r.confidence_ignored.ok()) << r.confidence_ignored.message();
  EXPECT_EQ(r.confidence.width, f.sample.disp_width);
  EXPECT_EQ(r.confidence.height, f.sample.disp_height);
  EXPECT_EQ(r.confidence.bits, 8);
  ASSERT_EQ(r.confidence.values.size(), f.confidence.size());
  size_t differing = 0;
  for (size_t i = 0; i < f.confidence.size(); ++i)
    differing += r.confidence.values[i] != f.confidence[i];
  EXPECT_EQ(differing, 0u);
  EXPECT_EQ(r.xmp.depth.confidence, f.sample.xmp.depth.confidence);
  EXPECT_EQ(r.xmp.depth.confidence_mime, "image/png");
}

// One line, naming the file and the field, and the depth read all the same.
void ExpectIgnored(const RefocusableImage& r, const RefocusSample& s, const char* field) {
  EXPECT_FALSE(r.confidence_ignored.ok());
  const std::string why = r.confidence_ignored.message();
  EXPECT_EQ(why.find('\n'), std::string::npos) << why;
  EXPECT_NE(why.find("shot.jpg"), std::string::npos) << why;
  EXPECT_NE(why.find(field), std::string::npos) << why;
  EXPECT_TRUE(r.confidence.values.empty());
  EXPECT_TRUE(r.xmp.depth.confidence.empty());
  EXPECT_EQ(r.depth.width, s.disp_width);
  EXPECT_EQ(r.depth.height, s.disp_height);
}

class ConfidenceFileTest : public ::testing::TestWithParam<bool> {};

TEST_P(ConfidenceFileTest, GDepthCarriesItAndTheReaderGivesItBack) {
  const ConfidenceFile f = Make(GetParam());
  const std::string main = test::PayloadText(f.sample.segments[0]);
  EXPECT_NE(main.find("GDepth:ConfidenceMime=\"image/png\""), std::string::npos);
  RefocusableImage r;
  const Status s = Read(f.bytes, &r);
  ASSERT_TRUE(s.ok()) << s.message();
  ExpectConfidence(f, r);
}

TEST_P(ConfidenceFileTest, DynamicDepthCarriesTheSameBytesAfterTheDepth) {
  const ConfidenceFile f = Make(GetParam());
  const RefocusableXmp& x = f.sample.xmp;
  // The items after the primary: the depth, then the confidence, then the original.
  const size_t tail = x.depth.data.size() + x.depth.confidence.size() + x.image.size();
  ASSERT_GT(f.bytes.size(), tail);
  const uint8_t* at = f.bytes.data() + f.bytes.size() - tail + x.depth.data.size();
  EXPECT_EQ(memcmp(at, x.depth.confidence.data(), x.depth.confidence.size()), 0);
  const std::vector<uint8_t> dd_only = test::WithoutGDepth(f.bytes);
  ASSERT_FALSE(dd_only.empty());
  RefocusableImage r;
  const Status s = Read(dd_only, &r);
  ASSERT_TRUE(s.ok()) << s.message();
  ASSERT_TRUE(r.xmp.depth.format == "RangeInverse");
  ExpectConfidence(f, r);
}

INSTANTIATE_TEST_SUITE_P(Sizes, ConfidenceFileTest, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& info) {
                           return info.param ? "Extended" : "OnePacket";
                         });

TEST(ConfidenceFile, AFileWithoutItOpensAsBefore) {
  const RefocusSample s = test::MakeRefocusSample(false);
  const std::vector<uint8_t> bytes = test::WriteRefocusJpeg(s, s.segments);
  EXPECT_EQ(test::PayloadText(s.segments[0]).find("Confidence"), std::string::npos);
  RefocusableImage r;
  const Status status = Read(bytes, &r);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_TRUE(r.confidence_ignored.ok());
  EXPECT_TRUE(r.confidence.values.empty());
  EXPECT_TRUE(r.xmp.depth.confidence.empty());
  // The fields say so too.
  std::vector<uint8_t> png(4096);
  RefocusableBuffers memory;
  memory.depth_png = png.data();
  memory.depth_png_capacity = png.size();
  RefocusableFields fields;
  ASSERT_TRUE(ReadRefocusableFields(bytes.data(), bytes.size(), "shot.jpg", memory, &fields).ok());
  EXPECT_EQ(fields.confidence, nullptr);
  EXPECT_TRUE(fields.confidence_ignored.ok());
}

TEST(ConfidenceFile, TheWriterRefusesAMapOfAnotherSize) {
  RefocusSample s = test::MakeRefocusSample(false);
  const std::vector<uint8_t> c = ConfidencePattern(s.disp_width + 1, s.disp_height);
  const Status status =
      SetConfidence(MakeView<const uint8_t>(c.data(), s.disp_width + 1, s.disp_height), &s.xmp);
  EXPECT_EQ(status.code(), Code::kInvalidArgument);
  EXPECT_TRUE(s.xmp.depth.confidence.empty());
}

// The packet of a one-packet file with GDepth:Confidence's value replaced.
std::vector<uint8_t> WithConfidenceValue(const RefocusSample& s, const std::string& value) {
  std::vector<JpegSegment> segments = s.segments;
  std::string text = test::PayloadText(segments[0]);
  const std::string field = "GDepth:Confidence=\"";
  const size_t begin = text.find(field);
  if (begin == std::string::npos) return {};
  const size_t from = begin + field.size();
  text.replace(from, text.find('"', from) - from, value);
  test::SetPayloadText(&segments[0], text);
  return test::WriteRefocusJpeg(s, segments);
}

TEST(ConfidenceFile, BadBase64IsIgnoredInOneLine) {
  const ConfidenceFile f = Make(false);
  const std::vector<uint8_t> bytes = WithConfidenceValue(f.sample, "iVBOR*not base64*");
  ASSERT_FALSE(bytes.empty());
  RefocusableImage r;
  const Status s = Read(bytes, &r);
  ASSERT_TRUE(s.ok()) << s.message();
  ExpectIgnored(r, f.sample, "GDepth:Confidence");
}

TEST(ConfidenceFile, BytesThatAreNoImageAreIgnored) {
  const ConfidenceFile f = Make(false);
  // Valid base64 of eight bytes that are no PNG.
  const std::vector<uint8_t> bytes = WithConfidenceValue(f.sample, "AAECAwQFBgc=");
  ASSERT_FALSE(bytes.empty());
  RefocusableImage r;
  const Status s = Read(bytes, &r);
  ASSERT_TRUE(s.ok()) << s.message();
  ExpectIgnored(r, f.sample, "GDepth:Confidence");
}

TEST(ConfidenceFile, AnImageOfAnotherSizeIsIgnored) {
  RefocusSample s = test::MakeRefocusSample(false);
  const std::vector<uint16_t> c(static_cast<size_t>(s.disp_width / 2) * s.disp_height, 100);
  ASSERT_TRUE(EncodeGrayPng(MakeView<const uint16_t>(c.data(), s.disp_width / 2, s.disp_height), 8,
                            &s.xmp.depth.confidence)
                  .ok());
  DynamicDepthExtras extras;
  ASSERT_TRUE(SetDynamicDepth(extras, &s.xmp).ok());
  ASSERT_TRUE(BuildXmpSegments(s.xmp, &s.segments).ok());
  std::vector<uint8_t> bytes = test::WriteRefocusJpeg(s, s.segments);
  ASSERT_TRUE(AppendDynamicDepthItems(s.xmp, extras, &bytes).ok());
  RefocusableImage r;
  Status status = Read(bytes, &r);
  ASSERT_TRUE(status.ok()) << status.message();
  ExpectIgnored(r, s, "GDepth:Confidence");
  EXPECT_NE(std::string(r.confidence_ignored.message()).find("depth map"), std::string::npos);
  // The same item in Dynamic Depth alone.
  status = Read(test::WithoutGDepth(bytes), &r);
  ASSERT_TRUE(status.ok()) << status.message();
  ExpectIgnored(r, s, "Dynamic Depth confidence");
}

TEST(ConfidenceFile, APngCutShortIsIgnored) {
  RefocusSample s = test::MakeRefocusSample(false);
  const std::vector<uint8_t> c = ConfidencePattern(s.disp_width, s.disp_height);
  ASSERT_TRUE(
      SetConfidence(MakeView<const uint8_t>(c.data(), s.disp_width, s.disp_height), &s.xmp).ok());
  // The header stays whole (it gives the right size); the pixels are cut.
  s.xmp.depth.confidence.resize(s.xmp.depth.confidence.size() / 2);
  ASSERT_TRUE(BuildXmpSegments(s.xmp, &s.segments).ok());
  RefocusableImage r;
  const Status status = Read(test::WriteRefocusJpeg(s, s.segments), &r);
  ASSERT_TRUE(status.ok()) << status.message();
  ExpectIgnored(r, s, "GDepth:Confidence");
}

// A reader given no room for the confidence (the web page's fixed buffers) reads the rest.
TEST(ConfidenceFile, AMemoryWithoutRoomForItReadsTheRest) {
  const ConfidenceFile f = Make(false);
  std::vector<uint8_t> png(4096);
  RefocusableBuffers memory;
  memory.depth_png = png.data();
  memory.depth_png_capacity = png.size();
  RefocusableFields fields;
  const Status s =
      ReadRefocusableFields(f.bytes.data(), f.bytes.size(), "shot.jpg", memory, &fields);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(fields.confidence, nullptr);
  EXPECT_EQ(fields.confidence_ignored.code(), Code::kOutOfMemory);
  EXPECT_EQ(fields.depth_png_size, f.sample.xmp.depth.data.size());
  // With room, the fields point at the PNG, its size from its header.
  std::vector<uint8_t> room(4096);
  memory.confidence = room.data();
  memory.confidence_capacity = room.size();
  const Status again =
      ReadRefocusableFields(f.bytes.data(), f.bytes.size(), "shot.jpg", memory, &fields);
  ASSERT_TRUE(again.ok()) << again.message();
  ASSERT_NE(fields.confidence, nullptr);
  EXPECT_EQ(fields.confidence_size, f.sample.xmp.depth.confidence.size());
  EXPECT_EQ(fields.confidence_width, f.sample.disp_width);
  EXPECT_EQ(fields.confidence_height, f.sample.disp_height);
  EXPECT_EQ(fields.confidence_mime, "image/png");
}

}  // namespace
}  // namespace lb
