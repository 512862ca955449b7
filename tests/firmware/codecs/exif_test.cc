#include "firmware/codecs/exif.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "algo/motion/camera.h"
#include "firmware/codecs/jpeg_writer.h"
#include "tests/firmware/codecs/jpeg_test_util.h"

namespace lb {
namespace {

std::vector<uint8_t> Photo(const JpegMetadata& meta) {
  const test::Ycc420 img = test::MakeTexture(40, 24);
  std::vector<uint8_t> jpeg;
  JpegWriter writer;
  EXPECT_TRUE(writer.BeginMemory(&jpeg, img.width, img.height, 90, meta).ok());
  for (int32_t y = 0; y < img.height; y += 16) {
    const int32_t rows = img.height - y < 16 ? img.height - y : 16;
    EXPECT_TRUE(writer.WriteStrip(img.Strip(y, rows), rows).ok());
  }
  EXPECT_TRUE(writer.Finish().ok());
  return jpeg;
}

// A re-render reads the orientation from the bytes it already holds: it must find what a read
// of the file finds.
TEST(ExifTest, TagsReadFromMemoryAndFromTheFileAgree) {
  JpegMetadata meta;
  meta.orientation = 6;
  meta.focal_35mm = 28;
  const std::vector<uint8_t> jpeg = Photo(meta);
  test::ScratchDir dir;
  const std::string path = dir.Path("tagged.jpg");
  FILE* f = fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  ASSERT_EQ(fwrite(jpeg.data(), 1, jpeg.size(), f), jpeg.size());
  fclose(f);
  EXPECT_EQ(ExifOrientation(path.c_str()), 6);
  EXPECT_EQ(ExifOrientation(jpeg.data(), jpeg.size()), 6);
  EXPECT_DOUBLE_EQ(ExifFocalPx(path.c_str(), 4000, 3000), FocalPxFrom35mm(28, 4000, 3000));
}

TEST(ExifTest, NoTagsReadAsZero) {
  const std::vector<uint8_t> plain = Photo(JpegMetadata());  // JFIF, no EXIF
  EXPECT_EQ(ExifOrientation(plain.data(), plain.size()), 0);
  const uint8_t junk[] = {0xFF, 0xD8, 0xFF, 0xE1, 0x00, 0x02, 'E', 'x'};
  EXPECT_EQ(ExifOrientation(junk, sizeof(junk)), 0);
  EXPECT_EQ(ExifOrientation(nullptr, 0), 0);
  EXPECT_EQ(ExifOrientation("/nonexistent/photo.jpg"), 0);
  EXPECT_EQ(ExifFocalPx("/nonexistent/photo.jpg", 64, 48), 0);
}

TEST(ExifTest, BadTagsAreRefusedByName) {
  ExifTags tags;
  tags.datetime_original = "2024-01-02 03:04:05";
  std::vector<uint8_t> payload;
  const Status s = BuildExif(tags, 64, 48, &payload);
  EXPECT_EQ(s.code(), Code::kInvalidArgument);
  EXPECT_NE(std::string(s.message()).find("DateTimeOriginal"), std::string::npos) << s.message();
  EXPECT_TRUE(payload.empty());
  EXPECT_FALSE(tags.has_exif() && ExifTags().has_exif());
}

}  // namespace
}  // namespace lb
