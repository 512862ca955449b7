// Arena: the one block of memory the pipeline owns. Stages first *plan* (count the bytes their
// configuration needs, with the same calls they later make), then the caller provides one block
// of exactly that size and the stages carve it. Nothing is freed piecemeal and nothing grows.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/image.h"

namespace lb {

class Arena {
 public:
  static constexpr size_t kAlign = 64;  // a cache line: SIMD loads and no false sharing

  // A planning arena: hands out no memory, only counts the bytes (Allocate returns nullptr).
  Arena() = default;
  // An arena over caller-owned memory.
  Arena(void* base, size_t size) : base_(static_cast<uint8_t*>(base)), size_(size) {}

  bool planning() const { return base_ == nullptr; }
  size_t used() const { return used_; }
  size_t size() const { return size_; }
  // Set when an Allocate did not fit: the configuration needs more than this arena holds.
  bool overflowed() const { return overflowed_; }

  // Returns `count` elements of T aligned to kAlign, or nullptr when planning or out of space.
  template <typename T>
  T* Allocate(size_t count) {
    return static_cast<T*>(AllocateBytes(count * sizeof(T)));
  }

  template <typename T>
  ImageView<T> AllocateImage(int32_t width, int32_t height, int32_t channels = 1) {
    // Rows padded to the alignment so every row starts on a cache line.
    const size_t row_elems = RoundUp(static_cast<size_t>(width) * channels * sizeof(T)) / sizeof(T);
    T* data = Allocate<T>(row_elems * static_cast<size_t>(height));
    return {data, width, height, channels, static_cast<ptrdiff_t>(row_elems)};
  }

  void* AllocateBytes(size_t bytes);

  static constexpr size_t RoundUp(size_t n) { return (n + kAlign - 1) & ~(kAlign - 1); }
  // The first kAlign boundary at or after p: for an arena in a buffer with no alignment of its
  // own, which then needs kAlign - 1 bytes more than the arena.
  static void* AlignUp(void* p) {
    const uintptr_t at = reinterpret_cast<uintptr_t>(p);
    return static_cast<uint8_t*>(p) + (RoundUp(at) - at);
  }

 private:
  uint8_t* base_ = nullptr;
  size_t size_ = 0;
  size_t used_ = 0;
  bool overflowed_ = false;
};

}  // namespace lb
