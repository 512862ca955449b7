// Format negotiation for a V4L2 capture node, as pure logic: which of the formats the driver
// lists the sensor asks for, and whether the format the driver settled on (S_FMT may adjust
// everything) describes buffers the pipeline can read in place.
#pragma once

#include <linux/videodev2.h>

#include <cstddef>
#include <cstdint>

#include "algo/core/frame.h"
#include "algo/core/status.h"

namespace lb {

// The formats the pipeline reads straight from the mmap'ed buffer, in order of preference.
inline constexpr uint32_t kV4l2Preferred[] = {V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_NV12,
                                              V4L2_PIX_FMT_RGB24, V4L2_PIX_FMT_BGR24};

// A fourcc as four printable characters ("YUYV"), for log lines.
struct FourccText {
  char text[5];
};
FourccText FourccName(uint32_t fourcc);

// False for a fourcc the pipeline does not read.
bool FourccToPixelFormat(uint32_t fourcc, PixelFormat* format);

// Picks `wanted` when non-zero (it must be listed and readable), otherwise the first preferred
// format in `listed` (what VIDIOC_ENUM_FMT returned). kUnsupported names what the device offers.
Status ChooseFourcc(const char* device, const uint32_t* listed, size_t count, uint32_t wanted,
                    uint32_t* chosen);

// Where the rows of one buffer lie.
struct V4l2Layout {
  PixelFormat format = PixelFormat::kYuyv;
  int32_t width = 0;
  int32_t height = 0;
  ptrdiff_t stride = 0;  // bytes per row of the first plane
  size_t uv_offset = 0;  // NV12: start of the UV plane in the buffer
  size_t min_bytes = 0;  // a buffer shorter than this cannot hold a frame
};

// Checks what VIDIOC_S_FMT returned against what was asked (`requested` fourcc).
Status LayoutFromFormat(const char* device, const v4l2_pix_format& pix, uint32_t requested,
                        V4l2Layout* layout);

}  // namespace lb
