// The PFM and preview writers: what a reader of those formats gets back, and no file at all when
// writing fails.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "firmware/codecs/image_file.h"
#include "firmware/depth_out/depth_out.h"

namespace lb {
namespace {

std::string TempPath(const char* name) {
  return std::string(::testing::TempDir()) + "/lb_depth_out_" + std::to_string(getpid()) + name;
}

TEST(DepthOutTest, PfmHoldsDisparityBottomUpLittleEndian) {
  const int32_t w = 5, h = 3;
  std::vector<uint16_t> disp(w * h);
  for (int32_t i = 0; i < w * h; ++i) disp[i] = static_cast<uint16_t>(i * 64 + 1);  // i/4 + 1/256
  const std::string path = TempPath("a.pfm");
  ASSERT_TRUE(WriteDisparityPfm(path.c_str(), MakeView(disp.data(), w, h).AsConst()).ok());
  FILE* f = fopen(path.c_str(), "rb");
  ASSERT_NE(f, nullptr);
  char magic[3] = {};
  int fw = 0, fh = 0;
  float scale = 0;
  ASSERT_EQ(fscanf(f, "%2s %d %d %f", magic, &fw, &fh, &scale), 4);
  fgetc(f);  // the single whitespace after the scale
  EXPECT_STREQ(magic, "Pf");
  EXPECT_EQ(fw, w);
  EXPECT_EQ(fh, h);
  EXPECT_LT(scale, 0) << "negative scale = little-endian";
  std::vector<uint8_t> raw(static_cast<size_t>(w) * h * 4);
  ASSERT_EQ(fread(raw.data(), 1, raw.size(), f), raw.size());
  EXPECT_EQ(fgetc(f), EOF) << "nothing after the rows";
  fclose(f);
  remove(path.c_str());
  for (int32_t row = 0; row < h; ++row) {
    const int32_t y = h - 1 - row;  // first stored row is the bottom one
    for (int32_t x = 0; x < w; ++x) {
      const uint8_t* b = &raw[(static_cast<size_t>(row) * w + x) * 4];
      const uint32_t bits = b[0] | (b[1] << 8) | (b[2] << 16) | (static_cast<uint32_t>(b[3]) << 24);
      float v;
      memcpy(&v, &bits, 4);
      EXPECT_FLOAT_EQ(v, disp[y * w + x] / 256.0f) << x << "," << y;
    }
  }
}

TEST(DepthOutTest, PreviewIsAPngOfTheColourRamp) {
  const int32_t w = 16, h = 2;
  std::vector<uint16_t> disp(w * h);
  for (int32_t x = 0; x < w; ++x) disp[x] = disp[w + x] = static_cast<uint16_t>(x * 256);
  const std::string path = TempPath("b.png");
  ASSERT_TRUE(
      WriteDisparityPreview(path.c_str(), MakeView(disp.data(), w, h).AsConst(), 0, 15 * 256).ok());
  ImageFileInfo info;
  std::vector<uint8_t> rgb;
  const Status read = ReadImageFile(path.c_str(), &info, &rgb);
  remove(path.c_str());
  ASSERT_TRUE(read.ok()) << read.message();
  ASSERT_EQ(info.format, PixelFormat::kRgb8);
  ASSERT_EQ(info.width, w);
  ASSERT_EQ(info.height, h);
  // Far is blue, near is red, and the ramp in between matches DisparityColour.
  EXPECT_EQ(rgb[0], 0);
  EXPECT_EQ(rgb[2], 255);
  EXPECT_EQ(rgb[(w - 1) * 3], 255);
  EXPECT_EQ(rgb[(w - 1) * 3 + 2], 0);
  for (int32_t x = 0; x < w; ++x) {
    uint8_t expect[3];
    DisparityColour(x * 256, 0, 15 * 256, expect);
    EXPECT_EQ(memcmp(&rgb[x * 3], expect, 3), 0) << x;
  }
}

TEST(DepthOutTest, FailureLeavesNoFile) {
  std::vector<uint16_t> disp(4 * 4, 100);
  const std::string dir = TempPath("missing_dir");
  const std::string path = dir + "/d.pfm";
  const Status s = WriteDisparityPfm(path.c_str(), MakeView(disp.data(), 4, 4).AsConst());
  EXPECT_EQ(s.code(), Code::kNotFound);
  EXPECT_NE(std::string(s.message()).find("missing_dir"), std::string::npos) << s.message();
  EXPECT_NE(access(path.c_str(), F_OK), 0);
  EXPECT_EQ(WriteDisparityPreview(TempPath("e.png").c_str(), ConstImageU16{}, 0, 1).code(),
            Code::kInvalidArgument);
  EXPECT_NE(access(TempPath("e.png").c_str(), F_OK), 0);
}

}  // namespace
}  // namespace lb
