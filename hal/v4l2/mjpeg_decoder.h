// MJPEG frames to RGB8 strips with libjpeg-turbo, in memory sized once by Configure.
//
// A frame first passes CheckMjpegFrame (mjpeg_check.h), so the usual bad frames of a USB camera
// are refused before any row reaches the sink. libjpeg then decodes it a strip of kStripRows
// rows at a time into one small row buffer, which the sink receives; a frame never exists whole.
// libjpeg's errors and its corrupt-data warnings (which it would otherwise print and paper over
// with grey rows) come back as kCorruptData instead of exit() or a bad picture.
//
// No allocation after Configure. libjpeg's default memory manager mallocs pools for every image
// and frees them at its end; Configure replaces every method of that manager with one over a
// fixed arena: image objects from its bottom, reset when libjpeg frees the image pool, and the
// few permanent ones (quantisation and Huffman tables, made the first time a frame needs them)
// from its top. The arena is sized from the width for baseline frames of any chroma subsampling;
// a frame that would need more (a progressive or multi-scan one wants a whole-frame coefficient
// buffer) is refused with kOutOfMemory or kUnsupported.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "algo/core/frame.h"
#include "algo/core/status.h"

namespace lb {

class MjpegDecoder {
 public:
  static constexpr int32_t kStripRows = 16;

  MjpegDecoder();
  ~MjpegDecoder();
  MjpegDecoder(const MjpegDecoder&) = delete;
  MjpegDecoder& operator=(const MjpegDecoder&) = delete;

  // The arena Configure sets aside for libjpeg for frames `width` px wide.
  static size_t ArenaBytes(int32_t width);

  // Makes the arena, the row buffer and the libjpeg decompressor for width x height frames: the
  // only call that allocates. Called again with the same size it keeps them.
  Status Configure(int32_t width, int32_t height);
  void Release();
  bool configured() const { return impl_ != nullptr; }

  // Decodes one frame of `size` bytes into `sink`: BeginFrame(info, with the decoder's size and
  // kRgb8), strips of at most kStripRows rows, EndFrame. *began says whether BeginFrame was
  // called: a frame refused with *began false never reached the sink, so the caller may take
  // another in its place. A sink's error comes back as it is.
  Status Decode(const uint8_t* data, size_t size, const FrameInfo& info, FrameSink& sink,
                bool* began);

  // How libjpeg used the arena: its size, the most it held at once, the allocations made in it.
  size_t arena_bytes() const;
  size_t arena_peak() const;
  uint64_t arena_allocations() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lb
