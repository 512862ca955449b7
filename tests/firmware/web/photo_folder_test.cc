// The photo folder as the web side sees it: which names can be asked for, the listing, the
// re-render names, and that a symbolic link is never followed.
#include "firmware/web/photo_folder.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <string>

#include "tests/firmware/codecs/jpeg_test_util.h"

namespace lb {
namespace {

void WriteFile(const std::string& path, const std::string& text) {
  FILE* f = fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr) << path;
  fwrite(text.data(), 1, text.size(), f);
  fclose(f);
}

TEST(PhotoFolderTest, OnlyPlainJpegNamesAreServable) {
  for (const char* ok : {"IMG_20260101_120000_0001.jpg", "a.JPG", "x-y.z.jpeg", "b.JpEg"}) {
    EXPECT_TRUE(IsServablePhotoName(ok)) << ok;
  }
  const std::string long_name = std::string(125, 'a') + ".jpg";  // 129 characters
  for (const char* bad :
       {"", ".jpg", ".hidden.jpg", "../a.jpg", "a/b.jpg", "/etc/a.jpg", "a.jpg/", "a.png",
        "a.jpg.txt", "a b.jpg", "a%2f.jpg", "a\\b.jpg", "..", "a.jpg\n", long_name.c_str()}) {
    EXPECT_FALSE(IsServablePhotoName(bad)) << bad;
  }
  EXPECT_TRUE(IsServablePhotoName(long_name.substr(1).c_str()));  // 128 is the limit
}

TEST(PhotoFolderTest, OpenRefusesLinksFoldersAndBadNames) {
  test::ScratchDir dir, outside;
  WriteFile(outside.Path("secret.jpg"), "outside");
  WriteFile(dir.Path("a.jpg"), "inside");
  ASSERT_EQ(symlink(outside.Path("secret.jpg").c_str(), dir.Path("link.jpg").c_str()), 0);
  ASSERT_EQ(mkdir(dir.Path("d.jpg").c_str(), 0755), 0);
  int dir_fd = -1;
  ASSERT_TRUE(OpenPhotoFolder(dir.dir().c_str(), &dir_fd).ok());
  int fd = -1;
  struct stat st;
  Status s = OpenPhoto(dir_fd, "a.jpg", &fd, &st);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(st.st_size, 6);
  close(fd);
  EXPECT_EQ(OpenPhoto(dir_fd, "link.jpg", &fd, &st).code(), Code::kInvalidArgument);
  EXPECT_EQ(fd, -1);
  EXPECT_EQ(OpenPhoto(dir_fd, "d.jpg", &fd, &st).code(), Code::kInvalidArgument);
  EXPECT_EQ(OpenPhoto(dir_fd, "none.jpg", &fd, &st).code(), Code::kNotFound);
  EXPECT_EQ(OpenPhoto(dir_fd, "../secret.jpg", &fd, &st).code(), Code::kInvalidArgument);
  close(dir_fd);
  EXPECT_EQ(OpenPhotoFolder(dir.Path("missing").c_str(), &dir_fd).code(), Code::kNotFound);
}

TEST(PhotoFolderTest, RerenderNamesContinueAndNeverReuseAName) {
  test::ScratchDir dir;
  int dir_fd = -1;
  ASSERT_TRUE(OpenPhotoFolder(dir.dir().c_str(), &dir_fd).ok());
  char out[kMaxPhotoName + 1];
  ASSERT_TRUE(ChooseRerenderName(dir_fd, "IMG_1_0001.jpg", out, sizeof(out)).ok());
  EXPECT_STREQ(out, "IMG_1_0001_r1.jpg");
  WriteFile(dir.Path("IMG_1_0001_r1.jpg"), "x");
  ASSERT_TRUE(ChooseRerenderName(dir_fd, "IMG_1_0001.jpg", out, sizeof(out)).ok());
  EXPECT_STREQ(out, "IMG_1_0001_r2.jpg");
  // From a re-render: the next number, not _r1_r1.
  ASSERT_TRUE(ChooseRerenderName(dir_fd, "IMG_1_0001_r1.jpg", out, sizeof(out)).ok());
  EXPECT_STREQ(out, "IMG_1_0001_r2.jpg");
  // Any entry, even a dangling link, takes the name.
  ASSERT_EQ(symlink("/nonexistent", dir.Path("IMG_1_0001_r2.jpg").c_str()), 0);
  ASSERT_TRUE(ChooseRerenderName(dir_fd, "IMG_1_0001.jpg", out, sizeof(out)).ok());
  EXPECT_STREQ(out, "IMG_1_0001_r3.jpg");
  ASSERT_TRUE(ChooseRerenderName(dir_fd, "photo.JPEG", out, sizeof(out)).ok());
  EXPECT_STREQ(out, "photo_r1.JPEG");
  const std::string longest = std::string(124, 'a') + ".jpg";
  EXPECT_EQ(ChooseRerenderName(dir_fd, longest.c_str(), out, sizeof(out)).code(),
            Code::kInvalidArgument);
  close(dir_fd);
}

}  // namespace
}  // namespace lb
