// MJPEG frames for the tests and the decode benchmark, made with libjpeg itself: a test picture,
// its JPEG in a chosen subsampling, the same without Huffman tables (as UVC cameras send it), and
// a plain libjpeg decode to compare the sensor's against.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace lb::jpegtest {

struct Rgb {
  int32_t width = 0, height = 0;
  std::vector<uint8_t> pixels;  // packed R G B rows
  const uint8_t* at(int32_t x, int32_t y) const { return &pixels[(size_t(y) * width + x) * 3]; }
};

// Smooth colour ramps with soft texture and a little seeded noise: detail a camera sees, and
// what JPEG keeps within a few levels at high quality.
Rgb TestPicture(int32_t width, int32_t height, uint32_t seed);

// k1x4: luma sampled 1x4 against chroma, the most rows per column libjpeg keeps for any layout.
enum class Sampling { k444, k422, k420, k1x4 };
struct EncodeOptions {
  int quality = 90;
  Sampling sampling = Sampling::k422;  // what UVC cameras send
  bool progressive = false;
  int restart_rows = 0;  // MCU rows between restart markers, 0 none
};
// Empty on a libjpeg error.
std::vector<uint8_t> Encode(const Rgb& picture, const EncodeOptions& options);
// The frame without its DHT segments.
std::vector<uint8_t> WithoutHuffmanTables(const std::vector<uint8_t>& jpeg);
// Occurrences of the marker 0xFF `code` before the first scan.
int CountHeaderMarkers(const std::vector<uint8_t>& jpeg, uint8_t code);
// The segments with marker 0xFF `code` before the first scan, one after another.
std::vector<uint8_t> HeaderSegments(const std::vector<uint8_t>& jpeg, uint8_t code);
// Where the entropy-coded data of the first scan starts (0 when there is none).
size_t ScanStart(const std::vector<uint8_t>& jpeg);
// libjpeg's own decode to RGB with its default memory manager (empty on error).
Rgb DecodeWithLibjpeg(const std::vector<uint8_t>& jpeg);

}  // namespace lb::jpegtest
