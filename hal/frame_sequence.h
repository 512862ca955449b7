// Dropped-frame detection from the V4L2 buffer sequence numbers: the driver counts every frame it
// produced, so a gap between two dequeued buffers is the number of frames it dropped (no free
// buffer, a buffer flagged bad). The counter is 32-bit and wraps.
#pragma once

#include <cstdint>

namespace lb {

class FrameSequence {
 public:
  void Reset() { started_ = false; }

  // Records the next buffer's sequence number. Returns false when it does not move forward
  // (repeated or going back); otherwise sets *missing to the frames skipped since the last one.
  bool Next(uint32_t sequence, uint32_t* missing);

  uint32_t last() const { return last_; }

 private:
  bool started_ = false;
  uint32_t last_ = 0;
};

}  // namespace lb
