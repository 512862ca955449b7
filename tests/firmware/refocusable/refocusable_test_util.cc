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

std::vector<uint8_t> WithoutGDepth(const std::vector<uint8_t>& jpeg) {
  const std::string xmp(kXmpSignature, sizeof(kXmpSignature));
  const std::string extended(kExtendedXmpSignature, sizeof(kExtendedXmpSignature));
  if (jpeg.size() < 4 || jpeg[0] != 0xFF || jpeg[1] != 0xD8) return {};
  std::vector<uint8_t> out(jpeg.begin(), jpeg.begin() + 2);
  bool found = false;
  for (size_t pos = 2; pos + 4 <= jpeg.size();) {
    if (jpeg[pos] != 0xFF) return {};
    const uint8_t marker = jpeg[pos + 1];
    if (marker == 0xDA) {  // the scan and everything after it, items included
      out.insert(out.end(), jpeg.begin() + static_cast<ptrdiff_t>(pos), jpeg.end());
      return found ? out : std::vector<uint8_t>();
    }
    const size_t length = static_cast<size_t>(jpeg[pos + 2]) << 8 | jpeg[pos + 3];
    if (length < 2 || pos + 2 + length > jpeg.size()) return {};
    const std::string payload(jpeg.begin() + static_cast<ptrdiff_t>(pos + 4),
                              jpeg.begin() + static_cast<ptrdiff_t>(pos + 2 + length));
    const size_t next = pos + 2 + length;
    if (marker == 0xE1 && payload.compare(0, extended.size(), extended) == 0) {
      pos = next;
      continue;
    }
    if (marker == 0xE1 && payload.compare(0, xmp.size(), xmp) == 0) {
      const size_t device = payload.find("xmlns:Device=");
      const size_t begin = payload.rfind("<rdf:Description", device);
      const std::string close = "</rdf:Description>";
      const size_t end = payload.find(close, device);
      if (device == std::string::npos || begin == std::string::npos || end == std::string::npos) {
        return {};
      }
      JpegSegment seg;
      SetPayloadText(&seg, xmp +
                               "<x:xmpmeta xmlns:x=\"adobe:ns:meta/\">\n <rdf:RDF xmlns:rdf=\""
                               "http://www.w3.org/1999/02/22-rdf-syntax-ns#\">\n" +
                               payload.substr(begin, end + close.size() - begin) +
                               "\n </rdf:RDF>\n</x:xmpmeta>");
      const size_t n = seg.payload.size() + 2;
      out.insert(out.end(), {0xFF, 0xE1, static_cast<uint8_t>(n >> 8), static_cast<uint8_t>(n)});
      out.insert(out.end(), seg.payload.begin(), seg.payload.end());
      found = true;
      pos = next;
      continue;
    }
    out.insert(out.end(), jpeg.begin() + static_cast<ptrdiff_t>(pos),
               jpeg.begin() + static_cast<ptrdiff_t>(next));
    pos = next;
  }
  return {};
}

}  // namespace lb::test
