// The photo folder check: every way a folder can be unusable gives one message naming it, and
// the checks hold for root too (the tests may run as root, whom permissions do not stop).
#include "firmware/daemon/startup_checks.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sched.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "tests/firmware/codecs/jpeg_test_util.h"

namespace lb {
namespace {

void Touch(const std::string& path) {
  FILE* f = fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr) << path;
  fclose(f);
}

TEST(CheckPhotoFolderTest, WritableFolderPassesAndKeepsNothing) {
  test::ScratchDir dir;
  Status s = CheckPhotoFolder(dir.dir().c_str());
  EXPECT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(dir.Entries(), std::vector<std::string>{});
}

TEST(CheckPhotoFolderTest, MissingFolderIsNamed) {
  test::ScratchDir dir;
  const std::string card = dir.Path("card");
  Status s = CheckPhotoFolder(card.c_str());
  EXPECT_EQ(s.code(), Code::kNotFound);
  EXPECT_STREQ(s.message(), ("output folder " + card + ": no such file or directory").c_str());
}

TEST(CheckPhotoFolderTest, FileWhereTheFolderShouldBe) {
  test::ScratchDir dir;
  const std::string card = dir.Path("card");
  Touch(card);
  Status s = CheckPhotoFolder(card.c_str());
  EXPECT_EQ(s.code(), Code::kNotFound);
  EXPECT_STREQ(s.message(), ("output folder " + card + ": not a folder (a regular file)").c_str());
}

TEST(CheckPhotoFolderTest, FolderUnderARegularFile) {
  test::ScratchDir dir;
  Touch(dir.Path("card"));
  const std::string photos = dir.Path("card/DCIM");
  Status s = CheckPhotoFolder(photos.c_str());
  EXPECT_EQ(s.code(), Code::kNotFound);
  EXPECT_STREQ(s.message(), ("output folder " + photos + ": not a directory").c_str());
}

TEST(CheckPhotoFolderTest, DeviceIsNoFolder) {
  Status s = CheckPhotoFolder("/dev/null");
  EXPECT_STREQ(s.message(), "output folder /dev/null: not a folder (a device)");
}

// A card mounted read-only (or remounted so after an error): refused even for root. Mounted in
// a private mount namespace of a child process (and a user namespace when not root), so nothing
// shows outside it; skipped where namespaces are not allowed (some containers, qemu-user).
TEST(CheckPhotoFolderTest, ReadOnlyMountIsNotWritable) {
  test::ScratchDir dir;
  const std::string card = dir.Path("card");
  ASSERT_EQ(mkdir(card.c_str(), 0755), 0);
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  const uid_t uid = geteuid();
  const gid_t gid = getegid();
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    close(fds[0]);
    auto report = [&](const char* text) {
      if (write(fds[1], text, strlen(text)) < 0) _exit(3);
      _exit(0);
    };
    if (unshare(CLONE_NEWNS) != 0) {
      if (unshare(CLONE_NEWUSER | CLONE_NEWNS) != 0) report("skip: no namespaces");
      char map[64];
      const int n = snprintf(map, sizeof(map), "0 %u 1", static_cast<unsigned>(uid));
      int f = open("/proc/self/uid_map", O_WRONLY);
      if (f < 0 || write(f, map, static_cast<size_t>(n)) != n) report("skip: no uid_map");
      close(f);
      f = open("/proc/self/setgroups", O_WRONLY);
      if (f >= 0 && write(f, "deny", 4) != 4) report("skip: no setgroups");
      if (f >= 0) close(f);
      const int m = snprintf(map, sizeof(map), "0 %u 1", static_cast<unsigned>(gid));
      f = open("/proc/self/gid_map", O_WRONLY);
      if (f < 0 || write(f, map, static_cast<size_t>(m)) != m) report("skip: no gid_map");
      close(f);
    }
    // Private first, so the mount below never propagates to the machine's namespace.
    if (mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0 ||
        mount("card", card.c_str(), "tmpfs", MS_RDONLY, nullptr) != 0) {
      report("skip: cannot mount");
    }
    report(CheckPhotoFolder(card.c_str()).message());
  }
  close(fds[1]);
  std::string got;
  char buf[512];
  for (ssize_t n; (n = read(fds[0], buf, sizeof(buf))) > 0;)
    got.append(buf, static_cast<size_t>(n));
  close(fds[0]);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  if (got.rfind("skip: ", 0) == 0) GTEST_SKIP() << got;
  EXPECT_EQ(got, "output folder " + card + ": cannot write in it: read-only file system");
  EXPECT_EQ(dir.Entries(), std::vector<std::string>{"card"});
}

}  // namespace
}  // namespace lb
