// ArenaBlock: how firmware owns the memory an arena carves (algo/core/arena.h). The block is sized
// once from a RequiredBytes, aligned to Arena::kAlign as every stage expects, and freed when its
// owner goes; algo itself never allocates. The job's pipeline, `refocus depth`, the re-render and
// the web page's engine all hold their arenas this way.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>

#include "algo/core/arena.h"
#include "algo/core/status.h"

namespace lb {

class ArenaBlock {
 public:
  // Holds `bytes` rounded up to Arena::kAlign; a block of that size already held is kept (its
  // contents too), any other is freed first. kOutOfMemory when there is no such memory, `what`
  // naming its use in the message; nothing is held then.
  Status Reserve(size_t bytes, const char* what) {
    const size_t size = Arena::RoundUp(bytes);
    if (block_ && size == size_) return Status::Ok();
    Release();
    block_.reset(
        static_cast<uint8_t*>(aligned_alloc(Arena::kAlign, size > 0 ? size : Arena::kAlign)));
    if (!block_) return Status(Code::kOutOfMemory, "cannot allocate %zu bytes %s", size, what);
    size_ = size;
    return Status::Ok();
  }

  void Release() {
    block_.reset();
    size_ = 0;
  }

  uint8_t* data() const { return block_.get(); }
  size_t size() const { return size_; }
  // An arena over the whole block.
  Arena arena() const { return Arena(block_.get(), size_); }

 private:
  struct Free {
    void operator()(uint8_t* p) const { free(p); }
  };
  std::unique_ptr<uint8_t, Free> block_;
  size_t size_ = 0;
};

}  // namespace lb
