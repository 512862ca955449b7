// Time as the daemon sees it: a monotonic clock for durations and the local wall-clock time that
// names the photos. Injected so tests can name photos at a fixed second.
#pragma once

#include <time.h>

#include <cstdint>

namespace lb {

class Clock {
 public:
  virtual ~Clock() = default;
  virtual int64_t MonotonicNs() const = 0;
  virtual void LocalTime(tm* out) const = 0;
};

class SystemClock : public Clock {
 public:
  int64_t MonotonicNs() const override {
    timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return static_cast<int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
  }
  void LocalTime(tm* out) const override {
    const time_t now = time(nullptr);
    localtime_r(&now, out);
  }
};

}  // namespace lb
