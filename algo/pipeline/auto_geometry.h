// Auto geometry: from the motion stage's estimate of a handheld burst to the depth stage's label
// range. Labels are planes of constant inverse depth rho, written as the disparity they cause
// for the burst's mean baseline per frame step:
//   disparity (working px per view step) = rho * px_per_inv_depth,
//   px_per_inv_depth = fx * sum_v |t_v| / sum_v |v - reference|,
// so on a rectified, equally spaced rig it is the rig's disparity per view step, whatever scale
// the motion estimate chose (only rho * t reaches pixels), and on a handheld burst it is the
// parallax of an average frame. The range is the tracked points' inverse-depth range (2nd to
// 98th percentile) widened by a fifth of its span on each side, so surfaces the corners missed
// (a textureless wall, the ground at the frame's edge) still find a label.
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

// kDegenerate when the estimate has no baseline or no depth range to label.
Status PlanLabelRange(const MotionResult& motion, int32_t labels, LabelRange* out);

// Hands a motion estimate to a kPlanes depth stage for its next Compute: the label range
// PlanLabelRange plans (set on the stage unless keep_range, for a range the caller chose) and the
// planes of those labels, built in `planes` (views x labels entries). `range` receives the plan.
Status SetDepthGeometry(const MotionResult& motion, bool keep_range, DepthStage* depth,
                        PlaneHomography* planes, LabelRange* range);

}  // namespace lb
