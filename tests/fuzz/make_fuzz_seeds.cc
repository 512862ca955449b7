// Writes small valid seed images for the reader fuzzers: OUT/pnm, OUT/png, OUT/jpeg. Generated
// at run time with the reference encoders so no third-party file is committed.
#include <png.h>
#include <sys/stat.h>

#include <cstdio>
#include <string>
#include <vector>

#include "tests/sim/files/test_images.h"

namespace {

using lb::test::Bytes;

int failures = 0;

void Save(const std::string& dir, const std::string& name, const Bytes& bytes) {
  mkdir(dir.c_str(), 0755);
  if (!lb::test::WriteFile(dir + "/" + name, bytes)) {
    fprintf(stderr, "make_fuzz_seeds: cannot write %s/%s\n", dir.c_str(), name.c_str());
    ++failures;
  }
}

std::vector<uint16_t> Ramp(size_t count, int maxval) {
  std::vector<uint16_t> samples(count);
  for (size_t i = 0; i < count; ++i) samples[i] = static_cast<uint16_t>((i * 37) % (maxval + 1));
  return samples;
}

void Pnm(const std::string& dir) {
  Save(dir, "rgb8_comments.ppm",
       lb::test::EncodePnm("P6", 4, 3, 255, Ramp(36, 255), " # comment\n"));
  Save(dir, "gray16.pgm", lb::test::EncodePnm("P5", 3, 2, 65535, Ramp(6, 65535)));
  Save(dir, "gray_maxval1023.pgm", lb::test::EncodePnm("P5", 5, 2, 1023, Ramp(10, 1023)));
  Save(dir, "rgb_maxval15.ppm", lb::test::EncodePnm("P6", 2, 2, 15, Ramp(12, 15)));
  Save(dir, "gray_strips.pgm", lb::test::EncodePnm("P5", 3, 20, 255, Ramp(60, 255)));
}

Bytes Png(int width, int height, int color_type, int bit_depth, bool interlaced,
          bool transparent = false) {
  lb::test::PngSpec spec{width, height, color_type, bit_depth, interlaced, {}, {}, transparent};
  const int channels[] = {1, 0, 3, 1, 2, 0, 4};
  const size_t row_bytes =
      (static_cast<size_t>(width) * static_cast<size_t>(channels[color_type]) * bit_depth + 7) / 8;
  for (size_t i = 0; i < row_bytes * static_cast<size_t>(height); ++i) {
    spec.rows.push_back(static_cast<uint8_t>(color_type == 3 ? i % 3 : i * 13));
  }
  if (color_type == PNG_COLOR_TYPE_PALETTE) spec.palette_rgb = {0, 0, 0, 200, 10, 10, 9, 250, 9};
  Bytes out;
  if (!lb::test::EncodePng(spec, &out)) ++failures;
  return out;
}

void PngSeeds(const std::string& dir) {
  Save(dir, "rgb8.png", Png(5, 18, PNG_COLOR_TYPE_RGB, 8, false));
  Save(dir, "gray8.png", Png(4, 4, PNG_COLOR_TYPE_GRAY, 8, false));
  Save(dir, "rgb16.png", Png(3, 3, PNG_COLOR_TYPE_RGB, 16, false));
  Save(dir, "gray16.png", Png(3, 3, PNG_COLOR_TYPE_GRAY, 16, false));
  Save(dir, "rgba8.png", Png(3, 3, PNG_COLOR_TYPE_RGB_ALPHA, 8, false));
  Save(dir, "gray_alpha16.png", Png(3, 3, PNG_COLOR_TYPE_GRAY_ALPHA, 16, false));
  Save(dir, "palette2.png", Png(6, 3, PNG_COLOR_TYPE_PALETTE, 2, false));
  Save(dir, "gray1.png", Png(9, 2, PNG_COLOR_TYPE_GRAY, 1, false));
  Save(dir, "adam7_rgb8.png", Png(11, 9, PNG_COLOR_TYPE_RGB, 8, true));
  Save(dir, "adam7_palette4.png", Png(7, 7, PNG_COLOR_TYPE_PALETTE, 4, true));
  Save(dir, "palette8_trns.png", Png(4, 4, PNG_COLOR_TYPE_PALETTE, 8, false, true));
  Save(dir, "gray4_trns.png", Png(5, 3, PNG_COLOR_TYPE_GRAY, 4, false, true));
}

Bytes Jpeg(int width, int height, int components, bool progressive) {
  std::vector<uint8_t> pixels;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < components; ++c) pixels.push_back(lb::test::Smooth(x, y, c));
    }
  }
  Bytes out;
  if (!lb::test::EncodeJpeg(width, height, components, pixels.data(), 75, progressive, &out)) {
    ++failures;
  }
  return out;
}

void JpegSeeds(const std::string& dir) {
  Save(dir, "rgb.jpg", Jpeg(16, 16, 3, false));
  Save(dir, "gray.jpg", Jpeg(9, 17, 1, false));
  Save(dir, "progressive.jpg", Jpeg(20, 12, 3, true));
  Save(dir, "cmyk.jpg", Jpeg(8, 8, 4, false));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: make_fuzz_seeds OUT_DIR\n");
    return 2;
  }
  const std::string out = argv[1];
  mkdir(out.c_str(), 0755);
  Pnm(out + "/pnm");
  PngSeeds(out + "/png");
  JpegSeeds(out + "/jpeg");
  return failures == 0 ? 0 : 1;
}
