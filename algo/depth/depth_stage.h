// Depth stage: from the working-resolution views of a burst to a disparity map of the reference
// view. Disparity is in working-resolution pixels per view step, unsigned Q8.8 (`dispQ8`): a
// point at disparity d appears at x - k*d in the view k steps to the right of the reference and
// at x + k*d in the view k steps to its left (the views are rectified and equally spaced).
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/arena.h"
#include "algo/core/image.h"
#include "algo/core/status.h"

namespace lb {

struct DepthConfig {
  static constexpr int32_t kMaxViews = 16;
  static constexpr int32_t kMaxLabels = 256;

  int32_t width = 0;  // working resolution
  int32_t height = 0;
  int32_t views = 0;
  int32_t reference = 0;    // index of the reference among the views
  int32_t labels = 0;       // number of disparity planes
  int32_t disp_min_q8 = 0;  // disparity of label 0 and of the last label, px per view step, Q8.8
  int32_t disp_max_q8 = 0;
};

struct DepthStats {
  int32_t labels = 0;
  int32_t cycles = 0;      // expansion cycles run
  int64_t energy = 0;      // final energy
  size_t arena_bytes = 0;  // bytes this stage carved from the arena
};

class DepthStage {
 public:
  // Checks a configuration without touching memory.
  static Status Validate(const DepthConfig& config);
  // Bytes of arena that Configure will carve for this configuration.
  static size_t RequiredBytes(const DepthConfig& config);

  Status Configure(const DepthConfig& config, Arena& arena);

  // `views[i]` are RGB8 working-resolution images, left to right. Writes dispQ8 for every pixel
  // of the reference view into `disp_q8` (width x height, one channel).
  Status Compute(const ConstImageU8* views, ImageU16 disp_q8);

  const DepthStats& stats() const { return stats_; }
  const DepthConfig& config() const { return config_; }

 private:
  Status Carve(Arena& arena);

  DepthConfig config_;
  DepthStats stats_;
  uint32_t* best_cost_ = nullptr;  // per pixel: lowest cost seen so far
};

}  // namespace lb
