// A cheap structural walk over one MJPEG frame, run before libjpeg sees it. libjpeg finds most
// damage only while it decodes rows, after the first strips have gone to the sink, and then no
// other frame can take this one's place; the walk finds what a USB camera's bad frames usually
// are (empty, cut short, garbage, a frame of another mode) before any row is delivered.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/status.h"

namespace lb {

// Ok for a frame that starts with SOI, whose marker segments all fit in `size` bytes, whose frame
// header is baseline or extended sequential Huffman (SOF0, SOF1), 8-bit, 1 or 3 components and
// `width` x `height`, that has one scan over all its components whose entropy-coded data holds
// nothing but stuffed bytes and restart markers, and that ends that scan with EOI (bytes after
// EOI are padding and ignored). Huffman tables may be missing: libjpeg-turbo supplies the standard
// ones, which UVC cameras leave out. kCorruptData or kUnsupported otherwise, saying what is wrong
// and at which byte.
Status CheckMjpegFrame(const uint8_t* data, size_t size, int32_t width, int32_t height);

}  // namespace lb
