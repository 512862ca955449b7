// The image decoder interface: how an image file is probed, streamed into a FrameSink and its
// camera tags read. The product's codecs implement it (firmware/codecs/codec_decoder.h); the
// file-backed sensor in sim/ reads its files through whichever one it is handed, so it reads them
// exactly as the product does. It lives in hal so that neither the codecs nor the simulator need
// to include the other.
#pragma once

#include <cstdint>

#include "algo/core/frame.h"
#include "algo/core/status.h"

namespace lb {

struct ImageHeader {
  PixelFormat format = PixelFormat::kRgb8;  // kGray8, kRgb8, kGray16 or kRgb16
  int32_t width = 0;
  int32_t height = 0;
};

// What the camera recorded in a file's EXIF.
struct CameraTags {
  double focal_px = 0;      // focal length in px of the image's size, 0 when not recorded
  int32_t orientation = 0;  // EXIF Orientation 1..8, 0 when not recorded
};

class ImageDecoder {
 public:
  virtual ~ImageDecoder() = default;
  // Reads only the header. Errors name the file.
  virtual Status Probe(const char* path, ImageHeader* header) const = 0;
  // Streams the pixels as frame `index` (BeginFrame, Rows..., EndFrame), a strip at a time;
  // 16-bit samples native-endian.
  virtual Status Stream(const char* path, int32_t index, FrameSink& sink) const = 0;
  // The EXIF tags of a width x height image; none (zeros) for a file without them.
  virtual CameraTags Tags(const char* path, int32_t width, int32_t height) const = 0;
};

}  // namespace lb
