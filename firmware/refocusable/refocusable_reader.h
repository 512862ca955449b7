// Reads a refocusable JPEG: walks the segments before the image data, reassembles extended XMP
// by GUID and offset (checking it against its MD5), and extracts GDepth (fields and the decoded
// depth image), GImage (the original JPEG's bytes) and GFocus. Any defect is a Status naming the
// file and the problem; the reader never trusts a length it has not checked. Host side: allocates.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "algo/core/status.h"
#include "firmware/codecs/png_reader.h"
#include "firmware/refocusable/xmp_writer.h"

namespace lb {

struct RefocusableImage {
  int32_t width = 0;  // the primary (refocused) image, from its frame header
  int32_t height = 0;
  RefocusableXmp xmp;  // depth.data holds the PNG bytes, image the original JPEG (may be empty)
  GrayPng depth;       // the decoded depth image
  int32_t orientation = 0;  // the photo's EXIF Orientation 1..8, 0 when it records none
};

Status ReadRefocusable(const uint8_t* data, size_t size, const char* name, RefocusableImage* out);
Status ReadRefocusableFile(const char* path, RefocusableImage* out);

// The depth image as Q8.8 disparity (RangeInverse files), with the range its Near and Far give.
Status DisparityFromDepth(const RefocusableImage& image, std::vector<uint16_t>* disp_q8,
                          DisparityRange* range);

}  // namespace lb
