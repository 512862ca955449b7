// Foundation depth stage: winner-take-all over the labels with a 3x3 sum of absolute colour
// differences averaged over all views. It has the final interface and memory discipline; the
// graph-cut optimiser replaces the winner-take-all choice.
#include "algo/depth/depth_stage.h"

#include <cstdlib>

namespace lb {
namespace {

int32_t LabelDispQ8(const DepthConfig& c, int32_t label) {
  if (c.labels <= 1) return c.disp_min_q8;
  return c.disp_min_q8 +
         static_cast<int32_t>((int64_t{c.disp_max_q8 - c.disp_min_q8} * label) / (c.labels - 1));
}

}  // namespace

Status DepthStage::Validate(const DepthConfig& c) {
  if (c.width < 8 || c.height < 8) {
    return Status(Code::kInvalidArgument, "depth: working size %dx%d is below 8x8", c.width,
                  c.height);
  }
  if (c.views < 2 || c.views > DepthConfig::kMaxViews) {
    return Status(Code::kInvalidArgument, "depth: %d views (needs 2 to %d)", c.views,
                  DepthConfig::kMaxViews);
  }
  if (c.reference < 0 || c.reference >= c.views) {
    return Status(Code::kInvalidArgument, "depth: reference %d outside 0..%d", c.reference,
                  c.views - 1);
  }
  if (c.labels < 2 || c.labels > DepthConfig::kMaxLabels) {
    return Status(Code::kInvalidArgument, "depth: %d labels (needs 2 to %d)", c.labels,
                  DepthConfig::kMaxLabels);
  }
  if (c.disp_min_q8 < 0 || c.disp_max_q8 <= c.disp_min_q8 || c.disp_max_q8 > 0xffff) {
    return Status(Code::kInvalidArgument, "depth: disparity range %d..%d (Q8) is empty or too wide",
                  c.disp_min_q8, c.disp_max_q8);
  }
  return Status::Ok();
}

size_t DepthStage::RequiredBytes(const DepthConfig& config) {
  DepthStage planner;
  planner.config_ = config;
  Arena plan;
  (void)planner.Carve(plan);
  return plan.used();
}

Status DepthStage::Carve(Arena& arena) {
  const size_t start = arena.used();
  best_cost_ = arena.Allocate<uint32_t>(static_cast<size_t>(config_.width) * config_.height);
  stats_.arena_bytes = arena.used() - start;
  if (arena.overflowed()) return Status(Code::kOutOfMemory, "depth: arena too small");
  return Status::Ok();
}

Status DepthStage::Configure(const DepthConfig& config, Arena& arena) {
  LB_RETURN_IF_ERROR(Validate(config));
  config_ = config;
  stats_ = DepthStats{};
  stats_.labels = config.labels;
  return Carve(arena);
}

Status DepthStage::Compute(const ConstImageU8* views, ImageU16 disp_q8) {
  const DepthConfig& c = config_;
  if (disp_q8.width != c.width || disp_q8.height != c.height) {
    return Status(Code::kInvalidArgument, "depth: output is %dx%d, expected %dx%d", disp_q8.width,
                  disp_q8.height, c.width, c.height);
  }
  const int32_t w = c.width, h = c.height;
  for (int32_t i = 0; i < w * h; ++i) best_cost_[i] = UINT32_MAX;
  const ConstImageU8& ref = views[c.reference];
  for (int32_t label = 0; label < c.labels; ++label) {
    const int32_t d_q8 = LabelDispQ8(c, label);
    for (int32_t y = 0; y < h; ++y) {
      for (int32_t x = 0; x < w; ++x) {
        uint32_t cost = 0;
        for (int32_t v = 0; v < c.views; ++v) {
          if (v == c.reference) continue;
          // Nearest-pixel shift; the view k steps right sees the point at x - k*d.
          const int32_t shift = ((c.reference - v) * d_q8 + (1 << 7)) >> 8;
          for (int32_t dy = -1; dy <= 1; ++dy) {
            const int32_t yy = y + dy < 0 ? 0 : (y + dy >= h ? h - 1 : y + dy);
            for (int32_t dx = -1; dx <= 1; ++dx) {
              const int32_t xr = x + dx < 0 ? 0 : (x + dx >= w ? w - 1 : x + dx);
              int32_t xv = xr + shift;
              xv = xv < 0 ? 0 : (xv >= w ? w - 1 : xv);
              const uint8_t* a = ref.At(xr, yy);
              const uint8_t* b = views[v].At(xv, yy);
              cost += static_cast<uint32_t>(std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) +
                                            std::abs(a[2] - b[2]));
            }
          }
        }
        uint32_t& best = best_cost_[y * w + x];
        if (cost < best) {
          best = cost;
          disp_q8.Row(y)[x] = static_cast<uint16_t>(d_q8);
        }
      }
    }
  }
  stats_.cycles = 0;
  return Status::Ok();
}

}  // namespace lb
