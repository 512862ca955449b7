// Which libcamera pixel formats the pipeline reads in place, and in what order the sensor asks
// for them. libcamera names packed RGB after DRM, by the bit order of a little-endian word:
// BGR888 is R, G, B in memory (V4L2 RGB24), RGB888 is B, G, R; XBGR8888 is R, G, B, X and
// XRGB8888 is B, G, R, X. YUV420 is I420 (Y, then U, then V at half width and height).
#pragma once

#include <libcamera/color_space.h>
#include <libcamera/pixel_format.h>

#include <optional>
#include <vector>

#include "algo/core/frame.h"

namespace lb {

bool LibcameraToPixelFormat(const libcamera::PixelFormat& format, PixelFormat* out);

// `current` when readable, otherwise the first readable of `offered`, preferred in the order
// YUYV, NV12, YUV420, BGR888, RGB888, XBGR8888, XRGB8888 (fewest bytes a pixel first); an
// invalid PixelFormat when none is.
libcamera::PixelFormat ChooseLibcameraFormat(const libcamera::PixelFormat& current,
                                             const std::vector<libcamera::PixelFormat>& offered);

// The YUV range a validated StreamConfiguration::colorSpace says: full only when it says so
// (Raspberry Pi's still stream is sYCC); limited when it says limited or nothing, V4L2's default.
YuvRange LibcameraYuvRange(const std::optional<libcamera::ColorSpace>& color_space);

}  // namespace lb
