// The progress line: on a terminal, `run` and `rerender` redraw one line of stage and percentage
// in place and clear it before their result; off a terminal they print nothing extra.
#include <pty.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/firmware/cli/cli_fixture.h"

namespace lb::clitest {
namespace {

// Runs refocus with stdout and stderr on a pseudo-terminal; returns everything it drew.
std::string RunOnTerminal(const std::vector<std::string>& args, int* exit_code) {
  fflush(nullptr);
  int master = -1;
  const pid_t pid = forkpty(&master, nullptr, nullptr, nullptr);
  if (pid < 0) return "";
  if (pid == 0) {
    std::vector<char*> argv = {const_cast<char*>(REFOCUS_BIN)};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(REFOCUS_BIN, argv.data());
    _exit(127);
  }
  std::string screen;
  char buf[4096];
  for (ssize_t n; (n = read(master, buf, sizeof(buf))) > 0;) screen.append(buf, n);
  close(master);
  int status = 0;
  waitpid(pid, &status, 0);
  *exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return screen;
}

struct Frame {
  std::string stage;
  int percent;
};

// The redraws "\r<stage> <percent>%\033[K" in the order they were drawn.
std::vector<Frame> Redraws(const std::string& screen) {
  std::vector<Frame> frames;
  for (size_t at = screen.find('\r'); at != std::string::npos; at = screen.find('\r', at + 1)) {
    const size_t end = screen.find("%\033[K", at);
    const size_t space = screen.find(' ', at);
    if (end == std::string::npos || space == std::string::npos || space > end) continue;
    frames.push_back({screen.substr(at + 1, space - at - 1), atoi(screen.c_str() + space)});
  }
  return frames;
}

void ExpectStagesInOrder(const std::vector<Frame>& frames, const std::vector<std::string>& order) {
  size_t next = 0;
  int last = -1;
  std::string stage;
  for (const Frame& f : frames) {
    if (f.stage != stage) {
      while (next < order.size() && order[next] != f.stage) ++next;
      ASSERT_LT(next, order.size()) << "stage '" << f.stage << "' out of order";
      stage = f.stage;
      last = -1;
    }
    EXPECT_GE(f.percent, last) << stage << " went back";
    EXPECT_LE(f.percent, 100);
    last = f.percent;
  }
  for (const std::string& s : order) {
    bool seen_full = false;
    for (const Frame& f : frames) seen_full = seen_full || (f.stage == s && f.percent == 100);
    if (s != "write") {
      EXPECT_TRUE(seen_full) << s << " never reached 100 %";
    }
  }
}

TEST_F(Cli, OnATerminalRunAndRerenderRedrawOneProgressLine) {
  int code = -1;
  const std::string screen = RunOnTerminal(
      {"run", "--synthetic", "--size", "320x240", "--labels", "8", "--out", Out()}, &code);
  ASSERT_EQ(code, 0) << screen;
  ExpectStagesInOrder(Redraws(screen), {"capture", "depth", "render", "write"});
  // The line is cleared before anything else is printed, which starts on a clean line.
  const size_t cleared = screen.find("\r\033[K");
  ASSERT_NE(cleared, std::string::npos) << screen;
  EXPECT_EQ(screen.substr(0, cleared).find('\n'), std::string::npos) << "one line, redrawn";
  EXPECT_NE(screen.find("wrote ", cleared), std::string::npos) << screen;

  const std::string again =
      RunOnTerminal({"rerender", Out(), "--focus", "10,10", "--out", out_dir_ + "/b.jpg"}, &code);
  ASSERT_EQ(code, 0) << again;
  ExpectStagesInOrder(Redraws(again), {"render"});
  EXPECT_NE(again.find("\r\033[Kwrote "), std::string::npos) << again;
}

TEST_F(Cli, OffATerminalThereIsNoProgressLine) {
  const Result r =
      Run({"run", "--synthetic", "--size", "320x240", "--labels", "8", "--out", Out()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('%'), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find('\r'), std::string::npos) << r.out;
  const Result again = Run({"rerender", Out(), "--out", out_dir_ + "/b.jpg"});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(again.err, "");
}

}  // namespace
}  // namespace lb::clitest
