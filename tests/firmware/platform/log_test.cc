// Log lines as a person (terminal) or journald (priority prefix) reads them.
#include "firmware/platform/log.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace lb {
namespace {

// Everything written to a pipe by `write`, read back.
template <typename F>
std::string Capture(F write) {
  int fds[2];
  EXPECT_EQ(pipe(fds), 0);
  write(fds[1]);
  close(fds[1]);
  std::string out;
  char buf[1024];
  for (ssize_t n; (n = read(fds[0], buf, sizeof(buf))) > 0;)
    out.append(buf, static_cast<size_t>(n));
  close(fds[0]);
  return out;
}

TEST(LogTest, TerminalLinesCarryTimeAndLevelWords) {
  const std::string out = Capture([](int fd) {
    FdLogSink sink(fd, false);
    Log log(&sink, LogLevel::kInfo);
    log.Printf(LogLevel::kDebug, "hidden %d", 1);
    log.Printf(LogLevel::kInfo, "photo %d: saved", 3);
    log.Printf(LogLevel::kError, "photo %d: not saved", 4);
  });
  // "YYYY-MM-DD HH:MM:SS.mmm level: text"
  ASSERT_EQ(out.size(),
            2 * 24 + strlen("info: photo 3: saved\n") + strlen("error: photo 4: not saved\n"))
      << out;
  EXPECT_EQ(out.find("hidden"), std::string::npos);
  EXPECT_EQ(out.substr(24, 21), "info: photo 3: saved\n");
  EXPECT_EQ(out[4], '-');
  EXPECT_EQ(out[19], '.');
  EXPECT_NE(out.find(" error: photo 4: not saved\n"), std::string::npos);
}

TEST(LogTest, JournalLinesCarryThePriorityPrefix) {
  const std::string out = Capture([](int fd) {
    FdLogSink sink(fd, true);
    Log log(&sink, LogLevel::kDebug);
    log.Printf(LogLevel::kError, "sensor: gone");
    log.Printf(LogLevel::kWarning, "press refused");
    log.Printf(LogLevel::kInfo, "ready");
  });
  EXPECT_EQ(out, "<3>sensor: gone\n<4>press refused\n<6>ready\n");
}

TEST(LogTest, LongLinesAreCutButStillEndTheLine) {
  const std::string out = Capture([](int fd) {
    FdLogSink sink(fd, true);
    Log log(&sink, LogLevel::kInfo);
    const std::string huge(3000, 'x');
    log.Printf(LogLevel::kInfo, "%s", huge.c_str());
    log.Printf(LogLevel::kInfo, "next");
  });
  const size_t first = out.find('\n');
  ASSERT_NE(first, std::string::npos);
  EXPECT_LE(first, static_cast<size_t>(Log::kMaxLine + 3));
  EXPECT_EQ(out.substr(first + 1), "<6>next\n");
}

TEST(LogTest, RecognisesTheJournalStreamSystemdGave) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  struct stat st;
  ASSERT_EQ(fstat(fds[1], &st), 0);
  char value[64];
  snprintf(value, sizeof(value), "%ju:%ju", static_cast<uintmax_t>(st.st_dev),
           static_cast<uintmax_t>(st.st_ino));
  setenv("JOURNAL_STREAM", value, 1);
  EXPECT_TRUE(FdLogSink::IsJournal(fds[1]));
  setenv("JOURNAL_STREAM", "1:2", 1);
  EXPECT_FALSE(FdLogSink::IsJournal(fds[1]));
  unsetenv("JOURNAL_STREAM");
  EXPECT_FALSE(FdLogSink::IsJournal(fds[1]));
  close(fds[0]);
  close(fds[1]);
  LogLevel level;
  EXPECT_TRUE(ParseLogLevel("warning", &level));
  EXPECT_EQ(level, LogLevel::kWarning);
  EXPECT_FALSE(ParseLogLevel("verbose", &level));
}

}  // namespace
}  // namespace lb
