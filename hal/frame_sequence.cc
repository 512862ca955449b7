#include "hal/frame_sequence.h"

namespace lb {

bool FrameSequence::Next(uint32_t sequence, uint32_t* missing) {
  *missing = 0;
  if (!started_) {
    started_ = true;
    last_ = sequence;
    return true;
  }
  // Unsigned difference handles the wrap; a step of more than half the range is a step back.
  uint32_t step = sequence - last_;
  if (step == 0 || step > 0x80000000u) return false;
  *missing = step - 1;
  last_ = sequence;
  return true;
}

}  // namespace lb
