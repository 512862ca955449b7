#include "tests/firmware/refocusable/refocusable_test_util.h"

namespace lb::test {

RefocusSample MakeRefocusSample(bool large, int bits) {
  RefocusSample s;
  s.picture = MakeTexture(large ? 480 : 48, large ? 320 : 32);
  s.disp_width = s.picture.width / 2;
  s.disp_height = s.picture.height / 2;
  s.range = {0, 16 << 8};
  s.disp_q8.resize(static_cast<size_t>(s.disp_width) * s.disp_height);
  uint32_t state = 12345;
  for (int32_t y = 0; y < s.disp_height; ++y) {
    for (int32_t x = 0; x < s.disp_width; ++x) {
      state = state * 1664525u + 1013904223u;
      const int32_t smooth = 256 + (x + y) * 3500 / (s.disp_width + s.disp_height);
      s.disp_q8[static_cast<size_t>(y) * s.disp_width + x] =
          static_cast<uint16_t>(large ? 1 + (state >> 8) % 4096 : smooth);
    }
  }
  ConstImageU16 disp = MakeView<const uint16_t>(s.disp_q8.data(), s.disp_width, s.disp_height);
  if (!SetDepthFromDisparity(disp, s.range, bits, &s.xmp).ok()) return s;
  if (large && !EncodeYCbCr420(s.picture.View(), 90, &s.xmp.image).ok()) return s;
  s.xmp.has_focus = true;
  s.xmp.focus = {0.0125, 0.25, 0.375, 0.625};
  if (!BuildXmpSegments(s.xmp, &s.segments).ok()) s.segments.clear();
  return s;
}

std::vector<uint8_t> WriteRefocusJpeg(const RefocusSample& s,
                                      const std::vector<JpegSegment>& segments) {
  JpegMetadata meta;
  meta.make = "LensBlur";
  meta.model = "PS-1";
  meta.f_number = 2.8f;
  meta.extra_segments = segments;
  std::vector<uint8_t> jpeg;
  JpegWriter writer;
  if (!writer.BeginMemory(&jpeg, s.picture.width, s.picture.height, 90, meta).ok()) return {};
  for (int32_t y = 0; y < s.picture.height; y += 16) {
    const int32_t rows = s.picture.height - y < 16 ? s.picture.height - y : 16;
    if (!writer.WriteStrip(s.picture.Strip(y, rows), rows).ok()) return {};
  }
  if (!writer.Finish().ok()) return {};
  return jpeg;
}

std::string PayloadText(const JpegSegment& seg) {
  return std::string(seg.payload.begin(), seg.payload.end());
}

void SetPayloadText(JpegSegment* seg, const std::string& text) {
  seg->payload.assign(text.begin(), text.end());
}

}  // namespace lb::test
