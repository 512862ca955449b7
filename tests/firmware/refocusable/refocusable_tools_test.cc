// The refocusable JPEG through exiftool, an independent reader of EXIF, XMP and extended XMP.
#include <gtest/gtest.h>

#include <string>

#include "firmware/storage/atomic_file.h"
#include "tests/firmware/refocusable/refocusable_test_util.h"

namespace lb {
namespace {

std::string WriteFile(const test::ScratchDir& dir, const test::RefocusSample& s) {
  const std::string path = dir.Path("refocus.jpg");
  const std::vector<uint8_t> jpeg = test::WriteRefocusJpeg(s, s.segments);
  AtomicFile file;
  EXPECT_FALSE(jpeg.empty());
  EXPECT_TRUE(file.Open(path.c_str()).ok());
  EXPECT_TRUE(file.Write(jpeg.data(), jpeg.size()).ok());
  EXPECT_TRUE(file.Commit().ok());
  return path;
}

std::string Exiftool(const std::string& args, const std::string& path) {
  int code = 0;
  std::string out = test::RunTool("exiftool " + args + " '" + path + "' 2>&1", &code);
  EXPECT_EQ(code, 0) << out;
  return out;
}

class RefocusableToolsTest : public ::testing::TestWithParam<bool> {
 protected:
  void SetUp() override {
    if (!test::HaveTool("exiftool")) GTEST_SKIP() << "exiftool not installed";
  }
};

TEST_P(RefocusableToolsTest, ExiftoolReadsEveryField) {
  const bool large = GetParam();
  const test::RefocusSample s = test::MakeRefocusSample(large);
  ASSERT_EQ(s.segments.size() > 1, large);
  test::ScratchDir dir;
  const std::string path = WriteFile(dir, s);

  const std::string xml = Exiftool("-X", path);
  char near_text[80], far_text[80];
  snprintf(near_text, sizeof(near_text), "<XMP-GDepth:Near>%.9g</XMP-GDepth:Near>",
           s.xmp.depth.near_depth);
  snprintf(far_text, sizeof(far_text), "<XMP-GDepth:Far>%.9g</XMP-GDepth:Far>",
           s.xmp.depth.far_depth);
  for (const std::string& want :
       {std::string("<XMP-GDepth:Format>RangeInverse<"), std::string(near_text),
        std::string(far_text), std::string("<XMP-GDepth:Mime>image/png<"),
        std::string("<XMP-GDepth:ImageWidth>") + std::to_string(s.disp_width) + "<",
        std::string("<XMP-GDepth:ImageHeight>") + std::to_string(s.disp_height) + "<",
        std::string("<XMP-GDepth:DepthImage>(Binary data"),
        std::string("<XMP-GFocus:BlurAtInfinity>0.0125<"),
        std::string("<XMP-GFocus:FocalDistance>0.25<"),
        std::string("<XMP-GFocus:FocalPointX>0.375<"),
        std::string("<XMP-GFocus:FocalPointY>0.625<"), std::string("<IFD0:Make>LensBlur<")}) {
    EXPECT_NE(xml.find(want), std::string::npos) << want << "\n" << xml.substr(0, 3000);
  }
  EXPECT_EQ(xml.find("Warning"), std::string::npos) << xml.substr(0, 3000);

  // exiftool names GDepth:Data "DepthImage" and GImage:Data "ImageData".
  const std::string png = Exiftool("-b -XMP-GDepth:DepthImage", path);
  EXPECT_EQ(png, std::string(s.xmp.depth.data.begin(), s.xmp.depth.data.end()));
  if (large) {
    EXPECT_NE(xml.find("<XMP-GImage:ImageMimeType>image/jpeg<"), std::string::npos);
    const std::string original = Exiftool("-b -XMP-GImage:ImageData", path);
    EXPECT_EQ(original, std::string(s.xmp.image.begin(), s.xmp.image.end()));
  }
  EXPECT_EQ(Exiftool("-validate -warning -a -s -s", path), "Validate: OK\n");
}

INSTANTIATE_TEST_SUITE_P(Sizes, RefocusableToolsTest, ::testing::Values(false, true),
                         [](const auto& info) { return info.param ? "Extended" : "OnePacket"; });

}  // namespace
}  // namespace lb
