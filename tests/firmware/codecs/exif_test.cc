#include "firmware/codecs/exif.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

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
  // From an open descriptor (the thumbnails'): the same, and where it stands does not move.
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(lseek(fd, 5, SEEK_SET), 5);
  EXPECT_EQ(ExifOrientationAt(fd), 6);
  EXPECT_EQ(lseek(fd, 0, SEEK_CUR), 5);
  close(fd);
  EXPECT_EQ(ExifOrientationAt(fd), 0) << "a closed descriptor reads as no tag";
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

// Where a viewer shows the stored image's top-left corner and a point near it, per EXIF 2.3's
// description of each orientation (the 0th row and column), and the way back.
TEST(ExifTest, OrientationMapsPointsAsAViewerTurnsThem) {
  struct Case {
    int32_t o;
    double u, v;  // where stored (0.25, 0.125) is displayed
  };
  const Case cases[] = {{0, 0.25, 0.125}, {1, 0.25, 0.125}, {2, 0.75, 0.125},
                        {3, 0.75, 0.875}, {4, 0.25, 0.875}, {5, 0.125, 0.25},
                        {6, 0.875, 0.25}, {7, 0.875, 0.75}, {8, 0.125, 0.75}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.o);
    double u = -1, v = -1, s = -1, t = -1;
    ExifStoredToDisplayed(c.o, 0.25, 0.125, &u, &v);
    EXPECT_DOUBLE_EQ(u, c.u);
    EXPECT_DOUBLE_EQ(v, c.v);
    ExifDisplayedToStored(c.o, u, v, &s, &t);
    EXPECT_DOUBLE_EQ(s, 0.25);
    EXPECT_DOUBLE_EQ(t, 0.125);
    EXPECT_EQ(ExifSwapsSides(c.o), c.o >= 5);
  }
}

}  // namespace
}  // namespace lb
