#include "algo/pipeline/auto_geometry.h"

#include "algo/depth/planes.h"

namespace lb {

Status PlanLabelRange(const MotionResult& m, int32_t labels, LabelRange* out) {
  double baseline = 0;
  int32_t steps = 0;
  for (int32_t v = 0; v < m.views; ++v) {
    if (v == m.reference) continue;
    const double* t = m.motion[v].translation;
    baseline += __builtin_sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    steps += v > m.reference ? v - m.reference : m.reference - v;
  }
  const double s = steps > 0 ? m.intrinsics.fx * baseline / steps : 0;
  const double span = m.inv_depth_max - m.inv_depth_min;
  if (!(s > 0) || !(span >= 0) || !(m.inv_depth_max > 0)) {
    return Status(Code::kDegenerate,
                  "the camera did not move between frames: move it a little sideways between "
                  "frames");
  }
  double lo = (m.inv_depth_min - 0.2 * span) * s * 256.0;
  double hi = (m.inv_depth_max + 0.2 * span) * s * 256.0;
  lo = lo > 0 ? lo : 0;
  // At least one Q8 step per label, and within the depth stage's 16-bit disparities.
  if (hi < lo + labels) hi = lo + labels;
  if (hi > 65535) hi = 65535;
  if (lo > hi - labels) lo = hi - labels;
  out->disp_min_q8 = static_cast<int32_t>(lo);
  out->disp_max_q8 = static_cast<int32_t>(hi + 0.999);
  out->px_per_inv_depth = s;
  return Status::Ok();
}

Status SetDepthGeometry(const MotionResult& motion, bool keep_range, DepthStage* depth,
                        PlaneHomography* planes, LabelRange* range) {
  LB_RETURN_IF_ERROR(PlanLabelRange(motion, depth->config().labels, range));
  if (!keep_range) {
    LB_RETURN_IF_ERROR(depth->SetDisparityRange(range->disp_min_q8, range->disp_max_q8));
  }
  MakeLabelPlanes(motion, depth->config(), range->px_per_inv_depth, planes);
  return depth->SetPlanes(planes);
}

}  // namespace lb
