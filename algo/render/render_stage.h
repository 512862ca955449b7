// Render stage: the synthetic shallow depth of field. Reads the full-resolution reference
// (YCbCr 4:2:0) and the working-resolution disparity, and produces the output strip by strip
// (16 luma rows and 8 chroma rows at a time, the JPEG encoder's MCU row), so no full-resolution
// output is ever held.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/arena.h"
#include "algo/core/image.h"
#include "algo/core/status.h"

namespace lb {

struct FocusRegion {
  int32_t x = 0, y = 0;           // top-left, full-resolution pixels
  int32_t width = 0, height = 0;  // 0 x 0 means "the default region" (the image centre)
};

struct Aperture {
  int32_t blades = 0;         // 0 = a disc; 3..12 = a polygonal iris
  float rotation_deg = 0.0f;  // rotation of the polygon
  float curvature = 0.0f;     // 0 = straight blades, 1 = a disc
};

struct RenderParams {
  FocusRegion focus;
  float f_number = 2.8f;  // as set on a lens: f/1.4 .. f/16
  Aperture aperture;
  uint8_t highlight_threshold = 255;  // luma at or above which highlights are boosted
  float highlight_gain = 1.0f;        // 1 = no boost
};

struct RenderConfig {
  static constexpr int32_t kStripRows = 16;  // luma rows per strip (JPEG 4:2:0 MCU row)

  int32_t width = 0;  // full (output) resolution
  int32_t height = 0;
  int32_t working_scale = 1;  // full-resolution pixels per working-resolution pixel
  int32_t working_width = 0;
  int32_t working_height = 0;
  int32_t max_radius = 32;  // largest blur radius in full-resolution pixels
};

class RenderStage {
 public:
  static Status Validate(const RenderConfig& config);
  static size_t RequiredBytes(const RenderConfig& config);
  Status Configure(const RenderConfig& config, Arena& arena);

  // Starts a render. `ref` is Y, Cb, Cr (chroma at half size); `disp_q8` the working-resolution
  // disparity (see depth_stage.h). Both must stay valid until the last strip.
  Status Begin(const ConstPlanarU8& ref, ConstImageU16 disp_q8, const RenderParams& params);

  // Renders the next strip into an arena buffer and points `strip` at it: strip->planes[0] has
  // `*rows` luma rows starting at `*y0`, planes 1 and 2 the matching (rows+1)/2 chroma rows.
  // `*rows` is 0 once the image is complete.
  Status NextStrip(ConstPlanarU8* strip, int32_t* y0, int32_t* rows);

  // The disparity (Q8.8) that the focus region put in focus, valid after Begin.
  int32_t focus_disp_q8() const { return focus_disp_q8_; }

 private:
  Status Carve(Arena& arena);
  int32_t RadiusQ8(int32_t disp_q8) const;

  RenderConfig config_;
  ConstPlanarU8 ref_;
  ConstImageU16 disp_;
  RenderParams params_;
  PlanarU8 strip_;
  int32_t next_row_ = 0;
  int32_t focus_disp_q8_ = 0;
  int32_t blur_per_disp_q8_ = 0;   // radius (Q8 px) per Q8 disparity difference, scaled by 256
  uint16_t* histogram_ = nullptr;  // disparity histogram for the focus statistic
};

}  // namespace lb
