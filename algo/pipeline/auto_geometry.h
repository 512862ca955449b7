// Auto geometry: from the motion stage's estimate of a handheld burst to the depth stage's label
// range. Labels are planes of constant inverse depth rho, written as the disparity they cause
// for the burst's mean baseline per view step:
//   disparity (working px per view step) = rho * px_per_inv_depth,
//   px_per_inv_depth = fx * sum_v |t_v| / sum_v steps_v,
// a frame's steps being its hops from the reference along the shortest tree joining the
// frames' translations (view_tree.h), not its place in the list. So on a rectified, equally
// spaced rig (a row, a cross) it is the rig's disparity per view step, whatever scale the
// motion estimate chose (only rho * t reaches pixels) and whatever order the frames came in,
// and on a handheld burst it is the parallax of a step between neighbouring viewpoints. Signed: rho
// may be negative (beyond the motion's infinity, motion_stage.h), and the range goes on through 0.
// The range covers the tracked points' inverse-depth range (2nd to 98th percentile) widened by a
// fifth of its span on each side, so surfaces the corners missed (a textureless wall, the ground at
// the frame's edge) still find a label.
//
// The labels are a window of a fixed lattice, not the range cut into equal parts: the spacing
// is a whole number of sixteenths of a pixel per view step, and label 0 sits on a multiple of
// `lattice` spacings from infinity (disparity 0), so the coarse pass's labels (every
// coarse_step-th) lie on one lattice through infinity whatever the points' percentiles, and a
// rectified rig's whole pixels are among them. Measured on the Middlebury sets with the rig's
// true poses: the range cut into 64 equal parts gives tsukuba 2.4-4.1 % bad pixels and venus
// 0.8-1.4 %, depending on where the percentiles fall; on the lattice 1.5 % and 0.6 %, the
// rectified figures (README, "Motion and auto geometry").
#pragma once

#include <cstdint>

#include "algo/core/status.h"
#include "algo/depth/depth_stage.h"
#include "algo/motion/motion_stage.h"

namespace lb {

struct LabelRange {
  int32_t disp_min_q8 = 0;  // working px per view step, Q8.8
  int32_t disp_max_q8 = 0;
  double px_per_inv_depth = 0;
};

struct LabelPlan {
  int32_t labels = 64;
  int32_t quantum_q8 = 16;  // the spacing is a multiple of this, Q8.8 px per view step
  int32_t lattice = 4;  // label 0 on a multiple of this many spacings (0: anywhere; <= labels - 2)
};

// kDegenerate when the estimate has no baseline or no depth range to label.
Status PlanLabelRange(const MotionResult& motion, const LabelPlan& plan, LabelRange* out);

// Hands a motion estimate to a kKnownPoses depth stage for its next Compute: the label range
// PlanLabelRange plans for the stage's labels and coarse step (set on the stage unless
// keep_range, for a range the caller chose) and the
// planes of those labels, built in `planes` (views x labels entries). `range` receives the plan.
Status SetDepthGeometry(const MotionResult& motion, bool keep_range, DepthStage* depth,
                        PlaneHomography* planes, LabelRange* range);

// After a kKnownPoses Compute on the planes SetDepthGeometry built for `motion`: asks the views'
// occlusions which end of the label range is near (depth_order.h) and, when a clear majority
// (twice the other's votes) says the low end, reverses the depth: the map (d -> -d), the
// stage's range and the motion (MotionStage::ReverseDepth; nullptr stage or motion: left as
// they are). `scratch` holds
// DepthOrderScratchBytes; `reversed`, when set, says whether it did.
Status OrderDepth(const ConstImageU8* views, const PlaneHomography* planes, uint8_t* scratch,
                  DepthStage* depth, MotionStage* stage, MotionResult* motion, ImageU16 map,
                  bool* reversed);

}  // namespace lb
