// `refocus rerender` on refocusable JPEGs it did not write: a payload that claims more pixels
// than the photo can hold is refused from its header, in little memory, and every refusal names
// the file.
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "firmware/app/refocusable.h"
#include "firmware/codecs/jpeg_writer.h"
#include "tests/firmware/cli/cli_fixture.h"
#include "tests/firmware/codecs/test_images.h"

namespace lb {
namespace {

using clitest::Cli;
using clitest::Result;
using test::Bytes;

constexpr int32_t kW = 64, kH = 48;

// A kW x kH refocusable JPEG (flat grey) carrying `disp_q8` as its depth map and `original` as
// its GImage, written the way the product writes them.
bool WriteRefocusable(const std::string& path, ConstImageU16 disp_q8, const Bytes& original) {
  JpegMetadata meta;
  DisparityRange range;
  range.min_q8 = 0;
  range.max_q8 = 8 << 8;
  if (!BuildRefocusableSegments(disp_q8, range, original, FocusUsed(), kW, &meta.extra_segments)
           .ok()) {
    return false;
  }
  std::vector<uint8_t> y(kW * 16, 120), c(kW / 2 * 8, 128), bytes;
  ConstPlanarU8 strip;
  strip.count = 3;
  strip.planes[0] = {y.data(), kW, 16, 1, kW};
  strip.planes[1] = {c.data(), kW / 2, 8, 1, kW / 2};
  strip.planes[2] = {c.data(), kW / 2, 8, 1, kW / 2};
  JpegWriter writer;
  if (!writer.BeginMemory(&bytes, kW, kH, 90, meta).ok()) return false;
  for (int32_t row = 0; row < kH; row += 16) {
    if (!writer.WriteStrip(strip, 16).ok()) return false;
  }
  return writer.Finish().ok() && test::WriteFile(path, bytes);
}

Bytes OriginalJpeg() {
  std::vector<uint8_t> rgb(kW * kH * 3);
  for (int32_t i = 0; i < kW * kH * 3; ++i)
    rgb[i] = static_cast<uint8_t>(test::Smooth(i / 3 % kW, i / 3 / kW, i % 3));
  Bytes jpg;
  return test::EncodeJpeg(kW, kH, 3, rgb.data(), 90, false, &jpg) ? jpg : Bytes{};
}

class Rerender : public Cli {
 protected:
  // A small depth map at a quarter of the photo's size, as `refocus run` stores them.
  std::vector<uint16_t> depth_ = std::vector<uint16_t>(kW / 4 * kH / 4, 3 << 8);
  ConstImageU16 depth() const { return MakeView(depth_.data(), kW / 4, kH / 4); }
  std::string In() const { return dir_ + "/in.jpg"; }
};

TEST_F(Rerender, AFileItCouldHaveWrittenRenders) {
  ASSERT_TRUE(WriteRefocusable(In(), depth(), OriginalJpeg()));
  const Result r = Run({"rerender", In(), "--out", Out()});
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

// A few bytes of GImage that claim a 16384x16384 original.
TEST_F(Rerender, AnOriginalClaimingHugeSizeIsRefusedFromItsHeader) {
  Bytes original = OriginalJpeg();
  size_t sof = 2;
  while (sof + 9 < original.size() && !(original[sof] == 0xFF && original[sof + 1] == 0xC0)) ++sof;
  ASSERT_LT(sof + 9, original.size()) << "no baseline frame header";
  for (const size_t at : {sof + 5, sof + 7}) {  // height, then width, big-endian
    original[at] = 0x40;
    original[at + 1] = 0x00;
  }
  ASSERT_TRUE(WriteRefocusable(In(), depth(), original));
  long rss_kib = 0;
  const Result r = RunMeasured({"rerender", In(), "--out", Out()}, &rss_kib);
  ExpectCleanFailure(r, In(), "16384x16384");
  EXPECT_LT(rss_kib, 64 * 1024) << "peak RSS in KiB";
  printf("a GImage claiming 16384x16384: refused at %ld KiB peak RSS\n", rss_kib);
}

// An 8192x8192 depth map (a small PNG of zeros) inside a 64x48 photo.
TEST_F(Rerender, ADepthMapLargerThanThePhotoIsRefusedFromItsHeader) {
  // Made in a process of its own: the measured child would count the pages of ours (a
  // sanitizer's allocator keeps freed memory).
  fflush(nullptr);
  const pid_t maker = fork();
  ASSERT_GE(maker, 0);
  if (maker == 0) {
    std::vector<uint16_t> huge(size_t{8192} * 8192, 0);
    _exit(WriteRefocusable(In(), MakeView(huge.data(), 8192, 8192), OriginalJpeg()) ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(waitpid(maker, &status, 0), maker);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "could not write the file";
  long rss_kib = 0;
  const Result r = RunMeasured({"rerender", In(), "--out", Out()}, &rss_kib);
  ExpectCleanFailure(r, In(), "8192x8192");
  EXPECT_LT(rss_kib, 64 * 1024) << "peak RSS in KiB";
  printf("an 8192x8192 GDepth in a 64x48 photo: refused at %ld KiB peak RSS\n", rss_kib);
}

// A depth map stored RangeLinear rerenders (its values read as depth = near + v * (far - near));
// one in a format of no name is refused naming the file and the formats it could be.
TEST_F(Rerender, ALinearDepthMapRerendersAndAnUnknownFormatIsRefused) {
  ASSERT_TRUE(WriteRefocusable(In(), depth(), OriginalJpeg()));
  const std::string good = clitest::Slurp(In());
  const size_t at = good.find("\"RangeInverse\"");
  ASSERT_NE(at, std::string::npos);
  std::string bytes = good;
  bytes.replace(at, 14, "\"RangeLinear\" ");  // the same length: no segment length changes
  ASSERT_TRUE(test::WriteFile(In(), Bytes(bytes.begin(), bytes.end())));
  Result r = Run({"rerender", In(), "--out", dir_ + "/linear.jpg"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  bytes = good;
  bytes.replace(at, 14, "\"RangeSquare\" ");
  ASSERT_TRUE(test::WriteFile(In(), Bytes(bytes.begin(), bytes.end())));
  r = Run({"rerender", In(), "--out", Out()});
  ExpectCleanFailure(r, In(), "RangeInverse or RangeLinear");
}

TEST_F(Rerender, ADepthMapOfNoWholeFractionNamesBothSizes) {
  std::vector<uint16_t> odd(5 * 5, 3 << 8);  // 64 / 5 = 12, and 5 x 12 rows are more than 48
  ASSERT_TRUE(WriteRefocusable(In(), MakeView(odd.data(), 5, 5), OriginalJpeg()));
  const Result r = Run({"rerender", In(), "--out", Out()});
  ExpectCleanFailure(r, In(), "depth map 5x5 is not a whole-number fraction of the 64x48 original");
}

TEST_F(Rerender, OverlappingExtendedXmpChunksAreNamedSo) {
  // An original too large for one XMP packet, so it travels in extended chunks; the bytes need
  // not decode, as the chunks are refused first.
  Bytes original = OriginalJpeg();
  for (uint32_t i = 0; original.size() < 200 * 1024; ++i) {
    original.push_back(static_cast<uint8_t>((i * 2654435761u) >> 24));
  }
  ASSERT_TRUE(WriteRefocusable(In(), depth(), original));
  std::string bytes = clitest::Slurp(In());
  const std::string signature("http://ns.adobe.com/xmp/extension/\0", 35);
  const size_t first = bytes.find(signature);
  ASSERT_NE(first, std::string::npos);
  const size_t second = bytes.find(signature, first + 1);
  ASSERT_NE(second, std::string::npos) << "one extended chunk only";
  // After the signature: the 32-digit GUID, the full length, then this chunk's offset
  // (big-endian): one byte back overlaps the chunk before.
  const size_t at = second + signature.size() + 32 + 4;
  uint32_t offset = 0;
  for (int k = 0; k < 4; ++k) offset = offset << 8 | static_cast<uint8_t>(bytes[at + k]);
  ASSERT_GT(offset, 0u);
  --offset;
  for (int k = 0; k < 4; ++k) bytes[at + k] = static_cast<char>(offset >> (24 - 8 * k));
  ASSERT_TRUE(test::WriteFile(In(), Bytes(bytes.begin(), bytes.end())));
  const Result r = Run({"rerender", In(), "--out", Out()});
  ExpectCleanFailure(r, In(), "extended XMP has an overlap at offset");
}

TEST_F(Rerender, OutGivenTwiceIsRefused) {
  ASSERT_TRUE(WriteRefocusable(In(), depth(), OriginalJpeg()));
  const Result r = Run({"rerender", In(), "--out", Out(), "--out", Out() + "2"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--out given twice"), std::string::npos) << r.err;
  EXPECT_TRUE(OutDirEmpty());
}

}  // namespace
}  // namespace lb
