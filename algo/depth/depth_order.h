// Which end of a plane-sweep label range is near. Small motion leaves it open: w -> -w,
// t -> -t gives every pixel the same motion, and at a narrow field of view the weak terms that
// would pin the offset of inverse depth, and with it the sign, are lost in the noise. The
// views' occlusions tell: where two surfaces of the reference land on one pixel of a view, that
// pixel shows the nearer one.
//
// Per view: every reference pixel is splatted at the rounded position its label's plane maps it
// to; each view pixel keeps the highest and the lowest label that landed on it, each with its
// colour error (mean |dR|, |dG|, |dB| against the view's pixel there). Where the two labels are
// at least `min_gap` apart and one error is below the other by more than `margin`, the pixel
// votes for that candidate's end as near. Integer-only per pixel; the same votes on every
// target.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/image.h"
#include "algo/motion/plane_homography.h"

namespace lb {

struct DepthOrderVotes {
  int64_t high_near = 0;  // the view showed the higher label's surface
  int64_t low_near = 0;   // the lower label's
};

struct DepthOrderParams {
  int32_t min_gap = 4;  // labels between the two candidates
  int32_t margin = 6;   // grey levels between their errors
};

// Scratch bytes for a width x height reference.
inline size_t DepthOrderScratchBytes(int32_t width, int32_t height) {
  return static_cast<size_t>(width) * height * 4;
}

// `views` are RGB8 of one size; `labels` the reference's label map (row stride = width);
// planes[view * label_count + label] as DepthStage::SetPlanes takes them.
DepthOrderVotes VoteDepthOrder(const ConstImageU8* views, int32_t view_count, int32_t reference,
                               const uint8_t* labels, int32_t label_count,
                               const PlaneHomography* planes, const DepthOrderParams& params,
                               uint8_t* scratch);

}  // namespace lb
