#include "algo/pipeline/auto_geometry.h"

#include "algo/depth/depth_order.h"
#include "algo/motion/view_tree.h"
#include "algo/pipeline/planes.h"

namespace lb {

static_assert(MotionConfig::kMaxViews <= kMaxTreePoints);

Status PlanLabelRange(const MotionResult& m, const LabelPlan& plan, LabelRange* out) {
  // The unit: the mean baseline per step, the steps counted along the viewpoints' tree
  // (view_tree.h), not along the list, so the same frames in any order get the same labels.
  double positions[3 * MotionConfig::kMaxViews] = {};
  int32_t parent[MotionConfig::kMaxViews], hops[MotionConfig::kMaxViews];
  const int32_t views = m.views <= MotionConfig::kMaxViews ? m.views : 0;
  for (int32_t v = 0; v < views; ++v) {
    for (int32_t k = 0; k < 3; ++k) positions[3 * v + k] = m.motion[v].translation[k];
  }
  double baseline = 0;
  int32_t steps = 0;
  if (ViewTree(positions, views, 3, m.reference, parent, hops)) {
    for (int32_t v = 0; v < views; ++v) {
      if (v == m.reference) continue;
      const double* t = m.motion[v].translation;
      baseline += __builtin_sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
      steps += hops[v];
    }
  }
  const double s = steps > 0 ? m.intrinsics.fx * baseline / steps : 0;
  const double span = m.inv_depth_max - m.inv_depth_min;
  if (plan.labels < 2 || plan.quantum_q8 < 1 || plan.lattice < 0 ||
      (plan.lattice > 0 && plan.lattice > plan.labels - 2)) {
    return Status(Code::kInvalidArgument, "label plan: %d labels, quantum %d, lattice %d",
                  plan.labels, plan.quantum_q8, plan.lattice);
  }
  if (!(s > 0) || !(span >= 0)) {
    return Status(Code::kDegenerate,
                  "the camera did not move between frames: move it a little sideways between "
                  "frames");
  }
  // Signed: the points may lie on both sides of what the motion's gauge calls infinity.
  constexpr double kLimit = 65535;
  double lo = (m.inv_depth_min - 0.2 * span) * s * 256.0;
  double hi = (m.inv_depth_max + 0.2 * span) * s * 256.0;
  lo = lo > -kLimit ? (lo < kLimit ? lo : kLimit) : -kLimit;
  hi = hi > -kLimit ? (hi < kLimit ? hi : kLimit) : -kLimit;
  // A whole number of quanta, so every label lies on the lattice and points a little different
  // keep the same one; the snap onto it may cost `lattice` labels of the range.
  const int64_t free_labels = plan.labels - 1 - plan.lattice;  // >= 1: the plan was checked
  const int64_t q = plan.quantum_q8;
  int64_t step = (static_cast<int64_t>((hi - lo) / static_cast<double>(free_labels)) / q + 1) * q;
  if (step * (plan.labels - 1) > 65535) step = 65535 / (plan.labels - 1);
  const int64_t width = step * (plan.labels - 1);
  // The slack (at least one lattice cell) split around the points, label 0 snapped down onto
  // the lattice (floor, also below 0), inside -65535..65535.
  const int64_t cell = step * (plan.lattice > 0 ? plan.lattice : 1);
  const double first = lo - 0.5 * (static_cast<double>(width - step * plan.lattice) - (hi - lo));
  int64_t label0 =
      plan.lattice > 0
          ? static_cast<int64_t>(__builtin_floor(first / static_cast<double>(cell))) * cell
          : static_cast<int64_t>(__builtin_floor(first));
  while (label0 + width > 65535) label0 -= cell;
  while (label0 < -65535) label0 += cell;
  out->disp_min_q8 = static_cast<int32_t>(label0);
  out->disp_max_q8 = static_cast<int32_t>(label0 + width);
  out->px_per_inv_depth = s;
  return Status::Ok();
}

Status SetDepthGeometry(const MotionResult& motion, bool keep_range, DepthStage* depth,
                        PlaneHomography* planes, LabelRange* range) {
  LabelPlan plan;
  plan.labels = depth->config().labels;
  const int32_t coarse = depth->config().coarse_step;
  plan.lattice = coarse <= plan.labels - 2 ? coarse : 0;
  LB_RETURN_IF_ERROR(PlanLabelRange(motion, plan, range));
  if (!keep_range) {
    LB_RETURN_IF_ERROR(depth->SetDisparityRange(range->disp_min_q8, range->disp_max_q8));
  }
  MakeLabelPlanes(motion, depth->config(), range->px_per_inv_depth, planes);
  return depth->SetPlanes(planes);
}

Status OrderDepth(const ConstImageU8* views, const PlaneHomography* planes, uint8_t* scratch,
                  DepthStage* depth, MotionStage* stage, MotionResult* motion, ImageU16 map,
                  bool* reversed) {
  const DepthConfig c = depth->config();
  if (reversed) *reversed = false;
  if (map.width != c.width || map.height != c.height) {
    return Status(Code::kInvalidArgument, "depth order: map %dx%d, depth %dx%d", map.width,
                  map.height, c.width, c.height);
  }
  const DepthOrderVotes votes = VoteDepthOrder(views, c.views, c.reference, depth->labels(),
                                               c.labels, planes, DepthOrderParams(), scratch);
  if (votes.low_near <= 2 * votes.high_near) return Status::Ok();
  const int32_t bias = DepthStage::MapBiasQ8(c);
  LB_RETURN_IF_ERROR(depth->SetDisparityRange(-c.disp_max_q8, -c.disp_min_q8));
  const int32_t new_bias = DepthStage::MapBiasQ8(depth->config());
  for (int32_t y = 0; y < map.height; ++y) {
    uint16_t* row = map.Row(y);
    for (int32_t x = 0; x < map.width; ++x) {
      row[x] = static_cast<uint16_t>(new_bias - (row[x] - bias));
    }
  }
  if (stage && motion) stage->ReverseDepth(motion);
  if (reversed) *reversed = true;
  return Status::Ok();
}

}  // namespace lb
