// The fixture the `refocus` command-line tests share: runs the real binary as a user would, in a
// fresh folder with an empty out/ subfolder, and reads what it said.
#pragma once

#include <dirent.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "tests/firmware/codecs/test_images.h"
#include "tests/support/remove_tree.h"

namespace lb::clitest {

struct Result {
  int exit_code = -1;
  std::string out, err;
};

std::string Slurp(const std::string& path) {
  std::string s;
  if (FILE* f = fopen(path.c_str(), "rb")) {
    char buf[4096];
    for (size_t n; (n = fread(buf, 1, sizeof(buf), f)) > 0;) s.append(buf, n);
    fclose(f);
  }
  return s;
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/refocus-cli-XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
    out_dir_ = dir_ + "/out";
    ASSERT_EQ(mkdir(out_dir_.c_str(), 0755), 0);
  }
  void TearDown() override { (void)lb::test::RemoveTree(dir_); }

  Result Run(const std::vector<std::string>& args) {
    std::string cmd = REFOCUS_BIN;
    for (const auto& a : args) cmd += " '" + a + "'";
    cmd += " >" + dir_ + "/stdout 2>" + dir_ + "/stderr";
    Result r;
    const int status = system(cmd.c_str());
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = Slurp(dir_ + "/stdout");
    r.err = Slurp(dir_ + "/stderr");
    return r;
  }

  // Run, measuring the child's peak resident memory (KiB) with wait4.
  Result RunMeasured(const std::vector<std::string>& args, long* max_rss_kib) {
    Result r;
    fflush(nullptr);  // the child would write out our buffered output again
    const pid_t pid = fork();
    if (pid < 0) return r;
    if (pid == 0) {
      if (!freopen((dir_ + "/stdout").c_str(), "w", stdout)) _exit(126);
      if (!freopen((dir_ + "/stderr").c_str(), "w", stderr)) _exit(126);
      std::vector<char*> argv = {const_cast<char*>(REFOCUS_BIN)};
      for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      execv(REFOCUS_BIN, argv.data());
      _exit(127);
    }
    int status = 0;
    rusage usage = {};
    if (wait4(pid, &status, 0, &usage) != pid) return r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = Slurp(dir_ + "/stdout");
    r.err = Slurp(dir_ + "/stderr");
    *max_rss_kib = usage.ru_maxrss;
    return r;
  }

  // A valid W x H RGB burst of `n` PPM files; returns their paths.
  std::vector<std::string> PpmBurst(int n, int w, int h) {
    std::vector<std::string> paths;
    for (int i = 0; i < n; ++i) {
      std::vector<uint16_t> samples(static_cast<size_t>(w) * h * 3);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          for (int c = 0; c < 3; ++c) samples[(y * w + x) * 3 + c] = test::Smooth(x + 2 * i, y, c);
      paths.push_back(dir_ + "/f" + std::to_string(i) + ".ppm");
      EXPECT_TRUE(test::WriteFile(paths.back(), test::EncodePnm("P6", w, h, 255, samples)));
    }
    return paths;
  }

  // The bad-input contract: exit 1, one line naming `names` and `problem`, no output file.
  void ExpectCleanFailure(const Result& r, const std::string& names, const std::string& problem) {
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(names), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(problem), std::string::npos) << r.err;
    EXPECT_TRUE(OutDirEmpty()) << "a file was left in " << out_dir_;
  }

  bool OutDirEmpty() {
    DIR* d = opendir(out_dir_.c_str());
    if (!d) return true;
    int entries = 0;
    while (dirent* e = readdir(d)) entries += e->d_name[0] != '.' || e->d_name[1] > '.';
    closedir(d);
    return entries == 0;
  }

  std::string Out() const { return out_dir_ + "/photo.jpg"; }

  std::string dir_, out_dir_;
};

}  // namespace lb::clitest
