// What a sensor delivers and the pipeline ingests: a frame's format and its rows. Frames arrive
// as one or more strips of rows, so a decoder or a sensor never needs to hold a whole frame; a
// strip is only valid during the call that receives it.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/status.h"

namespace lb {

// The largest frame side the product takes: sensors refuse larger modes, the pipeline sizes its
// arena for at most this.
inline constexpr int32_t kMaxFrameSide = 8192;

enum class PixelFormat : uint8_t {
  kGray8,   // 1 x 8-bit
  kRgb8,    // 3 x 8-bit, R G B in memory order
  kBgr8,    // 3 x 8-bit, B G R in memory order
  kGray16,  // 1 x 16-bit native endian, full scale 65535
  kRgb16,   // 3 x 16-bit native endian, full scale 65535
  kYuyv,    // 4:2:2 packed Y0 U Y1 V
  kNv12,    // 4:2:0: a Y plane, then an interleaved UV plane at half height
  kI420,    // 4:2:0: a Y plane, then a U and a V plane at half width and half height
  kRgbx8,   // 4 x 8-bit, R G B and an unused byte in memory order
  kBgrx8,   // 4 x 8-bit, B G R and an unused byte in memory order
};

// How the YUV formats (YUYV, NV12, I420) use their 8 bits; both with BT.601's matrix.
enum class YuvRange : uint8_t {
  kLimited,  // Y 16..235, U and V 16..240: V4L2's default for YUV, and what most cameras send
  kFull,     // 0..255 (JFIF, libcamera's sYCC): Raspberry Pi's still stream
};

const char* PixelFormatName(PixelFormat format);
// Bytes per pixel of the first plane's samples, 0 for formats without a whole-byte pixel size.
int BytesPerPixel(PixelFormat format);
// Planes a frame of the format has: 1, or 2 for NV12, 3 for I420.
int PlaneCount(PixelFormat format);

struct FrameInfo {
  int32_t index = 0;  // position in the burst, 0-based
  PixelFormat format = PixelFormat::kRgb8;
  int32_t width = 0;
  int32_t height = 0;
  int64_t timestamp_ns = 0;             // sensor time of the start of exposure
  uint32_t sequence = 0;                // sensor frame counter (a gap means a dropped frame)
  YuvRange range = YuvRange::kLimited;  // the YUV formats' only
};

// A strip of `height` rows starting at row `y0` of the frame. Plane strides are in bytes. For
// NV12, plane 1 is the UV plane; for I420, planes 1 and 2 are the U and V planes. Their first row
// is row y0 / 2 of the chroma, so 4:2:0 strips start on even rows.
struct FrameRows {
  int32_t y0 = 0;
  int32_t height = 0;
  const uint8_t* planes[3] = {nullptr, nullptr, nullptr};
  ptrdiff_t strides[3] = {0, 0, 0};
};

// Receives a burst frame by frame. Implemented by the pipeline (and by tests).
class FrameSink {
 public:
  virtual ~FrameSink() = default;
  virtual Status BeginFrame(const FrameInfo& info) = 0;
  // Rows arrive in order, top to bottom, covering the frame exactly once.
  virtual Status Rows(const FrameRows& rows) = 0;
  virtual Status EndFrame() = 0;
};

}  // namespace lb
