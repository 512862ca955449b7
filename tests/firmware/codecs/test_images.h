// Small encoders for test images, written with the reference libraries (libpng, libjpeg) so the
// readers are checked against an independent writer. Shared by the reader tests and the fuzz
// seed writer (tests/fuzz/make_fuzz_seeds.cc); no GoogleTest here.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace lb::test {

using Bytes = std::vector<uint8_t>;

// A netpbm file: `magic` "P5" or "P6", `header_gap` is put between the header fields (it may
// hold comments), samples big-endian when maxval > 255.
Bytes EncodePnm(const char* magic, int width, int height, int maxval,
                const std::vector<uint16_t>& samples, const std::string& header_gap = "\n");

struct PngSpec {
  int width = 0;
  int height = 0;
  int color_type = 2;  // PNG_COLOR_TYPE_*
  int bit_depth = 8;
  bool interlaced = false;
  std::vector<uint8_t> palette_rgb;  // for color type 3
  // Rows in PNG's own layout: packed low bit depths, 16-bit big-endian.
  Bytes rows;
  bool transparent = false;  // a tRNS chunk: palette entry 0, or grey/colour value 0
};
// Returns false when libpng refuses the spec.
bool EncodePng(const PngSpec& spec, Bytes* out);

// components 1 (grey), 3 (RGB) or 4 (CMYK).
bool EncodeJpeg(int width, int height, int components, const uint8_t* pixels, int quality,
                bool progressive, Bytes* out);

// A smooth pattern that JPEG keeps within a few levels: channel c of pixel (x, y).
uint8_t Smooth(int x, int y, int c);

// Finds the first chunk of `type` ("IDAT"); returns its offset (the length field) or -1.
long FindPngChunk(const Bytes& png, const char* type);

bool WriteFile(const std::string& path, const Bytes& bytes);

}  // namespace lb::test
