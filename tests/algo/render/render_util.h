// Runs the product's render stage over a whole image (tests only: it keeps every strip).
#pragma once

#include <cstdint>
#include <vector>

#include "algo/render/render_stage.h"
#include "tests/algo/render/reference_render.h"

namespace lb::test {

struct Rendered {
  std::vector<uint8_t> y, cb, cr;
  std::vector<int32_t> strip_rows;  // rows of each strip, in order
  float radius_per_disp = 0;
  float focus_disp = 0;
  PlaneF Luma(int32_t width, int32_t height) const {
    return PlaneF{width, height, std::vector<float>(y.begin(), y.end())};
  }
};

struct RenderSetup {
  int32_t max_radius = 16;
  RenderParams params;
  int32_t workers = 1;           // RenderConfig::workers
  TaskRunner* runner = nullptr;  // borrowed; nullptr: the caller
};

// Configures a stage for the scene, renders every strip and checks the strip sequence.
Status RenderAll(const ConstPlanarU8& ref, ConstImageU16 disp_q8, int32_t scale,
                 const RenderSetup& setup, Rendered* out);

}  // namespace lb::test
