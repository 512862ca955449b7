// The rule for every file the product writes (output_target.h, temp_registry.h): only an absent
// or regular target, never an input, a folder that exists; nothing renamed over a device, a
// FIFO or a link; no hidden temporary left by a signal.
#include "firmware/storage/output_target.h"

#include <dirent.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "firmware/storage/atomic_file.h"
#include "firmware/storage/temp_registry.h"
#include "tests/support/remove_tree.h"

namespace lb {
namespace {

class OutputTargetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/lb_target_XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override { ASSERT_TRUE(lb::test::RemoveTree(dir_)) << dir_; }
  std::string Path(const char* name) const { return dir_ + "/" + name; }
  void Touch(const std::string& path, const char* text = "old") {
    FILE* f = fopen(path.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    fputs(text, f);
    fclose(f);
  }
  int Entries() const {
    int n = 0;
    DIR* d = opendir(dir_.c_str());
    while (dirent* e = readdir(d))
      n += e->d_name[0] != '.' || (e->d_name[1] && e->d_name[1] != '.');
    closedir(d);
    return n;
  }
  std::string dir_;
};

TEST_F(OutputTargetTest, AbsentAndRegularTargetsPass) {
  EXPECT_TRUE(CheckOutputTarget(Path("new.jpg").c_str(), nullptr, 0).ok());
  Touch(Path("old.jpg"));
  EXPECT_TRUE(CheckOutputTarget(Path("old.jpg").c_str(), nullptr, 0).ok());
}

TEST_F(OutputTargetTest, DevicesFifosFoldersAndLinksAreRefused) {
  ASSERT_EQ(mkfifo(Path("fifo").c_str(), 0644), 0);
  Touch(Path("photo.jpg"));
  ASSERT_EQ(symlink(Path("photo.jpg").c_str(), Path("link.jpg").c_str()), 0);
  for (const std::string& p : {std::string("/dev/null"), Path("fifo"), dir_, Path("link.jpg")}) {
    const Status s = CheckOutputTarget(p.c_str(), nullptr, 0);
    EXPECT_EQ(s.code(), Code::kInvalidArgument) << p;
    EXPECT_NE(std::string(s.message()).find(p), std::string::npos) << s.message();
  }
}

TEST_F(OutputTargetTest, AnInputIsRefusedUnderAnyName) {
  Touch(Path("frame0.ppm"));
  ASSERT_EQ(link(Path("frame0.ppm").c_str(), Path("alias.jpg").c_str()), 0);
  const std::string in = Path("frame0.ppm");
  const char* inputs[] = {in.c_str()};
  EXPECT_EQ(CheckOutputTarget(in.c_str(), inputs, 1).code(), Code::kInvalidArgument);
  const Status s = CheckOutputTarget(Path("alias.jpg").c_str(), inputs, 1);
  EXPECT_EQ(s.code(), Code::kInvalidArgument);
  EXPECT_NE(std::string(s.message()).find("frame0.ppm"), std::string::npos) << s.message();
  EXPECT_TRUE(CheckOutputTarget(Path("other.jpg").c_str(), inputs, 1).ok());
}

TEST_F(OutputTargetTest, AMissingFolderIsNamed) {
  const std::string p = Path("no/such/x.jpg");
  const Status s = CheckOutputTarget(p.c_str(), nullptr, 0);
  EXPECT_EQ(s.code(), Code::kNotFound);
  EXPECT_NE(std::string(s.message()).find(Path("no/such")), std::string::npos) << s.message();
  Touch(Path("file"));
  EXPECT_EQ(CheckOutputTarget(Path("file/x.jpg").c_str(), nullptr, 0).code(), Code::kNotFound);
}

TEST_F(OutputTargetTest, CommitNeverRenamesOverAFifoThatAppearedMeanwhile) {
  AtomicFile f;
  ASSERT_TRUE(f.Open(Path("x.jpg").c_str()).ok());
  ASSERT_TRUE(f.Write("data", 4).ok());
  ASSERT_EQ(mkfifo(Path("x.jpg").c_str(), 0644), 0);
  EXPECT_EQ(f.Commit().code(), Code::kInvalidArgument);
  struct stat st;
  ASSERT_EQ(lstat(Path("x.jpg").c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode)) << "the FIFO is still there";
  EXPECT_EQ(Entries(), 1) << "no temporary left";
}

TEST_F(OutputTargetTest, ASignalRemovesTheTemporariesInFlight) {
  Touch(Path("photo.jpg"), "the old photo");
  for (int sig : {SIGINT, SIGTERM}) {
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      RemoveTemporariesOnSignals();
      AtomicFile a, b;
      if (!a.Open(Path("photo.jpg").c_str()).ok() || !b.Open(Path("other.jpg").c_str()).ok()) {
        _exit(3);
      }
      (void)a.Write("half a photo", 12);
      raise(sig);
      _exit(4);  // not reached: the handler ends the process by the signal
    }
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFSIGNALED(status)) << "exit " << WEXITSTATUS(status);
    EXPECT_EQ(WTERMSIG(status), sig);
    EXPECT_EQ(Entries(), 1) << "only the old photo";
    FILE* f = fopen(Path("photo.jpg").c_str(), "rb");
    ASSERT_NE(f, nullptr);
    char buf[32] = {};
    EXPECT_EQ(fread(buf, 1, sizeof(buf) - 1, f), 13u);
    fclose(f);
    EXPECT_STREQ(buf, "the old photo");
  }
}

TEST(TempRegistry, ForgetsWhatWasRemovedAndRefusesWhenFull) {
  for (int i = 0; i < temp_registry::kSlots; ++i) {
    EXPECT_TRUE(temp_registry::Add(("/tmp/lb_registry_" + std::to_string(i)).c_str()));
  }
  EXPECT_FALSE(temp_registry::Add("/tmp/lb_registry_one_too_many"));
  temp_registry::Remove("/tmp/lb_registry_3");
  EXPECT_TRUE(temp_registry::Add("/tmp/lb_registry_again"));
  for (int i = 0; i < temp_registry::kSlots; ++i) {
    temp_registry::Remove(("/tmp/lb_registry_" + std::to_string(i)).c_str());
  }
  temp_registry::Remove("/tmp/lb_registry_again");
  EXPECT_TRUE(temp_registry::Add("/tmp/lb_registry_last"));
  temp_registry::Remove("/tmp/lb_registry_last");
}

}  // namespace
}  // namespace lb
