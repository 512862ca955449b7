// Thumbnails: decoded from the photo's own main image, about 320 px wide, small, and showing
// the picture (dark left half stays dark, bright right half bright).
#include "firmware/web/thumbnail.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <string>
#include <vector>

#include "firmware/codecs/exif.h"
#include "firmware/codecs/jpeg_writer.h"
#include "tests/firmware/codecs/jpeg_test_util.h"
#include "tests/firmware/codecs/test_images.h"

namespace lb {
namespace {

// Luma 40 on the left half, 210 on the right, neutral chroma.
std::vector<uint8_t> HalfAndHalf(int32_t w, int32_t h) {
  test::Ycc420 img = test::MakeTexture(w, h);
  for (int32_t y = 0; y < h; ++y) {
    for (int32_t x = 0; x < w; ++x) img.y[static_cast<size_t>(y * w + x)] = x < w / 2 ? 40 : 210;
  }
  std::fill(img.cb.begin(), img.cb.end(), 128);
  std::fill(img.cr.begin(), img.cr.end(), 128);
  std::vector<uint8_t> jpeg;
  EXPECT_TRUE(EncodeYCbCr420(img.View(), 90, &jpeg).ok());
  return jpeg;
}

struct Thumb {
  int32_t w = 0, h = 0;
  std::vector<uint8_t> ycc, jpeg;
};

Thumb ThumbOf(const std::vector<uint8_t>& jpeg, const test::ScratchDir& dir) {
  const std::string path = dir.Path("p.jpg");
  FILE* f = fopen(path.c_str(), "wb");
  fwrite(jpeg.data(), 1, jpeg.size(), f);
  fclose(f);
  Thumb t;
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  Status s = MakeThumbnail(fd, 320, 80, &t.jpeg);
  close(fd);
  EXPECT_TRUE(s.ok()) << s.message();
  std::string error;
  EXPECT_TRUE(test::DecodeYcc(t.jpeg, &t.w, &t.h, &t.ycc, &error)) << error;
  return t;
}

TEST(ThumbnailTest, ShrinksToAbout320AndKeepsThePicture) {
  test::ScratchDir dir;
  const std::vector<uint8_t> photo = HalfAndHalf(1280, 960);
  const Thumb t = ThumbOf(photo, dir);
  EXPECT_EQ(t.w, 320);
  EXPECT_EQ(t.h, 240);
  EXPECT_LT(t.jpeg.size(), photo.size() / 4);
  EXPECT_LT(t.jpeg.size(), 20000u);
  const auto luma = [&](int32_t x, int32_t y) {
    return t.ycc[static_cast<size_t>(y * t.w + x) * 3];
  };
  EXPECT_NEAR(luma(40, 120), 40, 6);
  EXPECT_NEAR(luma(280, 120), 210, 6);
}

TEST(ThumbnailTest, OddSizesAndSmallPhotos) {
  test::ScratchDir dir;
  const Thumb big = ThumbOf(HalfAndHalf(3000, 2000), dir);  // 1/8 gives 375: averaged to 320
  EXPECT_EQ(big.w, 320);
  EXPECT_EQ(big.h, 213);
  const Thumb small = ThumbOf(HalfAndHalf(200, 100), dir);  // narrower: kept
  EXPECT_EQ(small.w, 200);
  EXPECT_EQ(small.h, 100);
}

TEST(ThumbnailTest, CarriesThePhotosOrientation) {
  test::ScratchDir dir;
  std::vector<uint8_t> photo = HalfAndHalf(640, 480);
  const Thumb plain = ThumbOf(photo, dir);
  EXPECT_EQ(ExifOrientation(plain.jpeg.data(), plain.jpeg.size()), 0) << "none recorded";
  // The same photo with EXIF Orientation 6 (turn 90 degrees clockwise) right after SOI.
  ExifTags tags;
  tags.orientation = 6;
  std::vector<uint8_t> exif;
  ASSERT_TRUE(BuildExif(tags, 640, 480, &exif).ok());
  const size_t length = exif.size() + 2;
  std::vector<uint8_t> app1 = {0xff, 0xe1, static_cast<uint8_t>(length >> 8),
                               static_cast<uint8_t>(length)};
  app1.insert(app1.end(), exif.begin(), exif.end());
  photo.insert(photo.begin() + 2, app1.begin(), app1.end());
  ASSERT_EQ(ExifOrientation(photo.data(), photo.size()), 6);
  const Thumb t = ThumbOf(photo, dir);
  EXPECT_EQ(t.w, 320) << "the pixels stay as stored";
  EXPECT_EQ(ExifOrientation(t.jpeg.data(), t.jpeg.size()), 6);
  // Behind 300 KB of other APP segments (an ICC profile, say) the orientation is still found.
  std::vector<uint8_t> app2 = {0xff, 0xe2, 0xff, 0xff};
  app2.resize(2 + 0xffff, 0x5a);
  for (int i = 0; i < 5; ++i) photo.insert(photo.begin() + 2, app2.begin(), app2.end());
  ASSERT_EQ(ExifOrientation(photo.data(), photo.size()), 6);
  const Thumb behind = ThumbOf(photo, dir);
  EXPECT_EQ(ExifOrientation(behind.jpeg.data(), behind.jpeg.size()), 6);
}

TEST(ThumbnailTest, AGreyPhotoGivesAGreyThumbnail) {
  test::ScratchDir dir;
  const int32_t w = 640, h = 480;
  std::vector<uint8_t> grey(static_cast<size_t>(w) * h);
  for (int32_t y = 0; y < h; ++y)
    for (int32_t x = 0; x < w; ++x) grey[static_cast<size_t>(y * w + x)] = x < w / 2 ? 40 : 210;
  test::Bytes photo;
  ASSERT_TRUE(test::EncodeJpeg(w, h, 1, grey.data(), 90, false, &photo));
  const Thumb t = ThumbOf(photo, dir);
  EXPECT_EQ(t.w, 320);
  EXPECT_EQ(t.h, 240);
  const auto at = [&](int32_t x, int32_t y, int c) {
    return t.ycc[static_cast<size_t>(y * t.w + x) * 3 + c];
  };
  EXPECT_NEAR(at(40, 120, 0), 40, 6);
  EXPECT_NEAR(at(280, 120, 0), 210, 6);
  EXPECT_NEAR(at(280, 120, 1), 128, 2) << "no colour";
  EXPECT_NEAR(at(280, 120, 2), 128, 2) << "no colour";
}

TEST(ThumbnailTest, CorruptBytesAreAnError) {
  test::ScratchDir dir;
  std::vector<uint8_t> photo = HalfAndHalf(320, 240);
  photo.resize(photo.size() / 2);
  const std::string path = dir.Path("cut.jpg");
  FILE* f = fopen(path.c_str(), "wb");
  fwrite(photo.data(), 1, photo.size(), f);
  fclose(f);
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  std::vector<uint8_t> out;
  EXPECT_EQ(MakeThumbnail(fd, 320, 80, &out).code(), Code::kCorruptData);
  close(fd);
  EXPECT_TRUE(out.empty());
}

}  // namespace
}  // namespace lb
