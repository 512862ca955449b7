#include "algo/core/arena.h"

namespace lb {

void* Arena::AllocateBytes(size_t bytes) {
  const size_t start = RoundUp(used_);
  const size_t end = start + RoundUp(bytes);
  used_ = end;
  if (planning()) return nullptr;
  if (end > size_) {
    overflowed_ = true;
    return nullptr;
  }
  return base_ + start;
}

}  // namespace lb
