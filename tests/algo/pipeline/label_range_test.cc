// The label range auto geometry plans from a motion estimate (auto_geometry.h).
#include <gtest/gtest.h>

#include "algo/pipeline/auto_geometry.h"

namespace lb {
namespace {

// A rectified rig of `n` views, spacing b, reference in the middle, seen by a camera of focal f,
// with points at inverse depths lo..hi.
MotionResult Rig(int32_t n, double b, double f, double lo, double hi) {
  MotionResult m;
  m.views = n;
  m.reference = n / 2;
  m.intrinsics = {f, f, 160, 120};
  for (int32_t v = 0; v < n; ++v) m.motion[v].translation[0] = -(v - n / 2) * b;
  m.inv_depth_min = lo;
  m.inv_depth_max = hi;
  return m;
}

TEST(LabelRange, ARigGivesItsDisparityPerViewStepWhateverTheScale) {
  for (const double scale : {1.0, 0.01, 250.0}) {
    // Translation scaled up, inverse depth down: the same pixels, the same labels.
    const MotionResult m = Rig(5, 0.1 * scale, 400, 0.1 / scale, 0.3 / scale);
    LabelRange r;
    ASSERT_TRUE(PlanLabelRange(m, 32, &r).ok());
    EXPECT_NEAR(r.px_per_inv_depth * 0.1 / scale, 4.0, 1e-9);  // f * b * rho at the near end
    // Points span 4..12 px per step; a fifth of the span is added on each side.
    EXPECT_NEAR(r.disp_min_q8 / 256.0, 4.0 - 1.6, 1.0 / 256);
    EXPECT_NEAR(r.disp_max_q8 / 256.0, 12.0 + 1.6, 1.0 / 256);
  }
}

TEST(LabelRange, StaysInsideTheDepthStagesLimits) {
  LabelRange r;
  // Points at infinity and close: the far end stops at 0.
  ASSERT_TRUE(PlanLabelRange(Rig(5, 1, 400, 0.0, 0.05), 16, &r).ok());
  EXPECT_EQ(r.disp_min_q8, 0);
  EXPECT_GT(r.disp_max_q8, r.disp_min_q8);
  // All points at one depth: still one Q8 step per label.
  ASSERT_TRUE(PlanLabelRange(Rig(5, 1, 400, 0.02, 0.02), 64, &r).ok());
  EXPECT_GE(r.disp_max_q8 - r.disp_min_q8, 64);
  // Enormous parallax: clamped to 16 bits.
  ASSERT_TRUE(PlanLabelRange(Rig(5, 100, 4000, 1, 2), 64, &r).ok());
  EXPECT_LE(r.disp_max_q8, 65535);
  EXPECT_GE(r.disp_max_q8 - r.disp_min_q8, 64);
}

TEST(LabelRange, NoBaselineIsDegenerate) {
  LabelRange r;
  const Status s = PlanLabelRange(Rig(5, 0, 400, 0.1, 0.3), 32, &r);
  EXPECT_EQ(s.code(), Code::kDegenerate);
  EXPECT_NE(std::string(s.message()).find("sideways"), std::string::npos) << s.message();
}

}  // namespace
}  // namespace lb
