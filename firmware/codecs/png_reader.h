// The product's PNG reader (png_reader.cc, libpng): image files and frames go through
// image_file.h like every format; this is its other door, for the grey depth image that a
// refocusable JPEG carries in memory.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "algo/core/status.h"

namespace lb {

struct GrayPng {
  int32_t width = 0;
  int32_t height = 0;
  int bits = 0;                  // 8 or 16 (1, 2 and 4 bit files are widened to 8)
  std::vector<uint16_t> values;  // width * height, row-major
};

// Decodes a non-interlaced grey PNG of at most `max_side` pixels a side and, unless they are 0,
// exactly `width` x `height`. `name` is used in error messages. Anything else (colour, alpha,
// interlace, wrong size, bad CRC, truncation) is a Status, and leaves `out` empty.
Status DecodeGrayPng(const uint8_t* data, size_t size, const char* name, int32_t max_side,
                     int32_t width, int32_t height, GrayPng* out);

// The caller's memory for DecodeGrayPngInto, sized once (the web page's engine): the values,
// and the strip libpng decodes rows into (ImageStripBytes(max_side, PixelFormat::kGray16)).
struct GrayPngBuffer {
  uint16_t* values = nullptr;
  size_t capacity = 0;  // values; a larger image is kOutOfMemory before any row is decoded
  uint8_t* strip = nullptr;
  size_t strip_bytes = 0;
  int32_t width = 0;  // the decoded image (0 after an error)
  int32_t height = 0;
  int bits = 0;
};

// DecodeGrayPng into `out` with no allocation but libpng's own; the same checks and values.
Status DecodeGrayPngInto(const uint8_t* data, size_t size, const char* name, int32_t max_side,
                         int32_t width, int32_t height, GrayPngBuffer* out);

}  // namespace lb
