// The product's PNG writer (libpng): the grey depth image inside the refocusable JPEG (8 or 16
// bits) and the colour preview of `refocus depth` (RGB, 8 bits), into memory.
#pragma once

#include <cstdint>
#include <vector>

#include "algo/core/image.h"
#include "algo/core/status.h"

namespace lb {

// Encodes `values` (one channel) as an 8-bit (values above 255 are clamped) or 16-bit grey PNG.
Status EncodeGrayPng(ConstImageU16 values, int bits, std::vector<uint8_t>* png);

// Encodes an RGB image (three channels, 8 bits) as an sRGB PNG.
Status EncodeRgbPng(ConstImageU8 rgb, std::vector<uint8_t>* png);

}  // namespace lb
