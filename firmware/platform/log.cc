#include "firmware/platform/log.h"

#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cinttypes>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace lb {
namespace {

// sd-daemon(3) priorities: the syslog levels.
int JournalPriority(LogLevel level) {
  switch (level) {
    case LogLevel::kDebug:
      return 7;
    case LogLevel::kInfo:
      return 6;
    case LogLevel::kWarning:
      return 4;
    case LogLevel::kError:
      return 3;
  }
  return 6;
}

}  // namespace

const char* LogLevelName(LogLevel level) {
  switch (level) {
    case LogLevel::kDebug:
      return "debug";
    case LogLevel::kInfo:
      return "info";
    case LogLevel::kWarning:
      return "warning";
    case LogLevel::kError:
      return "error";
  }
  return "?";
}

bool ParseLogLevel(const char* text, LogLevel* level) {
  for (LogLevel l : {LogLevel::kDebug, LogLevel::kInfo, LogLevel::kWarning, LogLevel::kError}) {
    if (strcmp(text, LogLevelName(l)) == 0) {
      *level = l;
      return true;
    }
  }
  return false;
}

bool FdLogSink::IsJournal(int fd) {
  // systemd sets JOURNAL_STREAM to "<device>:<inode>" of the stream it gave the service.
  const char* stream = getenv("JOURNAL_STREAM");
  if (stream == nullptr) return false;
  uintmax_t dev = 0, ino = 0;
  if (sscanf(stream, "%ju:%ju", &dev, &ino) != 2) return false;
  struct stat st;
  if (fstat(fd, &st) != 0) return false;
  return static_cast<uintmax_t>(st.st_dev) == dev && static_cast<uintmax_t>(st.st_ino) == ino;
}

void FdLogSink::Write(LogLevel level, const char* text) {
  char line[Log::kMaxLine + 64];
  int n = 0;
  if (journal_) {
    n = snprintf(line, sizeof(line), "<%d>%s\n", JournalPriority(level), text);
  } else {
    timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    tm local;
    localtime_r(&ts.tv_sec, &local);
    char when[32];
    strftime(when, sizeof(when), "%Y-%m-%d %H:%M:%S", &local);
    n = snprintf(line, sizeof(line), "%s.%03ld %s: %s\n", when, ts.tv_nsec / 1000000L,
                 LogLevelName(level), text);
  }
  if (n < 0) return;
  size_t size = static_cast<size_t>(n) < sizeof(line) ? static_cast<size_t>(n) : sizeof(line) - 1;
  line[size - 1] = '\n';  // a cut line still ends the line
  // A log that cannot be written (a closed pipe) must not stop the camera: ignore failures.
  const char* p = line;
  while (size > 0) {
    ssize_t w = write(fd_, p, size);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return;
    p += w;
    size -= static_cast<size_t>(w);
  }
}

void Log::Printf(LogLevel level, const char* format, ...) {
  if (level < min_level_) return;
  char text[kMaxLine];
  va_list args;
  va_start(args, format);
  vsnprintf(text, sizeof(text), format, args);
  va_end(args);
  std::lock_guard<std::mutex> lock(mutex_);
  sink_->Write(level, text);
}

}  // namespace lb
