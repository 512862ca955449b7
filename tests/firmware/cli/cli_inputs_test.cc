// What `refocus` reads and what it is told: an input that is no regular file (a FIFO) is refused
// at once by every command, options that cannot apply are refused, and a setting given twice is
// an error as it is in refocusd.conf.
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "tests/firmware/cli/cli_fixture.h"

namespace lb {
namespace {

using clitest::Cli;
using clitest::Result;
using clitest::Slurp;

// A command that blocks is killed after this long, so a regression fails instead of hanging.
constexpr unsigned kLimitS = 30;

class CliInputs : public Cli {
 protected:
  // Run, but the child gets SIGALRM (its default action ends it) after kLimitS seconds: the
  // exit code is then -1 and `err` says so.
  Result RunWithin(const std::vector<std::string>& args) {
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
      signal(SIGALRM, SIG_DFL);
      alarm(kLimitS);  // kept across exec
      execv(REFOCUS_BIN, argv.data());
      _exit(127);
    }
    int status = 0;
    if (waitpid(pid, &status, 0) != pid) return r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = Slurp(dir_ + "/stdout");
    r.err = Slurp(dir_ + "/stderr");
    if (WIFSIGNALED(status)) r.err += "(killed by signal " + std::to_string(WTERMSIG(status)) + ")";
    return r;
  }

  std::string Fifo(const std::string& name) {
    const std::string path = dir_ + "/" + name;
    EXPECT_EQ(mkfifo(path.c_str(), 0644), 0);
    return path;
  }

  void ExpectFifoRefused(const Result& r, const std::string& fifo) {
    ExpectCleanFailure(r, fifo, "not a regular file (a FIFO)");
  }
};

TEST_F(CliInputs, AFifoAmongTheFilesIsRefusedNotWaitedOn) {
  std::vector<std::string> args = {"run", "--geometry", "rectified", "--out", Out()};
  for (const std::string& p : PpmBurst(2, 64, 48)) args.push_back(p);
  const std::string fifo = Fifo("f9.ppm");
  args.push_back(fifo);
  ExpectFifoRefused(RunWithin(args), fifo);
}

TEST_F(CliInputs, AFifoInTheInputFolderIsRefusedNotWaitedOn) {
  PpmBurst(3, 64, 48);  // f0.ppm .. f2.ppm in dir_, sorted before the FIFO
  const std::string fifo = Fifo("z.ppm");
  ExpectFifoRefused(RunWithin({"run", "--input", dir_, "--geometry", "rectified", "--out", Out()}),
                    fifo);
}

TEST_F(CliInputs, AFifoToRerenderIsRefusedNotWaitedOn) {
  const std::string fifo = Fifo("in.jpg");
  ExpectFifoRefused(RunWithin({"rerender", fifo, "--out", Out()}), fifo);
}

TEST_F(CliInputs, AFifoAsAViewIsRefusedNotWaitedOn) {
  const std::vector<std::string> views = PpmBurst(2, 64, 48);
  const std::string fifo = Fifo("v2.ppm");
  ExpectFifoRefused(RunWithin({"depth", "--views", views[0], views[1], fifo, "--disparity-out",
                               out_dir_ + "/d.pfm"}),
                    fifo);
}

TEST_F(CliInputs, SyntheticOnlyOptionsAreRefusedWithFiles) {
  const std::vector<std::string> frames = PpmBurst(3, 64, 48);
  struct Case {
    std::vector<std::string> args;
    std::string says;
  };
  for (const Case& c : {
           Case{{"run", "--seed", "7", "--out", Out()}, "--seed is for the synthetic scene"},
           Case{{"run", "--motion", "handheld", "--out", Out()},
                "--motion is for the synthetic scene"},
           Case{{"run", "--input", dir_, "--seed", "7", "--out", Out()},
                "--seed is for the synthetic scene"},
       }) {
    std::vector<std::string> args = c.args;
    if (args[1] != "--input") args.insert(args.end(), frames.begin(), frames.end());
    const Result r = RunWithin(args);
    EXPECT_EQ(r.exit_code, 2) << c.args[1] << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
  }
  EXPECT_TRUE(OutDirEmpty());
}

TEST_F(CliInputs, ASettingGivenTwiceIsRefusedAsInTheConfigurationFile) {
  const std::string in = dir_ + "/in.jpg";  // never read: the options are refused first
  struct Case {
    std::vector<std::string> args;
    std::string says;
  };
  for (const Case& c : {
           Case{{"rerender", in, "--f-number", "2", "--f-number", "8", "--out", Out()},
                "--f-number given twice"},
           Case{{"rerender", in, "--rotation", "10", "--aperture-rotation", "20", "--out", Out()},
                "--aperture-rotation given twice (--rotation is the same setting)"},
           Case{{"run", "--size", "64x48", "--labels", "8", "--labels", "16", "--out", Out()},
                "--labels given twice"},
           Case{{"depth", "--labels", "8", "--labels", "16", "--views", in, in, "--disparity-out",
                 out_dir_ + "/d.pfm"},
                "--labels given twice"},
       }) {
    const Result r = RunWithin(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args[0] << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
  }
  EXPECT_TRUE(OutDirEmpty());
}

}  // namespace
}  // namespace lb
