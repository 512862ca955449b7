// The depth map a photo carries and the render uses: the depth stage's labels on a grid as fine
// as the photo needs (at least half its side, or a megapixel when that is smaller), its edges
// taken from the photo.
//
// Each map pixel is the render's edge-aware upsampling of the stage's disparity
// (depth_upsample.h) at its centre, in the mode that keeps one side of a depth edge: a pixel
// there takes the side whose colour it shares (between neighbours of one colour, the sure ones
// over the unsure), never a mix of both; on the stage's own grid this moves a label edge that
// missed the photo's by a pixel onto it. An odd map_scale has a full-resolution pixel at each
// map pixel's centre; an even one takes the mean of the four around it. Values become map px
// per view step, so a reader that knows only the map and the photo gets the blur the product
// rendered.
//
// Measured alternatives (docs/accuracy.md): smoothing the whole map along the photo's surfaces
// (a confidence-weighted domain-transform filter), and filling unsure pixels from sure ones of
// their colour, both made the synthetic scenes' maps worse: the labels' errors are not where the
// confidence is low, and any fill that looks only at its neighbours' depths flattens a surface
// that slants.
//
// Fixed point; the same bits for any number of workers. Memory: one upsampler and four rows of
// samples per worker, carved once (RequiredBytes) in the region the depth stage and the render
// take turns in.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/arena.h"
#include "algo/core/image.h"
#include "algo/core/task_runner.h"
#include "algo/render/depth_upsample.h"

namespace lb {

struct RefineConfig {
  int32_t width = 0, height = 0;                            // the reference, full resolution
  int32_t work_scale = 1, work_width = 0, work_height = 0;  // the depth stage's grid
  int32_t map_scale = 1, map_width = 0, map_height = 0;     // map_scale <= work_scale
  int32_t workers = 1;
};

class DepthRefiner {
 public:
  // The map's grid for a photo: the largest integer factor, at most the depth stage's, that keeps
  // at least half the photo's side or 1 MP (1 << 20 px), whichever is smaller.
  static int32_t MapScale(int32_t width, int32_t height, int32_t work_scale);

  static size_t RequiredBytes(const RefineConfig& config);
  void Carve(const RefineConfig& config, Arena& arena);
  void SetRunner(TaskRunner* runner);

  // Makes the map (Q8.8, map px per view step) and its confidence (the depth stage's, at the
  // nearest of its pixels; left alone when empty) from the stage's disparity (Q8.8, working px)
  // and confidence (empty: all equally sure), guided by the reference `ref`.
  void Run(const ConstPlanarU8& ref, ConstImageU16 disp_q8, ConstImageU8 confidence,
           ImageU16 map_q8, ImageU8 map_confidence);

 private:
  void Rows(ConstImageU8 confidence, ImageU16 map_q8, ImageU8 map_confidence, int32_t y0,
            int32_t y1, int32_t worker);
  uint16_t ToMap(uint32_t working_q8) const;

  RefineConfig config_;
  InlineRunner inline_;
  TaskRunner* runner_ = &inline_;
  DepthUpsampler upsampler_;                // map_scale < work_scale only
  uint16_t* samples_[kMaxWorkers][4] = {};  // per worker: up to 4 rows of map-grid samples
};

}  // namespace lb
