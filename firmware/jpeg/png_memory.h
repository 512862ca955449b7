// Greyscale PNG to and from memory (libpng): the depth image inside the refocusable JPEG.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "algo/core/image.h"
#include "algo/core/status.h"

namespace lb {

// Encodes `values` (one channel) as an 8-bit (values 0..255) or 16-bit grey PNG.
Status EncodeGrayPng(ConstImageU16 values, int bits, std::vector<uint8_t>* png);

struct GrayPng {
  int32_t width = 0;
  int32_t height = 0;
  int bits = 0;                  // 8 or 16 (1, 2 and 4 bit files are widened to 8)
  std::vector<uint16_t> values;  // width * height, row-major
};

// Decodes a non-interlaced grey PNG of at most `max_side` pixels a side and, unless they are 0,
// exactly `width` x `height`. `name` is used in error messages. Anything else (colour, alpha,
// interlace, wrong size, bad CRC, truncation) is a Status.
Status DecodeGrayPng(const uint8_t* data, size_t size, const char* name, int32_t max_side,
                     int32_t width, int32_t height, GrayPng* out);

}  // namespace lb
