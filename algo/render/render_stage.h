// Render stage: the synthetic shallow depth of field. Reads the full-resolution reference
// (YCbCr 4:2:0) and the working-resolution disparity, and produces the output strip by strip
// (16 luma rows and 8 chroma rows at a time, the JPEG encoder's MCU row), so no full-resolution
// output is ever held.
//
// Per strip: the disparity is upsampled edge-aware to full resolution (depth_upsample.h), turned
// into a signed blur radius by the lens model (lens_model.h: linear in |d - d_focus|, scaled by
// 1/f-number, capped at max_radius), each pixel is split between two neighbouring depth layers,
// and the layers are blurred by the aperture's shape (aperture.h) and composited back to front
// (layer_plane.h). Everything is fixed point after Begin; the output is the same on every CPU.
//
// Lens model (lens_model.h): radius_px = 2 * (2.8 / f_number) * working_scale * |d - d_focus|,
// d in working px per view step (at f/2.8 the synthetic lens spans the 4 view steps of a 5-frame
// burst), capped at max_radius; d_focus is the median disparity of the focus region.
// Memory: rings of rows and one strip's accumulators, sized by the width and max_radius (about
// 5.3 MiB at 4056 px wide and max_radius 32); nothing is allocated after Configure.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/arena.h"
#include "algo/core/image.h"
#include "algo/core/status.h"
#include "algo/core/task_runner.h"
#include "algo/render/depth_upsample.h"
#include "algo/render/layer_plane.h"
#include "algo/render/lens_model.h"

namespace lb {

struct FocusRegion {
  int32_t x = 0, y = 0;  // top-left, full-resolution pixels
  // 0 x 0 means the default region (the central ninth of the image); a region under 3x3
  // working px (e.g. a tapped point, 1 x 1) is grown to 3x3 around its centre.
  int32_t width = 0, height = 0;
};

struct Aperture {
  int32_t blades = 0;         // 0 = a disc; 3..12 = a polygonal iris
  float rotation_deg = 0.0f;  // rotation of the polygon (0: a flat blade edge faces +x)
  float curvature = 0.0f;     // 0 = straight blades, 1 = a disc
};

struct RenderParams {
  // The f-numbers the product accepts anywhere (settings, the command line, the camera's page):
  // as on a lens, f/1 .. f/22.
  static constexpr float kMinFNumber = 1.0f, kMaxFNumber = 22.0f;
  FocusRegion focus;
  float f_number = 2.8f;  // kMinFNumber .. kMaxFNumber
  Aperture aperture;
  // Highlights: luma at or above the threshold is multiplied by a gain that ramps from 1 at the
  // threshold to highlight_gain at 255 before blurring, so point lights make bright bokeh balls.
  uint8_t highlight_threshold = 255;
  float highlight_gain = 1.0f;  // 1 = no boost, at most 8
};

struct RenderConfig {
  static constexpr int32_t kStripRows = 16;  // luma rows per strip (JPEG 4:2:0 MCU row)

  int32_t width = 0;  // full (output) resolution
  int32_t height = 0;
  int32_t working_scale = 1;  // full-resolution pixels per working-resolution pixel
  int32_t working_width = 0;
  int32_t working_height = 0;
  int32_t max_radius = 32;  // largest blur radius in full-resolution pixels
  // Strips rendered at once, one per worker (task_runner.h), 1..kMaxWorkers: each worker's
  // accumulators and output strip, and ring rows for that many strips, come from the arena.
  int32_t workers = 1;
};

class RenderStage {
 public:
  static Status Validate(const RenderConfig& config);
  static size_t RequiredBytes(const RenderConfig& config);
  Status Configure(const RenderConfig& config, Arena& arena);
  const RenderConfig& config() const { return config_; }
  // Where the strips of a batch render (borrowed; nullptr: on the caller), with at most
  // config.workers workers. The output does not depend on it.
  void SetRunner(TaskRunner* runner);

  // Starts a render. `ref` is Y, Cb, Cr (chroma at half size); `disp_q8` the working-resolution
  // disparity (see depth_stage.h). Both must stay valid until the last strip.
  Status Begin(const ConstPlanarU8& ref, ConstImageU16 disp_q8, const RenderParams& params);

  // Renders the next strip into an arena buffer and points `strip` at it: strip->planes[0] has
  // `*rows` luma rows starting at `*y0`, planes 1 and 2 the matching (rows+1)/2 chroma rows.
  // `*rows` is 0 once the image is complete. The strips come in batches of config.workers,
  // rendered at once; a strip stays valid until the call after the batch's last.
  Status NextStrip(ConstPlanarU8* strip, int32_t* y0, int32_t* rows);

  // What the lens model computed in Begin (for GFocus metadata and re-rendering):
  // the disparity (Q8.8, working px) that the focus region put in focus,
  int32_t focus_disp_q8() const { return lens_.focus_disp_q8(); }
  // the blur radius in full-resolution px per working px of disparity difference,
  float radius_per_disp() const { return lens_.radius_per_disp(); }
  // and the blur radius of a point at infinity (disparity 0), before the max_radius cap.
  float blur_at_infinity() const {
    return radius_per_disp() * static_cast<float>(lens_.focus_disp_q8()) / 256.0f;
  }
  // Signed blur radius (Q4 full-resolution px; + nearer, - farther) of a disparity, after Begin.
  int32_t SignedRadiusQ4(int32_t disp_q8) const { return lens_.SignedRadiusQ4(disp_q8); }

  // Distinct layer radii (0..max_radius): each is a kernel of both layer planes.
  static constexpr int32_t kMaxRadii = LayerPlane::kMaxKernels;
  // Radii of the depth layers, Q4 px, ascending from 0; returns how many, at most kMaxRadii
  // (out may be null).
  static int32_t LayerRadiiQ4(int32_t max_radius, int32_t* out);
  static Status ValidateParams(const RenderParams& params);

 private:
  Status Carve(Arena& arena);
  Status RenderBatch();
  void FillTables();
  // The ring rows a batch reads, split over the workers: luma rows first (the chroma rows'
  // radii are their 2x2 blocks' means).
  void FillRows(int32_t luma_end, int32_t chroma_end);
  void FillLumaRow(int32_t y, int32_t worker);
  void FillChromaRow(int32_t y);

  RenderConfig config_;
  ConstPlanarU8 ref_;
  ConstImageU16 disp_;
  RenderParams params_;
  PlanarU8 strips_[kMaxWorkers];
  int32_t batch_y0_ = 0, batch_count_ = 0, batch_next_ = 0;  // the batch being handed out
  InlineRunner inline_;
  TaskRunner* runner_ = &inline_;
  int32_t next_row_ = 0;
  bool begun_ = false;
  bool luma_stale_ = false;  // a chroma row was made from a recycled luma row (a bug)
  LensModel lens_;
  DepthUpsampler upsampler_;
  LayerPlane luma_, chroma_;
  int32_t radii_ = 0, layers_ = 0;
  int32_t luma_reach_ = 0, chroma_reach_ = 0;
  int32_t* radii_q4_ = nullptr;           // radii_
  int32_t* radius_of_layer_ = nullptr;    // layers_: kernel index of each layer, far to near
  uint16_t* layer_of_ = nullptr;          // [signed radius Q4 + max_radius * 16]: layer << 8 | frac
  uint16_t* disp_row_[kMaxWorkers] = {};  // per worker: one upsampled row
  uint16_t* boost_q8_ = nullptr;          // [luma]: highlight gain, Q8
  uint32_t* histogram_ = nullptr;         // 256 bins for the focus median
};

}  // namespace lb
