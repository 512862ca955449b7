// Plane-sweep depth on synthetic handheld bursts with the scene's true poses: the motion result
// they make, labels over the scene's inverse-depth range, and the bad-pixel rate against the
// scene's ground truth. Host-side; allocates freely.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "algo/depth/depth_stage.h"
#include "algo/motion/motion_stage.h"
#include "algo/pipeline/planes.h"
#include "tests/algo/motion/burst.h"

namespace lb::handheld {

// A depth stage on its own aligned block.
struct Stage {
  std::vector<uint8_t> memory;
  DepthStage depth;
  std::vector<uint16_t> disp;

  Status Configure(const DepthConfig& c) {
    const size_t bytes = DepthStage::RequiredBytes(c);
    memory.assign(bytes + Arena::kAlign, 0);
    void* const base = Arena::AlignUp(memory.data());
    Arena arena(base, bytes);
    disp.assign(static_cast<size_t>(c.width) * c.height, 0);
    return depth.Configure(c, arena);
  }
  Status Compute(const ConstImageU8* views) {
    return depth.Compute(views, MakeView(disp.data(), depth.config().width, depth.config().height));
  }
};

// The scene's true poses as a motion result: inverse depth in 1/m, translations in metres.
inline MotionResult TrueMotion(const motiontest::Burst& b) {
  MotionResult r;
  r.views = b.scene.views();
  r.reference = b.scene.reference();
  r.intrinsics = b.intrinsics;
  for (int32_t v = 0; v < r.views; ++v) r.motion[v] = b.scene.pose(v);
  return r;
}

struct Labels {
  DepthConfig config;
  double px_per_inv_depth = 0;  // focal length times the mean sideways baseline
};

// Quarter-pixel labels (of motion in the mean-baseline view) over the scene's inverse-depth
// range widened by `margin` of it on each side.
inline Labels HandheldLabels(const motiontest::Burst& b, double margin) {
  Labels out;
  double base = 0;
  for (int32_t v = 0; v < b.scene.views(); ++v) {
    const double* t = b.scene.pose(v).translation;
    base += std::sqrt(t[0] * t[0] + t[1] * t[1]);
  }
  base /= b.scene.views() - 1;
  out.px_per_inv_depth = b.intrinsics.fx * base;
  const double lo = b.scene.inverse_depth_min_q12() / 4096.0;
  const double hi = b.scene.inverse_depth_max_q12() / 4096.0;
  const double span = hi - lo;
  DepthConfig& c = out.config;
  c.width = b.scene.width();
  c.height = b.scene.height();
  c.views = b.scene.views();
  c.reference = b.scene.reference();
  c.geometry = ViewGeometry::kKnownPoses;
  c.disp_min_q8 =
      static_cast<int32_t>(std::max(0.0, lo - margin * span) * out.px_per_inv_depth * 256);
  const int32_t top =
      static_cast<int32_t>(std::ceil((hi + margin * span) * out.px_per_inv_depth * 256));
  c.labels = std::min(DepthConfig::kMaxLabels, (top - c.disp_min_q8 + 63) / 64 + 1);
  c.disp_max_q8 = c.disp_min_q8 + (c.labels - 1) * 64;
  return out;
}

inline std::vector<PlaneHomography> Planes(const motiontest::Burst& b, const Labels& l) {
  std::vector<PlaneHomography> planes(static_cast<size_t>(l.config.views) * l.config.labels);
  MakeLabelPlanes(TrueMotion(b), l.config, l.px_per_inv_depth, planes.data());
  return planes;
}

// Percent of reference pixels whose disparity (px of mean-baseline motion) is off the truth by
// more than `threshold_px`.
inline double BadPixelPercent(const motiontest::Burst& b, const Labels& l,
                              const std::vector<uint16_t>& disp_q8, double threshold_px) {
  const int32_t w = b.scene.width(), h = b.scene.height();
  std::vector<uint16_t> truth(static_cast<size_t>(w) * h);
  if (!b.scene.InverseDepthRows(1, 0, h, truth.data(), w).ok()) return 100;
  int64_t bad = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    const double err = disp_q8[i] / 256.0 - truth[i] / 4096.0 * l.px_per_inv_depth;
    bad += std::fabs(err) > threshold_px ? 1 : 0;
  }
  return 100.0 * static_cast<double>(bad) / static_cast<double>(truth.size());
}

}  // namespace lb::handheld
