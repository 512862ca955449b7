// LayerPlane's configuration bounds: a plane refuses what would overrun its per-kernel tables.
#include "algo/render/layer_plane.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "algo/render/render_stage.h"

namespace lb {
namespace {

std::vector<int32_t> Radii(int32_t n) {
  std::vector<int32_t> r(n);
  for (int32_t i = 0; i < n; ++i) r[i] = 8 * i;
  return r;
}

TEST(LayerPlane, CarveAcceptsTheLargestKernelCount) {
  const std::vector<int32_t> r = Radii(LayerPlane::kMaxKernels);
  Arena plan;  // planning: sizes only
  LayerPlane plane;
  const Status s = plane.Carve(plan, 64, 64, 1, 16, 1, r.data(), LayerPlane::kMaxKernels,
                               2 * LayerPlane::kMaxKernels - 1, 0);
  EXPECT_TRUE(s.ok()) << s.message();
}

TEST(LayerPlane, CarveRefusesMoreRadiiThanItHoldsKernels) {
  const std::vector<int32_t> r = Radii(LayerPlane::kMaxKernels + 1);
  Arena plan;
  LayerPlane plane;
  const Status s = plane.Carve(plan, 64, 64, 1, 16, 1, r.data(), LayerPlane::kMaxKernels + 1,
                               2 * LayerPlane::kMaxKernels + 1, 0);
  EXPECT_EQ(s.code(), Code::kInvalidArgument);
  EXPECT_NE(std::string(s.message()).find("radii"), std::string::npos) << s.message();
  EXPECT_EQ(plan.used(), 0u);  // refused before carving anything
}

TEST(LayerPlane, CarveRefusesNoRadiiTooManyLayersAndOtherChannelCounts) {
  const std::vector<int32_t> r = Radii(4);
  Arena plan;
  LayerPlane plane;
  EXPECT_EQ(plane.Carve(plan, 64, 64, 1, 16, 1, r.data(), 0, 1, 0).code(), Code::kInvalidArgument);
  EXPECT_EQ(plane.Carve(plan, 64, 64, 1, 16, 1, r.data(), 4, 2 * LayerPlane::kMaxKernels, 0).code(),
            Code::kInvalidArgument);
  EXPECT_EQ(plane.Carve(plan, 64, 64, 3, 16, 1, r.data(), 4, 7, 0).code(), Code::kInvalidArgument);
}

TEST(LayerPlane, TheRenderStageNeverAsksForMoreKernelsThanAPlaneHolds) {
  // The radii come from LayerRadiiQ4, for every blur radius Validate lets through.
  for (int32_t max_radius = 0; max_radius <= 128; ++max_radius) {
    const int32_t n = RenderStage::LayerRadiiQ4(max_radius, nullptr);
    EXPECT_GE(n, 1) << max_radius;
    EXPECT_LE(n, LayerPlane::kMaxKernels) << max_radius;
  }
  static_assert(RenderStage::kMaxRadii == LayerPlane::kMaxKernels);
}

}  // namespace
}  // namespace lb
