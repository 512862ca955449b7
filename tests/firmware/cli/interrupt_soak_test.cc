// `refocus run` and `rerender` interrupted by SIGINT or SIGTERM at random
// moments (50 runs) leave no hidden temporary in the output folder, and the photo already
// under the output name is intact: the old bytes, or the new photo whole when the run got
// there first. Release only (label soak).
#include <dirent.h>
#include <signal.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "tests/support/remove_tree.h"

namespace lb {
namespace {

std::string Slurp(const std::string& path) {
  std::string s;
  if (FILE* f = fopen(path.c_str(), "rb")) {
    char buf[65536];
    for (size_t n; (n = fread(buf, 1, sizeof(buf), f)) > 0;) s.append(buf, n);
    fclose(f);
  }
  return s;
}

double Now() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

// Starts refocus with `args` (output to /dev/null), sends `sig` after `delay_s` unless it
// ended first; returns the wait status.
int RunAndInterrupt(const std::vector<std::string>& args, int sig, double delay_s) {
  const pid_t pid = fork();
  if (pid == 0) {
    if (!freopen("/dev/null", "w", stdout) || !freopen("/dev/null", "w", stderr)) _exit(126);
    std::vector<char*> argv = {const_cast<char*>(REFOCUS_BIN)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(REFOCUS_BIN, argv.data());
    _exit(127);
  }
  int status = 0;
  const double until = Now() + delay_s;
  while (Now() < until) {
    if (waitpid(pid, &status, WNOHANG) == pid) return status;
    usleep(500);
  }
  kill(pid, sig);
  waitpid(pid, &status, 0);
  return status;
}

bool WholeJpeg(const std::string& s) {
  return s.size() > 4 && static_cast<uint8_t>(s[0]) == 0xff && static_cast<uint8_t>(s[1]) == 0xd8 &&
         static_cast<uint8_t>(s[s.size() - 2]) == 0xff &&
         static_cast<uint8_t>(s[s.size() - 1]) == 0xd9;
}

std::vector<std::string> Hidden(const std::string& dir) {
  std::vector<std::string> out;
  DIR* d = opendir(dir.c_str());
  while (dirent* e = d ? readdir(d) : nullptr) {
    const std::string n = e->d_name;
    if (n != "." && n != ".." && n[0] == '.') out.push_back(n);
  }
  if (d) closedir(d);
  return out;
}

TEST(InterruptSoak, NoTemporaryLeftAndTheOldPhotoIntact) {
  char tmpl[] = "/tmp/refocus-interrupt-XXXXXX";
  ASSERT_NE(mkdtemp(tmpl), nullptr);
  const std::string dir = tmpl, out = dir + "/photo.jpg", src = dir + "/src.jpg";
  const std::vector<std::string> run = {"run", "--synthetic", "--size", "1280x960", "--out", out};
  const std::vector<std::string> rerender = {"rerender", src, "--focus", "100,100", "--out", out};
  // The source photo, and how long each command takes here.
  double t0 = Now();
  ASSERT_EQ(RunAndInterrupt({"run", "--synthetic", "--size", "1280x960", "--out", src}, 0, 1e9), 0);
  const double run_s = Now() - t0;
  t0 = Now();
  ASSERT_EQ(RunAndInterrupt(rerender, 0, 1e9), 0);
  const double rerender_s = Now() - t0;
  std::mt19937 rng(20261201);
  std::uniform_real_distribution<double> when(0.0, 1.1);
  // On a shared machine one command can take twice as long as the next: a run that finished
  // before its signal says how long it takes now, and the shortest seen sets the next delays.
  double took[2] = {rerender_s, run_s};
  int interrupted = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const std::string old = Slurp(out);
    ASSERT_TRUE(WholeJpeg(old));
    const bool is_run = trial % 2 == 0;
    const int sig = trial % 4 < 2 ? SIGINT : SIGTERM;
    const double delay = when(rng) * took[is_run];
    const double start = Now();
    const int status = RunAndInterrupt(is_run ? run : rerender, sig, delay);
    const bool killed = WIFSIGNALED(status) && WTERMSIG(status) == sig;
    if (!killed && Now() - start < took[is_run]) took[is_run] = Now() - start;
    EXPECT_TRUE(killed || (WIFEXITED(status) && WEXITSTATUS(status) == 0))
        << "trial " << trial << ": status " << status;
    interrupted += killed;
    EXPECT_EQ(Hidden(dir), std::vector<std::string>{})
        << "trial " << trial << " after " << delay << " s";
    const std::string now = Slurp(out);
    EXPECT_TRUE(now == old || (!killed && WholeJpeg(now)))
        << "trial " << trial << ": the photo changed although the run was interrupted";
  }
  printf("50 runs: %d interrupted (run %.2f s, rerender %.2f s uninterrupted)\n", interrupted,
         run_s, rerender_s);
  EXPECT_GT(interrupted, 25) << "most signals should land inside a run";
  ASSERT_TRUE(lb::test::RemoveTree(dir)) << dir;
}

}  // namespace
}  // namespace lb
