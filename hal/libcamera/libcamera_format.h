// Which libcamera pixel formats the pipeline reads in place, and in what order the sensor asks
// for them. libcamera names packed RGB after DRM, by the bit order of a little-endian word:
// BGR888 is R, G, B in memory (V4L2 RGB24), RGB888 is B, G, R.
#pragma once

#include <libcamera/pixel_format.h>

#include <vector>

#include "algo/core/frame.h"

namespace lb {

bool LibcameraToPixelFormat(const libcamera::PixelFormat& format, PixelFormat* out);

// `current` when readable, otherwise the first readable of `offered` (YUYV, NV12, BGR888, RGB888
// preferred in that order); an invalid PixelFormat when none is.
libcamera::PixelFormat ChooseLibcameraFormat(const libcamera::PixelFormat& current,
                                             const std::vector<libcamera::PixelFormat>& offered);

}  // namespace lb
