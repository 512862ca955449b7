// The one open every input goes through: a regular file reads, anything else is refused at once
// with its kind named (a FIFO with no writer would otherwise block the open for ever).
#include "firmware/storage/input_file.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <string>
#include <vector>

#include "tests/support/remove_tree.h"

namespace lb {
namespace {

class InputFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/lb_input_XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
    alarm(30);  // a blocking open fails the test instead of hanging it
  }
  void TearDown() override {
    alarm(0);
    (void)test::RemoveTree(dir_);
  }
  std::string dir_;
};

TEST_F(InputFileTest, ARegularFileOpensBlockingAndReads) {
  const std::string path = dir_ + "/a.ppm";
  FILE* f = fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  fputs("P6 1 1 255\n\1\2\3", f);
  fclose(f);
  int fd = -1;
  int64_t size = 0;
  Status s = OpenInputFile(path.c_str(), &fd, &size);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(size, 14);
  EXPECT_EQ(fcntl(fd, F_GETFL) & O_NONBLOCK, 0);
  EXPECT_NE(fcntl(fd, F_GETFD) & FD_CLOEXEC, 0);
  close(fd);
  std::vector<uint8_t> bytes;
  s = ReadInputFile(path.c_str(), 1024, &bytes);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(bytes.size(), 14u);
  s = ReadInputFile(path.c_str(), 10, &bytes);
  EXPECT_EQ(s.code(), Code::kInvalidArgument);
  EXPECT_TRUE(bytes.empty());
}

TEST_F(InputFileTest, AnythingButARegularFileIsRefusedNamingItsKind) {
  const std::string fifo = dir_ + "/fifo.jpg";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0644), 0);
  struct Case {
    std::string path, says;
    Code code;
  };
  for (const Case& c : {
           Case{fifo, fifo + ": not a regular file (a FIFO)", Code::kInvalidArgument},
           Case{dir_, dir_ + ": not a regular file (a folder)", Code::kInvalidArgument},
           Case{"/dev/null", "/dev/null: not a regular file (a device)", Code::kInvalidArgument},
           Case{dir_ + "/none", dir_ + "/none: no such file or directory", Code::kNotFound},
       }) {
    int fd = 7;
    const Status s = OpenInputFile(c.path.c_str(), &fd);
    EXPECT_EQ(s.code(), c.code) << c.path;
    EXPECT_EQ(std::string(s.message()).find(c.says), 0u) << s.message();
    EXPECT_EQ(fd, -1);
    std::vector<uint8_t> bytes;
    EXPECT_EQ(ReadInputFile(c.path.c_str(), 1024, &bytes).code(), c.code) << c.path;
  }
}

}  // namespace
}  // namespace lb
