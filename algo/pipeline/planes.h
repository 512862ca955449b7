// Label planes for the plane-sweep depth geometry: label l is the fronto-parallel plane at
// inverse depth LabelDispQ8(l) / 256 / px_per_inv_depth (in the motion result's units), so the
// depth map's disparity is px_per_inv_depth times inverse depth. Choose px_per_inv_depth as the
// pixels a unit of inverse depth moves a point in a typical view (focal length times the mean
// baseline) to keep the label step a fixed fraction of a pixel of motion. It joins the motion
// stage's result to the depth stage's labels, so it lives with the pipeline that composes them.
#pragma once

#include "algo/depth/depth_stage.h"
#include "algo/motion/motion_stage.h"

namespace lb {

// Fills out[v * config.labels + l] for every view v (the reference's is the identity) and label
// l: the array DepthStage::SetPlanes takes. Double geometry, configure-time cost (views x labels
// homographies).
void MakeLabelPlanes(const MotionResult& motion, const DepthConfig& config, double px_per_inv_depth,
                     PlaneHomography* out);

}  // namespace lb
