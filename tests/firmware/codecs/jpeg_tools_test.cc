// The written JPEG through independent readers: djpeg decodes it, exiftool reads its EXIF.
#include <gtest/gtest.h>

#include <string>

#include "firmware/codecs/jpeg_writer.h"
#include "tests/firmware/codecs/jpeg_test_util.h"

namespace lb {
namespace {

std::string WriteSample(const test::ScratchDir& dir, int32_t width, int32_t height) {
  const test::Ycc420 img = test::MakeTexture(width, height);
  const std::string path = dir.Path("sample.jpg");
  AtomicFile file;
  JpegWriter writer;
  JpegMetadata meta;
  meta.make = "LensBlur";
  meta.model = "PS-1";
  meta.software = "lensblur 0.1";
  meta.datetime_original = "2026:11:23 18:30:05";
  meta.f_number = 5.6f;
  EXPECT_TRUE(file.Open(path.c_str()).ok());
  EXPECT_TRUE(writer.Begin(&file, width, height, 92, meta).ok());
  for (int32_t y = 0; y < height; y += 16) {
    const int32_t rows = height - y < 16 ? height - y : 16;
    EXPECT_TRUE(writer.WriteStrip(img.Strip(y, rows), rows).ok());
  }
  EXPECT_TRUE(writer.Finish().ok());
  EXPECT_TRUE(file.Commit().ok());
  return path;
}

TEST(JpegToolsTest, DjpegDecodesWithoutWarnings) {
  if (!test::HaveTool("djpeg")) GTEST_SKIP() << "djpeg not installed (libjpeg-turbo-progs)";
  test::ScratchDir dir;
  const std::string path = WriteSample(dir, 123, 45);
  int code = 0;
  // djpeg prints corrupt-data warnings on stderr: fold them into the output to see them.
  const std::string out = test::RunTool("djpeg -pnm '" + path + "' 2>&1 | head -c 15", &code);
  EXPECT_EQ(code, 0);
  EXPECT_EQ(out.rfind("P6\n123 45\n255\n", 0), 0u) << out;
}

TEST(JpegToolsTest, ExiftoolReadsTheExif) {
  if (!test::HaveTool("exiftool"))
    GTEST_SKIP() << "exiftool not installed (libimage-exiftool-perl)";
  test::ScratchDir dir;
  const std::string path = WriteSample(dir, 97, 33);
  int code = 0;
  const std::string out = test::RunTool(
      "exiftool -s -s -n -Make -Model -Software -DateTimeOriginal -ExifImageWidth "
      "-ExifImageHeight -FNumber -Warning -Error '" +
          path + "'",
      &code);
  EXPECT_EQ(code, 0);
  EXPECT_EQ(out,
            "Make: LensBlur\n"
            "Model: PS-1\n"
            "Software: lensblur 0.1\n"
            "DateTimeOriginal: 2026:11:23 18:30:05\n"
            "ExifImageWidth: 97\n"
            "ExifImageHeight: 33\n"
            "FNumber: 5.6\n");
  const std::string check =
      test::RunTool("exiftool -validate -warning -a -s -s '" + path + "'", &code);
  EXPECT_EQ(check, "Validate: OK\n");
}

}  // namespace
}  // namespace lb
