// Sample refocusable JPEGs for the XMP tests: a textured picture, a disparity map and the
// segments the firmware would write, kept editable so tests can break them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "firmware/refocusable/xmp_writer.h"
#include "tests/firmware/codecs/jpeg_test_util.h"

namespace lb::test {

struct RefocusSample {
  Ycc420 picture;
  int32_t disp_width = 0, disp_height = 0;
  std::vector<uint16_t> disp_q8;
  DisparityRange range;
  RefocusableXmp xmp;
  std::vector<JpegSegment> segments;
};

// `large` gives an incompressible depth map (and an all-in-focus original), so the XMP needs
// extended chunks; otherwise a small smooth map that fits one packet.
RefocusSample MakeRefocusSample(bool large, int bits = 16);

// The JPEG bytes of `s.picture` with EXIF and `segments`.
std::vector<uint8_t> WriteRefocusJpeg(const RefocusSample& s,
                                      const std::vector<JpegSegment>& segments);

std::string PayloadText(const JpegSegment& seg);
void SetPayloadText(JpegSegment* seg, const std::string& text);

// A refocusable JPEG with its GDepth part removed, as a Dynamic Depth writer that knows nothing of
// GDepth would have written it: the extended XMP dropped, the main packet cut to the Dynamic
// Depth Device element, the items after the EOI kept. Empty when the file has no Device element.
std::vector<uint8_t> WithoutGDepth(const std::vector<uint8_t>& jpeg);

}  // namespace lb::test
