// Helpers for the JPEG tests: synthetic YCbCr images, an independent libjpeg decoder, PSNR,
// scratch directories and host tools.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "algo/core/image.h"

namespace lb::test {

// A YCbCr 4:2:0 image with owned planes: a smooth texture (gradients and a slow ripple) that a
// quality-95 JPEG keeps well above 35 dB.
struct Ycc420 {
  int32_t width = 0, height = 0;
  std::vector<uint8_t> y, cb, cr;
  int32_t cwidth() const { return (width + 1) / 2; }
  int32_t cheight() const { return (height + 1) / 2; }
  ConstPlanarU8 View() const;
  // Rows [y0, y0 + rows) as a strip the way the render stage hands it out.
  ConstPlanarU8 Strip(int32_t y0, int32_t rows) const;
};
Ycc420 MakeTexture(int32_t width, int32_t height);

// Decodes to full-resolution YCbCr (3 bytes a pixel). False on any libjpeg error.
bool DecodeYcc(const std::vector<uint8_t>& jpeg, int32_t* width, int32_t* height,
               std::vector<uint8_t>* ycc, std::string* error);
// PSNR of the decoded plane `c` (0 Y, 1 Cb, 2 Cr) against the source (chroma upsampled by
// repetition, as DecodeYcc does).
double PlanePsnr(const Ycc420& src, const std::vector<uint8_t>& ycc, int c);

std::vector<uint8_t> ReadFile(const std::string& path);

// mkdtemp directory removed on destruction.
class ScratchDir {
 public:
  ScratchDir();
  ~ScratchDir();
  std::string Path(const std::string& name) const { return dir_ + "/" + name; }
  std::vector<std::string> Entries() const;
  const std::string& dir() const { return dir_; }

 private:
  std::string dir_;
};

bool HaveTool(const char* name);
// Runs a shell command, returns its stdout; `*exit_code` gets the exit status.
std::string RunTool(const std::string& command, int* exit_code);

}  // namespace lb::test
