// How far a long stage is, for the person waiting (a progress line, a log). A stage calls it on
// its own thread between units of work (an expansion move, a frame), never per pixel.
#pragma once

#include <cstdint>

namespace lb {

class ProgressSink {
 public:
  virtual ~ProgressSink() = default;
  // `done` of `total` units of the stage in progress; done reaches total at its end.
  virtual void Report(int32_t done, int32_t total) = 0;
};

}  // namespace lb
