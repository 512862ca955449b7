#include "algo/pipeline/planes.h"

namespace lb {

void MakeLabelPlanes(const MotionResult& motion, const DepthConfig& config, double px_per_inv_depth,
                     PlaneHomography* out) {
  for (int32_t v = 0; v < config.views; ++v) {
    for (int32_t l = 0; l < config.labels; ++l) {
      const double inv_depth = DepthStage::LabelDispQ8(config, l) / 256.0 / px_per_inv_depth;
      out[v * config.labels + l] = motion.Homography(v, inv_depth);
    }
  }
}

}  // namespace lb
