// Photo names: IMG_YYYYMMDD_HHMMSS_NNNN.jpg, unique, never an existing file, continuing across
// restarts; and the clean-up of temporaries a killed run left behind.
#include "firmware/daemon/photo_namer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "tests/firmware/codecs/jpeg_test_util.h"

namespace lb {
namespace {

tm PiDay() {
  tm t = {};
  t.tm_year = 2026 - 1900;
  t.tm_mon = 2;
  t.tm_mday = 14;
  t.tm_hour = 15;
  t.tm_min = 9;
  t.tm_sec = 26;
  return t;
}

void Touch(const std::string& path) {
  FILE* f = fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr) << path;
  fputs("x", f);
  fclose(f);
}

bool Exists(const test::ScratchDir& dir, const std::string& name) {
  const auto entries = dir.Entries();
  return std::find(entries.begin(), entries.end(), name) != entries.end();
}

std::string NextName(PhotoNamer& namer, const test::ScratchDir& dir) {
  char path[1024];
  Status s = namer.Next(PiDay(), path, sizeof(path));
  EXPECT_TRUE(s.ok()) << s.message();
  return std::string(path).substr(dir.dir().size() + 1);
}

TEST(PhotoNamerTest, NamesByLocalTimeAndCounter) {
  test::ScratchDir dir;
  PhotoNamer namer;
  int removed = -1;
  ASSERT_TRUE(namer.Scan(dir.dir().c_str(), &removed).ok());
  EXPECT_EQ(removed, 0);
  EXPECT_EQ(NextName(namer, dir), "IMG_20260314_150926_0001.jpg");
  // Not used yet (the photo failed): the number is offered again.
  EXPECT_EQ(NextName(namer, dir), "IMG_20260314_150926_0001.jpg");
  namer.Used();
  EXPECT_EQ(NextName(namer, dir), "IMG_20260314_150926_0002.jpg");
}

TEST(PhotoNamerTest, NeverOffersAnExistingName) {
  test::ScratchDir dir;
  PhotoNamer namer;
  int removed = 0;
  ASSERT_TRUE(namer.Scan(dir.dir().c_str(), &removed).ok());
  // Appeared after the scan (copied onto the card by hand, say).
  Touch(dir.Path("IMG_20260314_150926_0001.jpg"));
  Touch(dir.Path("IMG_20260314_150926_0002.jpg"));
  EXPECT_EQ(NextName(namer, dir), "IMG_20260314_150926_0003.jpg");
}

TEST(PhotoNamerTest, ContinuesAfterTheHighestNumberAndWraps) {
  test::ScratchDir dir;
  Touch(dir.Path("IMG_20250101_000000_0041.jpg"));
  Touch(dir.Path("IMG_20250101_000000_0007.jpg"));
  Touch(dir.Path("IMG_20250101_000000_9000.txt"));  // not a photo name
  PhotoNamer namer;
  int removed = 0;
  ASSERT_TRUE(namer.Scan(dir.dir().c_str(), &removed).ok());
  EXPECT_EQ(namer.next_counter(), 42);

  Touch(dir.Path("IMG_20250101_000000_9999.jpg"));
  ASSERT_TRUE(namer.Scan(dir.dir().c_str(), &removed).ok());
  EXPECT_EQ(namer.next_counter(), 1);
}

TEST(PhotoNamerTest, ScanRemovesOnlyStaleTemporaries) {
  test::ScratchDir dir;
  Touch(dir.Path(".IMG_20260314_150926_0003.jpg.a1B2c3"));
  Touch(dir.Path(".IMG_20260314_150926_0004.jpg.Zz9yX8"));
  Touch(dir.Path(".hidden"));
  Touch(dir.Path(".IMG_notes.jpg.abcdef"));
  Touch(dir.Path("IMG_20260314_150926_0002.jpg"));
  PhotoNamer namer;
  int removed = 0;
  ASSERT_TRUE(namer.Scan(dir.dir().c_str(), &removed).ok());
  EXPECT_EQ(removed, 2);
  EXPECT_FALSE(Exists(dir, ".IMG_20260314_150926_0003.jpg.a1B2c3"));
  EXPECT_FALSE(Exists(dir, ".IMG_20260314_150926_0004.jpg.Zz9yX8"));
  EXPECT_TRUE(Exists(dir, ".hidden"));
  EXPECT_TRUE(Exists(dir, ".IMG_notes.jpg.abcdef"));
  EXPECT_TRUE(Exists(dir, "IMG_20260314_150926_0002.jpg"));
  EXPECT_EQ(namer.next_counter(), 3);
}

TEST(PhotoNamerTest, MissingFolderIsNotAnErrorAtScan) {
  PhotoNamer namer;
  int removed = -1;
  Status s = namer.Scan("/nonexistent/card/DCIM", &removed);
  EXPECT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(removed, 0);
  char path[1024];
  ASSERT_TRUE(namer.Next(PiDay(), path, sizeof(path)).ok());
  EXPECT_STREQ(path, "/nonexistent/card/DCIM/IMG_20260314_150926_0001.jpg");
}

TEST(PhotoNamerTest, RecognisesNames) {
  int32_t n = 0;
  EXPECT_TRUE(PhotoNamer::IsPhotoName("IMG_20260314_150926_0123.jpg", &n));
  EXPECT_EQ(n, 123);
  EXPECT_FALSE(PhotoNamer::IsPhotoName("IMG_20260314_150926_123.jpg", &n));
  EXPECT_FALSE(PhotoNamer::IsPhotoName("IMG_2026031a_150926_0123.jpg", &n));
  EXPECT_FALSE(PhotoNamer::IsPhotoName("IMG_20260314_150926_0123.jpeg", &n));
  EXPECT_TRUE(PhotoNamer::IsTemporaryName(".IMG_20260314_150926_0123.jpg.XyZ123"));
  EXPECT_FALSE(PhotoNamer::IsTemporaryName(".IMG_20260314_150926_0123.jpg"));
  EXPECT_FALSE(PhotoNamer::IsTemporaryName("IMG_20260314_150926_0123.jpg.XyZ123"));
}

}  // namespace
}  // namespace lb
