// The depth image a GDepth field carries, as whatever writer chose to store it: PNG (grey, grey
// with alpha, RGB or RGBA, palette; 8 or 16 bit) or JPEG (grey or colour). Google Camera's Lens
// Blur, for one, writes 8-bit RGBA with the grey value repeated in R, G and B. A colour image is
// taken only when its channels agree: one whose channels differ is refused, never read through
// one channel the writer may not have meant. Alpha carries no depth and is ignored.
//
// Rows are decoded a strip at a time into the caller's strip; only the values are whole.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "algo/core/image.h"
#include "algo/core/status.h"
#include "firmware/codecs/png_reader.h"

namespace lb {

// What the depth image's header says, before any pixel is decoded.
struct DepthImageHeader {
  int32_t width = 0;
  int32_t height = 0;
  int bits = 0;             // 8 or 16 per sample, as stored (PNG 1, 2 and 4 bit: as stored)
  const char* colour = "";  // "grey", "grey+alpha", "RGB", "RGBA", "palette"
  bool is_jpeg = false;
};

// `mime` is GDepth:Mime: image/png or image/jpeg (anything else is kUnsupported).
Status ProbeDepthImage(const uint8_t* data, size_t size, std::string_view mime, const char* name,
                       DepthImageHeader* header);

// The caller's memory, sized once: the values and the strip the codec decodes rows into.
struct DepthImageBuffer {
  uint16_t* values = nullptr;
  size_t capacity = 0;  // values; a larger image is kOutOfMemory before any row is decoded
  uint8_t* strip = nullptr;
  size_t strip_bytes = 0;  // at least DepthStripBytes(the widest image expected)
  int32_t width = 0;       // the decoded image (0 after an error)
  int32_t height = 0;
  int bits = 0;  // 8 or 16: the values' scale
};

size_t DepthStripBytes(int32_t max_width);

// Decodes into `out`: at most `max_side` a side and, unless they are 0, exactly `width` x
// `height` (GDepth:ImageWidth/Height), checked against the header first. `name` starts every
// message ("photo.jpg: GDepth:Data").
Status DecodeDepthImageInto(const uint8_t* data, size_t size, std::string_view mime,
                            const char* name, int32_t max_side, int32_t width, int32_t height,
                            DepthImageBuffer* out);

// The same for host tools: allocates the values and a strip.
Status DecodeDepthImage(const uint8_t* data, size_t size, std::string_view mime, const char* name,
                        int32_t max_side, int32_t width, int32_t height, GrayPng* out);

// Bilinear resampling of a disparity map to another size (a depth map smaller than the photo,
// or not a whole-number fraction of it).
void ResampleDisparity(ConstImageU16 in, ImageU16 out);

}  // namespace lb
