// Format negotiation for a V4L2 capture node, as pure logic: which of the formats the driver
// lists the sensor asks for, and whether the format the driver settled on (S_FMT may adjust
// everything) describes buffers the pipeline can read in place (YUYV, NV12, RGB24, BGR24) or
// frames the sensor decodes to RGB8 itself (MJPEG, JPEG).
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
// Compressed formats the sensor decodes to RGB8 rows: a decode costs CPU time and a little
// quality, so they come after the uncompressed ones, but most USB cameras offer 720p and up only
// as MJPEG. Some drivers say JPEG for the same stream.
inline constexpr uint32_t kV4l2Compressed[] = {V4L2_PIX_FMT_MJPEG, V4L2_PIX_FMT_JPEG};

bool IsJpegFourcc(uint32_t fourcc);
// Start and end markers: a buffer or frame shorter than this holds no JPEG.
inline constexpr size_t kMinJpegBytes = 4;

// A fourcc as four printable characters ("YUYV"), for log lines.
struct FourccText {
  char text[5];
};
FourccText FourccName(uint32_t fourcc);

// The format the sink receives for a fourcc (kRgb8 for MJPEG and JPEG, which the sensor
// decodes); false for a fourcc the pipeline does not read.
bool FourccToPixelFormat(uint32_t fourcc, PixelFormat* format);

// Picks `wanted` when non-zero (it must be listed and readable). Otherwise, from `listed` (what
// VIDIOC_ENUM_FMT returned): the first of kV4l2Preferred offered at the wanted frame size, else
// the first of kV4l2Compressed offered at that size, else, so the driver picks the nearest size,
// the first of kV4l2Preferred offered at all, else the first of kV4l2Compressed.
// `at_size[i]` says whether listed[i] is offered at the wanted size (VIDIOC_ENUM_FRAMESIZES);
// nullptr: every format is. kUnsupported names what the device offers.
Status ChooseFourcc(const char* device, const uint32_t* listed, const bool* at_size, size_t count,
                    uint32_t wanted, uint32_t* chosen);
inline Status ChooseFourcc(const char* device, const uint32_t* listed, size_t count,
                           uint32_t wanted, uint32_t* chosen) {
  return ChooseFourcc(device, listed, nullptr, count, wanted, chosen);
}

// Where the rows of one buffer lie.
struct V4l2Layout {
  PixelFormat format = PixelFormat::kYuyv;  // what the sink receives
  int32_t width = 0;
  int32_t height = 0;
  ptrdiff_t stride = 0;     // bytes per row of the first plane; 0 when compressed
  size_t uv_offset = 0;     // NV12: start of the UV plane in the buffer
  size_t min_bytes = 0;     // a buffer shorter than this cannot hold a frame
  bool compressed = false;  // MJPEG or JPEG: each buffer holds one JPEG of bytesused bytes
};

// Checks what VIDIOC_S_FMT returned against what was asked (`requested` fourcc).
Status LayoutFromFormat(const char* device, const v4l2_pix_format& pix, uint32_t requested,
                        V4l2Layout* layout);

}  // namespace lb
