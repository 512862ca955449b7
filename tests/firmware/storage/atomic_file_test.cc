#include "firmware/storage/atomic_file.h"

#include <dirent.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "firmware/storage/temp_registry.h"
#include "tests/support/remove_tree.h"

namespace lb {
namespace {

// A fresh directory per test, removed with its contents afterwards.
class AtomicFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/lb_atomic_XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override { ASSERT_TRUE(lb::test::RemoveTree(dir_)) << dir_; }
  std::string Path(const char* name) const { return dir_ + "/" + name; }
  std::vector<std::string> Entries() const {
    std::vector<std::string> names;
    DIR* d = opendir(dir_.c_str());
    if (d == nullptr) return names;
    while (dirent* e = readdir(d)) {
      const std::string n = e->d_name;
      if (n != "." && n != "..") names.push_back(n);
    }
    closedir(d);
    return names;
  }
  static std::string ReadAll(const std::string& path) {
    std::string out;
    FILE* f = fopen(path.c_str(), "rb");
    if (f == nullptr) return "<missing>";
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof(buf), f)) > 0) out.append(buf, n);
    fclose(f);
    return out;
  }
  std::string dir_;
};

TEST_F(AtomicFileTest, CommitPublishesTheWholeFileReadableByAll) {
  const std::string path = Path("out.jpg");
  AtomicFile file;
  ASSERT_TRUE(file.Open(path.c_str()).ok());
  ASSERT_GE(file.fd(), 0);
  EXPECT_FALSE(access(path.c_str(), F_OK) == 0) << "final name visible before commit";
  ASSERT_EQ(Entries().size(), 1u);
  EXPECT_EQ(Entries()[0].rfind(".out.jpg.", 0), 0u) << Entries()[0];
  ASSERT_TRUE(file.Write("hello ", 6).ok());
  ASSERT_TRUE(file.Write("world", 5).ok());
  Status status = file.Commit();
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(ReadAll(path), "hello world");
  struct stat st;
  ASSERT_EQ(stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0644u);
  EXPECT_EQ(Entries(), std::vector<std::string>{"out.jpg"});
}

TEST_F(AtomicFileTest, ReplacesAnExistingFileOnlyAtCommit) {
  const std::string path = Path("x.jpg");
  {
    AtomicFile old;
    ASSERT_TRUE(old.Open(path.c_str()).ok());
    ASSERT_TRUE(old.Write("old", 3).ok());
    ASSERT_TRUE(old.Commit().ok());
  }
  AtomicFile file;
  ASSERT_TRUE(file.Open(path.c_str()).ok());
  ASSERT_TRUE(file.Write("new contents", 12).ok());
  EXPECT_EQ(ReadAll(path), "old");
  ASSERT_TRUE(file.Commit().ok());
  EXPECT_EQ(ReadAll(path), "new contents");
  EXPECT_EQ(Entries().size(), 1u);
}

// A new photo beside others: the commit refuses a taken name, even one taken after Open, and
// leaves the file that has it and no temporary.
TEST_F(AtomicFileTest, NeverReplaceRefusesATakenNameAtCommit) {
  const std::string path = Path("IMG_1.jpg");
  AtomicFile file;
  ASSERT_TRUE(file.Open(path.c_str()).ok());
  ASSERT_TRUE(file.Write("second", 6).ok());
  {
    AtomicFile first;
    ASSERT_TRUE(first.Open(path.c_str()).ok());
    ASSERT_TRUE(first.Write("first", 5).ok());
    ASSERT_TRUE(first.Commit(AtomicFile::Replace::kNever).ok());
  }
  const Status status = file.Commit(AtomicFile::Replace::kNever);
  EXPECT_EQ(status.code(), Code::kInvalidArgument) << status.message();
  EXPECT_NE(std::string(status.message()).find("IMG_1.jpg exists"), std::string::npos)
      << status.message();
  EXPECT_EQ(ReadAll(path), "first");
  EXPECT_EQ(Entries(), std::vector<std::string>{"IMG_1.jpg"});
  // A free name is written as by the default commit.
  AtomicFile other;
  ASSERT_TRUE(other.Open(Path("IMG_2.jpg").c_str()).ok());
  ASSERT_TRUE(other.Write("2", 1).ok());
  ASSERT_TRUE(other.Commit(AtomicFile::Replace::kNever).ok());
  EXPECT_EQ(ReadAll(Path("IMG_2.jpg")), "2");
  EXPECT_EQ(Entries().size(), 2u);
}

TEST_F(AtomicFileTest, AbortAndDestructorLeaveNothing) {
  {
    AtomicFile file;
    ASSERT_TRUE(file.Open(Path("a.jpg").c_str()).ok());
    ASSERT_TRUE(file.Write("partial", 7).ok());
  }
  AtomicFile file;
  ASSERT_TRUE(file.Open(Path("b.jpg").c_str()).ok());
  ASSERT_TRUE(file.Write("partial", 7).ok());
  file.Abort();
  EXPECT_TRUE(Entries().empty());
  EXPECT_FALSE(file.Write("x", 1).ok());
  EXPECT_FALSE(file.Commit().ok());
  // The same object can be used again after an abort.
  ASSERT_TRUE(file.Open(Path("b.jpg").c_str()).ok());
  ASSERT_TRUE(file.Commit().ok());
  EXPECT_EQ(Entries(), std::vector<std::string>{"b.jpg"});
}

TEST_F(AtomicFileTest, MissingDirectoryNamesThePathAndTheReason) {
  const std::string path = Path("missing/out.jpg");
  AtomicFile file;
  Status status = file.Open(path.c_str());
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.code(), Code::kNotFound);
  EXPECT_NE(std::string(status.message()).find(path), std::string::npos) << status.message();
  EXPECT_NE(std::string(status.message()).find("no such file or directory"), std::string::npos)
      << status.message();
  EXPECT_TRUE(Entries().empty());
}

TEST_F(AtomicFileTest, DirectoryThatIsARegularFileFails) {
  {
    AtomicFile blocker;
    ASSERT_TRUE(blocker.Open(Path("file").c_str()).ok());
    ASSERT_TRUE(blocker.Commit().ok());
  }
  const std::string path = Path("file/out.jpg");
  AtomicFile file;
  Status status = file.Open(path.c_str());
  ASSERT_FALSE(status.ok());
  EXPECT_NE(std::string(status.message()).find(path), std::string::npos) << status.message();
  EXPECT_NE(std::string(status.message()).find("not a directory"), std::string::npos)
      << status.message();
  EXPECT_EQ(Entries(), std::vector<std::string>{"file"});
}

TEST_F(AtomicFileTest, BadPathsAreRejected) {
  AtomicFile file;
  EXPECT_EQ(file.Open("").code(), Code::kInvalidArgument);
  EXPECT_EQ(file.Open(Path("dir/").c_str()).code(), Code::kInvalidArgument);
  const std::string long_path = Path(std::string(2000, 'a').c_str());
  EXPECT_EQ(file.Open(long_path.c_str()).code(), Code::kInvalidArgument);
  EXPECT_TRUE(Entries().empty());
}

TEST_F(AtomicFileTest, BareFileNameUsesTheCurrentDirectory) {
  char cwd[4096];
  ASSERT_NE(getcwd(cwd, sizeof(cwd)), nullptr);
  ASSERT_EQ(chdir(dir_.c_str()), 0);
  AtomicFile file;
  Status open = file.Open("plain.jpg");
  Status commit = open.ok() ? file.Commit() : open;
  ASSERT_EQ(chdir(cwd), 0);
  ASSERT_TRUE(commit.ok()) << commit.message();
  EXPECT_EQ(Entries(), std::vector<std::string>{"plain.jpg"});
}

// A full card, simulated with a file size limit in a child process: the write fails (EFBIG),
// nothing can be committed, and no file is left.
TEST_F(AtomicFileTest, FullDiskLeavesNoFile) {
  const std::string path = Path("full.jpg");
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    signal(SIGXFSZ, SIG_IGN);
    rlimit limit = {4096, 4096};
    if (setrlimit(RLIMIT_FSIZE, &limit) != 0) _exit(10);
    AtomicFile file;
    if (!file.Open(path.c_str()).ok()) _exit(11);
    std::vector<char> block(3000, 'x');
    if (!file.Write(block.data(), block.size()).ok()) _exit(12);  // fits
    Status full = file.Write(block.data(), block.size());
    if (full.ok()) _exit(13);
    if (std::string(full.message()).find(path + ": file too large") == std::string::npos) _exit(14);
    if (file.Commit().ok()) _exit(15);
    _exit(0);
  }
  int wstatus = 0;
  ASSERT_EQ(waitpid(pid, &wstatus, 0), pid);
  ASSERT_TRUE(WIFEXITED(wstatus));
  EXPECT_EQ(WEXITSTATUS(wstatus), 0);
  EXPECT_TRUE(Entries().empty());
}

// A command's SIGINT or SIGTERM (temp_registry.h) ends it, its temporary removed, until its
// file is committed; after that it finishes as if not interrupted, so an interrupted command
// never leaves a new file behind, nor dies once it has.
TEST_F(AtomicFileTest, ASignalEndsTheCommandUntilItsFileIsInPlaceNotAfter) {
  for (const bool commit_first : {false, true}) {
    const std::string path = Path(commit_first ? "kept.jpg" : "dropped.jpg");
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      RemoveTemporariesOnSignals();
      AtomicFile file;
      if (!file.Open(path.c_str()).ok() || !file.Write("jpeg", 4).ok()) _exit(11);
      if (commit_first && !file.Commit().ok()) _exit(12);
      raise(SIGTERM);
      _exit(0);
    }
    int wstatus = 0;
    ASSERT_EQ(waitpid(pid, &wstatus, 0), pid);
    if (commit_first) {
      EXPECT_TRUE(WIFEXITED(wstatus) && WEXITSTATUS(wstatus) == 0) << wstatus;
    } else {
      EXPECT_TRUE(WIFSIGNALED(wstatus) && WTERMSIG(wstatus) == SIGTERM) << wstatus;
    }
  }
  EXPECT_EQ(Entries(), std::vector<std::string>{"kept.jpg"});
}

}  // namespace
}  // namespace lb
