// Reads a refocusable JPEG: walks the segments before the image data, reassembles extended XMP
// by GUID and offset (checking it against its MD5), and extracts GDepth (fields, the decoded
// depth image and its confidence map), GImage (the original JPEG's bytes) and GFocus. Any defect
// is a Status naming the file and the problem; the reader never trusts a length it has not
// checked. The confidence map alone is optional even when broken: a bad one is ignored, with
// the reason in the fields, and the depth still opens.
//
// One reader, two doors: ReadRefocusableFields puts what it decodes where a RefocusableMemory
// says (the web page's engine: memory sized once, nothing allocated) and leaves the depth PNG
// encoded; ReadRefocusable wraps it for host tools (vectors, and the PNG decoded).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "algo/core/status.h"
#include "firmware/codecs/png_reader.h"
#include "firmware/refocusable/xmp_writer.h"

namespace lb {

// One extended-XMP chunk of the file (the reader's bookkeeping, in the caller's memory).
struct ExtendedXmpChunk {
  const uint8_t* guid;  // 32 bytes
  uint32_t full;        // the whole extended packet's length, as the chunk states it
  uint32_t offset;
  const uint8_t* bytes;
  size_t size;
};

// Where the reader puts what is not in the file's bytes as they are. Each call returns room for
// `count` items, or nullptr when there is none (the read is then kOutOfMemory).
class RefocusableMemory {
 public:
  // kConfidence: a memory without room for it (nullptr) reads the file without its confidence.
  enum class Part : uint8_t { kExtendedXmp, kDepthPng, kImage, kConfidence };
  virtual ~RefocusableMemory() = default;
  virtual ExtendedXmpChunk* Chunks(size_t count) = 0;
  virtual uint8_t* Bytes(Part part, size_t count) = 0;
};

// Fixed buffers, sized once by the caller.
class RefocusableBuffers final : public RefocusableMemory {
 public:
  ExtendedXmpChunk* chunks = nullptr;
  size_t chunk_capacity = 0;
  uint8_t* extended = nullptr;  // the reassembled extended XMP
  size_t extended_capacity = 0;
  uint8_t* depth_png = nullptr;  // GDepth:Data, base64-decoded
  size_t depth_png_capacity = 0;
  uint8_t* image = nullptr;  // GImage:Data, base64-decoded
  size_t image_capacity = 0;
  uint8_t* confidence = nullptr;  // GDepth:Confidence, base64-decoded (none: not read)
  size_t confidence_capacity = 0;

  ExtendedXmpChunk* Chunks(size_t count) override;
  uint8_t* Bytes(Part part, size_t count) override;
};

// The file's fields: text points into the file's bytes or the extended XMP, data into the memory.
struct RefocusableFields {
  int32_t width = 0;  // the primary (refocused) image, from its frame header
  int32_t height = 0;
  int32_t orientation = 0;  // the photo's EXIF Orientation 1..8, 0 when it records none
  std::string_view depth_format, depth_mime, depth_units;  // units: "" when not given
  double near_depth = 0.0, far_depth = 0.0;
  int32_t depth_width = 0, depth_height = 0;  // GDepth:ImageWidth/Height, 0 = not recorded
  const uint8_t* depth_png = nullptr;  // the depth image (PNG or JPEG, depth_mime), still encoded
  size_t depth_png_size = 0;
  int32_t depth_max_side =
      0;  // the largest side the depth image may have (no larger than the photo)
  std::string_view image_mime;
  const uint8_t* image = nullptr;  // GImage:Data; nullptr when the file has none
  size_t image_size = 0;
  bool has_focus = false;
  GFocusInfo focus;
  bool dynamic_depth = false;  // the depth and the image from Dynamic Depth's items (no GDepth)
  // How sure each depth pixel is (GDepth:Confidence, or Dynamic Depth's confidence item when the
  // depth comes from there), still encoded, an image the depth image's size by both headers;
  // nullptr when the file has none or it was ignored.
  std::string_view confidence_mime;
  const uint8_t* confidence = nullptr;
  size_t confidence_size = 0;
  int32_t confidence_width = 0, confidence_height = 0;
  // Not ok when the file's confidence map was ignored (bad base64, an image that does not read
  // or is not the depth's size, no room for it): one line saying why. The depth still opens.
  Status confidence_ignored;
};

// The file's main XMP packet and its extended one, reassembled into `memory` ("" when the file has
// none); the photo's size from its frame header into out->width and out->height.
Status ReadXmpPackets(const uint8_t* data, size_t size, const char* name, RefocusableMemory& memory,
                      RefocusableFields* out, std::string_view* main, std::string_view* extended);

Status ReadRefocusableFields(const uint8_t* data, size_t size, const char* name,
                             RefocusableMemory& memory, RefocusableFields* out);

struct RefocusableImage {
  int32_t width = 0;  // the primary (refocused) image, from its frame header
  int32_t height = 0;
  RefocusableXmp xmp;  // depth.data holds the PNG bytes, image the original JPEG (may be empty)
  GrayPng depth;       // the decoded depth image, grey whatever colour type it was stored in
  // The decoded confidence map (xmp.depth.confidence holds its bytes): empty when the file has
  // none or it was ignored (confidence_ignored says why).
  GrayPng confidence;
  Status confidence_ignored;
  int32_t orientation = 0;  // the photo's EXIF Orientation 1..8, 0 when it records none
};

// Host side: allocates.
Status ReadRefocusable(const uint8_t* data, size_t size, const char* name, RefocusableImage* out);
Status ReadRefocusableFile(const char* path, RefocusableImage* out);

// The name the depth image goes by in messages ("<file>: GDepth:Data").
void DepthPngName(const char* name, char* out, size_t out_size);

// The depth image as Q8.8 disparity, with the range its Near and Far give (ScaledDisparityFromDepth
// at scale 1).
Status DisparityFromDepth(const RefocusableImage& image, std::vector<uint16_t>* disp_q8,
                          DisparityRange* range);

// The depth image (RangeInverse or RangeLinear) as Q8.8 disparity = `scale` / depth
// (DepthValuesToDisparity): a phone's depth is in its own units, not the product's 1 / px.
Status ScaledDisparityFromDepth(const RefocusableImage& image, double scale,
                                std::vector<uint16_t>* disp_q8, DisparityRange* range);

}  // namespace lb
