#include "firmware/refocusable/refocusable_reader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <regex>
#include <string>

#include "tests/firmware/refocusable/refocusable_test_util.h"

namespace lb {
namespace {

using test::RefocusSample;

Status Read(const std::vector<uint8_t>& jpeg, RefocusableImage* out) {
  return ReadRefocusable(jpeg.data(), jpeg.size(), "shot.jpg", out);
}

void ExpectSameAsWritten(const RefocusSample& s, const RefocusableImage& r) {
  EXPECT_EQ(r.width, s.picture.width);
  EXPECT_EQ(r.height, s.picture.height);
  EXPECT_EQ(r.xmp.depth.format, "RangeInverse");
  EXPECT_EQ(r.xmp.depth.mime, "image/png");
  EXPECT_NEAR(r.xmp.depth.near_depth, s.xmp.depth.near_depth, 1e-9 * s.xmp.depth.near_depth);
  EXPECT_NEAR(r.xmp.depth.far_depth, s.xmp.depth.far_depth, 1e-9 * s.xmp.depth.far_depth);
  EXPECT_EQ(r.xmp.depth.width, s.disp_width);
  EXPECT_EQ(r.xmp.depth.height, s.disp_height);
  EXPECT_EQ(r.xmp.depth.data, s.xmp.depth.data);
  EXPECT_EQ(r.depth.width, s.disp_width);
  EXPECT_EQ(r.depth.height, s.disp_height);
  EXPECT_EQ(r.xmp.image, s.xmp.image);
  EXPECT_TRUE(r.xmp.has_focus);
  EXPECT_DOUBLE_EQ(r.xmp.focus.blur_at_infinity, 0.0125);
  EXPECT_DOUBLE_EQ(r.xmp.focus.focal_distance, 0.25);
  EXPECT_DOUBLE_EQ(r.xmp.focus.focal_point_x, 0.375);
  EXPECT_DOUBLE_EQ(r.xmp.focus.focal_point_y, 0.625);
  // The exact disparities come back (16 bits), infinity (0) included.
  std::vector<uint16_t> disp;
  DisparityRange range;
  ASSERT_TRUE(DisparityFromDepth(r, &disp, &range).ok());
  EXPECT_EQ(range.max_q8, s.range.max_q8);
  ASSERT_EQ(disp.size(), s.disp_q8.size());
  for (size_t i = 0; i < disp.size(); ++i) {
    ASSERT_EQ(disp[i], s.disp_q8[i]) << "pixel " << i;
  }
}

TEST(RefocusableTest, SmallFileRoundTripsInOnePacket) {
  const RefocusSample s = test::MakeRefocusSample(false);
  ASSERT_EQ(s.segments.size(), 1u);
  const std::string text = test::PayloadText(s.segments[0]);
  EXPECT_EQ(text.find("HasExtendedXMP"), std::string::npos);
  EXPECT_NE(text.find("GDepth:Data=\""), std::string::npos);
  RefocusableImage r;
  Status status = Read(test::WriteRefocusJpeg(s, s.segments), &r);
  ASSERT_TRUE(status.ok()) << status.message();
  ExpectSameAsWritten(s, r);
  for (size_t i = 0; i < s.disp_q8.size(); ++i) {
    ASSERT_EQ(r.depth.values[i], EncodeRangeInverse(s.disp_q8[i], s.range, 16));
  }
}

TEST(RefocusableTest, LargeFileUsesExtendedXmpAndRoundTrips) {
  const RefocusSample s = test::MakeRefocusSample(true);
  ASSERT_GE(s.segments.size(), 4u);  // the main packet and at least three chunks
  EXPECT_GT(s.xmp.image.size(), 10000u);
  const std::string main = test::PayloadText(s.segments[0]);
  EXPECT_LE(main.size(), sizeof(kXmpSignature) + kMaxXmpPacket);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(main, m, std::regex("xmpNote:HasExtendedXMP=\"([0-9A-F]{32})\"")));
  EXPECT_EQ(main.find("GDepth:Data"), std::string::npos);
  for (size_t i = 1; i < s.segments.size(); ++i) {
    const std::vector<uint8_t>& p = s.segments[i].payload;
    ASSERT_LE(p.size(), JpegSegment::kMaxPayload);
    ASSERT_EQ(memcmp(p.data(), "http://ns.adobe.com/xmp/extension/\0", 35), 0);
    EXPECT_EQ(std::string(p.begin() + 35, p.begin() + 67), m[1].str());
  }
  RefocusableImage r;
  Status status = Read(test::WriteRefocusJpeg(s, s.segments), &r);
  ASSERT_TRUE(status.ok()) << status.message();
  ExpectSameAsWritten(s, r);
}

// Fixed buffers of exactly the size each part needs (the web page's engine sizes them once):
// the same fields and bytes as the vector door; one byte less in any of them is kOutOfMemory.
TEST(RefocusableTest, FixedBuffersReadTheSameFieldsAndRefuseWhatDoesNotFit) {
  const RefocusSample s = test::MakeRefocusSample(true);
  const std::vector<uint8_t> jpeg = test::WriteRefocusJpeg(s, s.segments);
  std::vector<ExtendedXmpChunk> chunks(s.segments.size() - 1);
  // The decoded parts; base64 may need up to a byte or two more than it decodes to.
  std::vector<uint8_t> extended(1 << 20), png(s.xmp.depth.data.size() + 2),
      image(s.xmp.image.size() + 2);
  size_t extended_size = 0;
  for (size_t i = 1; i < s.segments.size(); ++i) extended_size += s.segments[i].payload.size() - 75;
  RefocusableBuffers memory;
  memory.chunks = chunks.data();
  memory.chunk_capacity = chunks.size();
  memory.extended = extended.data();
  memory.extended_capacity = extended_size;
  memory.depth_png = png.data();
  memory.depth_png_capacity = png.size();
  memory.image = image.data();
  memory.image_capacity = image.size();
  RefocusableFields f;
  Status status = ReadRefocusableFields(jpeg.data(), jpeg.size(), "shot.jpg", memory, &f);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(f.width, s.picture.width);
  EXPECT_EQ(f.depth_format, "RangeInverse");
  EXPECT_EQ(f.depth_width, s.disp_width);
  EXPECT_EQ(std::vector<uint8_t>(f.depth_png, f.depth_png + f.depth_png_size), s.xmp.depth.data);
  EXPECT_EQ(std::vector<uint8_t>(f.image, f.image + f.image_size), s.xmp.image);
  EXPECT_TRUE(f.has_focus);
  EXPECT_DOUBLE_EQ(f.focus.focal_point_x, 0.375);

  for (int part = 0; part < 4; ++part) {
    SCOPED_TRACE(part);
    RefocusableBuffers small = memory;
    size_t* capacity[4] = {&small.chunk_capacity, &small.extended_capacity,
                           &small.depth_png_capacity, &small.image_capacity};
    // The base64 check is on the text's length: shrink those below the decoded size.
    *capacity[part] -= part < 2 ? 1 : 3;
    status = ReadRefocusableFields(jpeg.data(), jpeg.size(), "shot.jpg", small, &f);
    EXPECT_EQ(status.code(), Code::kOutOfMemory) << status.message();
    EXPECT_EQ(std::string(status.message()).rfind("shot.jpg: ", 0), 0u) << status.message();
  }
}

TEST(RefocusableTest, EightBitDepthReadsBack) {
  const RefocusSample s = test::MakeRefocusSample(false, 8);
  RefocusableImage r;
  ASSERT_TRUE(Read(test::WriteRefocusJpeg(s, s.segments), &r).ok());
  EXPECT_EQ(r.depth.bits, 8);
  for (size_t i = 0; i < s.disp_q8.size(); ++i) {
    ASSERT_EQ(r.depth.values[i], EncodeRangeInverse(s.disp_q8[i], s.range, 8));
  }
}

TEST(RefocusableTest, ChunksAreReassembledByOffsetNotOrder) {
  const RefocusSample s = test::MakeRefocusSample(true);
  std::vector<JpegSegment> segs = s.segments;
  std::reverse(segs.begin() + 1, segs.end());
  // A chunk of some other extended packet is ignored.
  JpegSegment other = segs.back();
  std::fill(other.payload.begin() + 35, other.payload.begin() + 67, 'A');
  segs.push_back(other);
  RefocusableImage r;
  Status status = Read(test::WriteRefocusJpeg(s, segs), &r);
  ASSERT_TRUE(status.ok()) << status.message();
  ExpectSameAsWritten(s, r);
}

// Each defect gives a Status with the file name and a recognisable reason.
void ExpectDefect(const std::vector<uint8_t>& jpeg, const char* reason) {
  RefocusableImage r;
  Status status = Read(jpeg, &r);
  ASSERT_FALSE(status.ok()) << reason;
  EXPECT_EQ(std::string(status.message()).rfind("shot.jpg: ", 0), 0u) << status.message();
  EXPECT_NE(std::string(status.message()).find(reason), std::string::npos) << status.message();
}

TEST(RefocusableTest, PlainJpegHasNoXmp) {
  const RefocusSample s = test::MakeRefocusSample(false);
  ExpectDefect(test::WriteRefocusJpeg(s, {}), "no XMP");
  RefocusableImage r;
  EXPECT_EQ(Read(test::WriteRefocusJpeg(s, {}), &r).code(), Code::kNotFound);
  ExpectDefect({0x89, 'P', 'N', 'G', 0, 0}, "not a JPEG");
}

TEST(RefocusableTest, BrokenExtendedXmpIsReported) {
  const RefocusSample s = test::MakeRefocusSample(true);
  const size_t n = s.segments.size();
  {
    std::vector<JpegSegment> segs = s.segments;
    segs.erase(segs.begin() + 2);
    ExpectDefect(test::WriteRefocusJpeg(s, segs), "gap");
  }
  {
    std::vector<JpegSegment> segs = s.segments;
    segs.pop_back();
    ExpectDefect(test::WriteRefocusJpeg(s, segs), "truncated");
  }
  {
    std::vector<JpegSegment> segs(s.segments.begin(), s.segments.begin() + 1);
    ExpectDefect(test::WriteRefocusJpeg(s, segs), "announced but absent");
  }
  {
    std::vector<JpegSegment> segs = s.segments;
    segs[n - 1].payload.resize(60);  // cut inside the chunk header
    ExpectDefect(test::WriteRefocusJpeg(s, segs), "chunk at offset");
  }
  {
    std::vector<JpegSegment> segs = s.segments;
    segs[1].payload[71] ^= 0x10;  // offset field: the chunk now claims to lie past the end
    ExpectDefect(test::WriteRefocusJpeg(s, segs), "overruns");
  }
  {
    std::vector<JpegSegment> segs = s.segments;
    segs[2].payload[1000] ^= 0x01;
    ExpectDefect(test::WriteRefocusJpeg(s, segs), "does not match its MD5");
  }
}

std::vector<uint8_t> WithMainPacket(const RefocusSample& s, const std::string& pattern,
                                    const std::string& replacement) {
  std::vector<JpegSegment> segs = s.segments;
  const std::string text = test::PayloadText(segs[0]);
  const std::string edited = std::regex_replace(text, std::regex(pattern), replacement,
                                                std::regex_constants::format_first_only);
  EXPECT_NE(edited, text) << pattern;
  test::SetPayloadText(&segs[0], edited);
  return test::WriteRefocusJpeg(s, segs);
}

TEST(RefocusableTest, BadFieldsAreReported) {
  const RefocusSample s = test::MakeRefocusSample(false);
  ExpectDefect(WithMainPacket(s, "GDepth:Near=\"[^\"]*\"", ""), "GDepth:Near missing");
  ExpectDefect(WithMainPacket(s, "GDepth:Format=\"[^\"]*\"", ""), "GDepth:Format missing");
  ExpectDefect(WithMainPacket(s, "GDepth:Far=\"[^\"]*\"", "GDepth:Far=\"abc\""),
               "GDepth:Far is not a number");
  ExpectDefect(WithMainPacket(s, "GDepth:Far=\"[^\"]*\"", "GDepth:Far=\"0.001\""),
               "not a valid range");
  ExpectDefect(WithMainPacket(s, "GDepth:Format=\"[^\"]*\"", "GDepth:Format=\"Disparity\""),
               "GDepth:Format 'Disparity'");
  ExpectDefect(WithMainPacket(s, "GDepth:Mime=\"[^\"]*\"", "GDepth:Mime=\"image/gif\""),
               "(image/png or image/jpeg)");
  ExpectDefect(WithMainPacket(s, "GDepth:Mime=\"[^\"]*\"", "GDepth:Mime=\"image/jpeg\""),
               "Not a JPEG");
  ExpectDefect(WithMainPacket(s, "GDepth:Data=\"", "GDepth:Data=\"!"), "base64");
  ExpectDefect(WithMainPacket(s, "GDepth:Data=\"[^\"]*\"", "GDepth:Data=\"AAAA\""),
               "PNG data ends");
  ExpectDefect(WithMainPacket(s, "GDepth:ImageWidth=\"[^\"]*\"", "GDepth:ImageWidth=\"25\""),
               "expected 25x16");
  ExpectDefect(WithMainPacket(s, "GDepth:ImageHeight=\"[^\"]*\"", ""), "must come together");
  ExpectDefect(WithMainPacket(s, "GFocus:FocalDistance=\"[^\"]*\"", ""),
               "GFocus:FocalDistance missing");
  ExpectDefect(WithMainPacket(s, "xmlns:GDepth=\"[^\"]*\"", "xmlns:GDepth=\"http://example.com/\""),
               "no depth map");
  ExpectDefect(WithMainPacket(s, "<rdf:Description",
                              "<rdf:Description xmlns:xmpNote=\"http://ns.adobe.com/xmp/note/\" "
                              "xmpNote:HasExtendedXMP=\"12\""),
               "not an MD5");
}

TEST(RefocusableTest, OtherPrefixesAndElementFormAreUnderstood) {
  const RefocusSample s = test::MakeRefocusSample(false);
  std::string text = test::PayloadText(s.segments[0]);
  text = std::regex_replace(text, std::regex("GDepth:"), "gd:");
  text = std::regex_replace(text, std::regex("xmlns:GDepth="), "xmlns:gd=");
  text = std::regex_replace(text, std::regex("gd:Format=\"RangeInverse\""), "");
  text = std::regex_replace(text, std::regex("/>\n </rdf:RDF>"),
                            "><gd:Format>RangeInverse</gd:Format></rdf:Description>\n </rdf:RDF>");
  std::vector<JpegSegment> segs = s.segments;
  test::SetPayloadText(&segs[0], text);
  RefocusableImage r;
  Status status = Read(test::WriteRefocusJpeg(s, segs), &r);
  ASSERT_TRUE(status.ok()) << status.message();
  ExpectSameAsWritten(s, r);
}

TEST(RefocusableTest, TruncatedFilesAreReported) {
  const RefocusSample s = test::MakeRefocusSample(true);
  const std::vector<uint8_t> jpeg = test::WriteRefocusJpeg(s, s.segments);
  for (size_t cut : {size_t{3}, size_t{100}, size_t{70000}, jpeg.size() / 2}) {
    RefocusableImage r;
    const std::vector<uint8_t> part(jpeg.begin(), jpeg.begin() + static_cast<ptrdiff_t>(cut));
    Status status = Read(part, &r);
    EXPECT_FALSE(status.ok()) << cut;
  }
}

// Random damage anywhere in the metadata never crashes the reader (ASan watches) and never
// passes off a damaged depth map as good: a read that succeeds has the depth data intact or
// reports different data.
TEST(RefocusableTest, RandomDamageNeverCrashes) {
  for (bool large : {false, true}) {
    const RefocusSample s = test::MakeRefocusSample(large);
    const std::vector<uint8_t> jpeg = test::WriteRefocusJpeg(s, s.segments);
    size_t header = 0;  // bytes up to the first scan
    while (header + 1 < jpeg.size() && !(jpeg[header] == 0xFF && jpeg[header + 1] == 0xDA)) {
      ++header;
    }
    uint32_t state = 99;
    for (int round = 0; round < 400; ++round) {
      std::vector<uint8_t> bad = jpeg;
      const int flips = 1 + round % 4;
      for (int i = 0; i < flips; ++i) {
        state = state * 1664525u + 1013904223u;
        bad[2 + (state >> 4) % (header - 2)] ^= static_cast<uint8_t>(1 + (state & 0xFE));
      }
      if (round % 5 == 0) bad.resize(2 + (state >> 3) % header);
      RefocusableImage r;
      Status status = Read(bad, &r);
      if (status.ok()) {
        EXPECT_EQ(r.depth.values.size(),
                  static_cast<size_t>(r.depth.width) * static_cast<size_t>(r.depth.height));
      }
    }
  }
}

}  // namespace
}  // namespace lb
