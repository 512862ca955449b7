// The programs' log (refocusd and the web page it serves): one line per event, with a level,
// written to stderr so journald keeps it. Under systemd (stderr is the journal stream named by
// JOURNAL_STREAM) each line carries the "<N>" priority prefix journald understands; on a
// terminal it carries the local time and the level in words instead. Safe to call from several
// threads; formats into a fixed buffer, so logging never allocates.
#pragma once

#include <cstdint>
#include <mutex>

namespace lb {

enum class LogLevel : uint8_t { kDebug, kInfo, kWarning, kError };

const char* LogLevelName(LogLevel level);
// "debug", "info", "warning", "error"; false for anything else.
bool ParseLogLevel(const char* text, LogLevel* level);

// Where finished lines go (the text has no level prefix and no newline).
class LogSink {
 public:
  virtual ~LogSink() = default;
  virtual void Write(LogLevel level, const char* text) = 0;
};

// Writes whole lines to a descriptor with one write(2) each, so lines from two processes or
// threads never interleave.
class FdLogSink : public LogSink {
 public:
  // `journal`: prefix lines with "<N>" (sd-daemon priorities) instead of time and level.
  FdLogSink(int fd, bool journal) : fd_(fd), journal_(journal) {}
  void Write(LogLevel level, const char* text) override;

  // True when `fd` is the stream systemd connected to the journal.
  static bool IsJournal(int fd);

 private:
  int fd_;
  bool journal_;
};

class Log {
 public:
  static constexpr int kMaxLine = 512;  // longer lines are cut

  Log(LogSink* sink, LogLevel min_level) : sink_(sink), min_level_(min_level) {}

  void set_min_level(LogLevel level) { min_level_ = level; }
  void Printf(LogLevel level, const char* format, ...) __attribute__((format(printf, 3, 4)));

 private:
  std::mutex mutex_;
  LogSink* sink_;
  LogLevel min_level_;
};

}  // namespace lb
