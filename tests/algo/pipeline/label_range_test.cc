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

LabelPlan Plan(int32_t labels) {
  LabelPlan p;
  p.labels = labels;
  return p;
}

int32_t Step(const LabelRange& r, int32_t labels) {
  return (r.disp_max_q8 - r.disp_min_q8) / (labels - 1);
}

TEST(LabelRange, ARigGivesItsDisparityPerViewStepWhateverTheScale) {
  for (const double scale : {1.0, 0.01, 250.0}) {
    // Translation scaled up, inverse depth down: the same pixels, the same labels.
    const MotionResult m = Rig(5, 0.1 * scale, 400, 0.1 / scale, 0.3 / scale);
    LabelRange r;
    ASSERT_TRUE(PlanLabelRange(m, Plan(32), &r).ok());
    EXPECT_NEAR(r.px_per_inv_depth * 0.1 / scale, 4.0, 1e-9);  // f * b * rho at the near end
    // Points span 4..12 px per step; a fifth of the span more on each side is covered.
    EXPECT_LE(r.disp_min_q8, (4.0 - 1.6) * 256);
    EXPECT_GE(r.disp_max_q8, (12.0 + 1.6) * 256);
    // Not much more: 32 labels, 4 of them spent on the lattice's snap, the spacing rounded up
    // to a sixteenth of a pixel.
    EXPECT_LE(r.disp_max_q8 - r.disp_min_q8, (11.2 * 256 / 27 + 16) * 31);
  }
}

TEST(LabelRange, LabelsLieOnALatticeFromInfinity) {
  // Every label a whole Q8 step apart, label 0 a multiple of 4 steps: the same lattice for
  // points that differ a little, so the coarse pass's labels do not move with the percentiles.
  LabelRange a, b;
  ASSERT_TRUE(PlanLabelRange(Rig(5, 1, 400, 0.02, 0.05), Plan(64), &a).ok());
  ASSERT_TRUE(PlanLabelRange(Rig(5, 1, 400, 0.0201, 0.0499), Plan(64), &b).ok());
  for (const LabelRange& r : {a, b}) {
    const int32_t step = Step(r, 64);
    EXPECT_EQ(r.disp_min_q8 + 63 * step, r.disp_max_q8);
    EXPECT_EQ(r.disp_min_q8 % (4 * step), 0) << r.disp_min_q8 << " step " << step;
  }
  EXPECT_EQ(a.disp_min_q8, b.disp_min_q8);
  EXPECT_EQ(a.disp_max_q8, b.disp_max_q8);
}

TEST(LabelRange, AShallowSceneGetsTheFinestSpacingAroundItsPoints) {
  // Points at 40..41 px per step, 1.4 px with the margins: one sixteenth of a pixel per label,
  // the window around the points.
  LabelRange r;
  ASSERT_TRUE(PlanLabelRange(Rig(5, 1, 400, 0.1, 0.1025), Plan(64), &r).ok());
  EXPECT_EQ(Step(r, 64), 16);
  EXPECT_LE(r.disp_min_q8, (40 - 0.2) * 256);
  EXPECT_GE(r.disp_max_q8, (41 + 0.2) * 256);
  EXPECT_EQ(r.disp_min_q8 % (4 * 16), 0);
  // Near infinity the window goes on beyond it (signed inverse depth), still on the lattice
  // through 0.
  ASSERT_TRUE(PlanLabelRange(Rig(5, 1, 400, 0.001, 0.003), Plan(64), &r).ok());
  EXPECT_LT(r.disp_min_q8, 0);
  EXPECT_LE(r.disp_min_q8, (0.4 - 0.16) * 256);
  EXPECT_GE(r.disp_max_q8, (1.2 + 0.16) * 256);
  EXPECT_EQ(r.disp_min_q8 % (4 * Step(r, 64)), 0);
}

TEST(LabelRange, PointsOnBothSidesOfInfinityKeepTheirWindow) {
  // A converged rig: the gauge's infinity inside the points' range (-3..+3 px per step).
  LabelRange r;
  ASSERT_TRUE(PlanLabelRange(Rig(5, 1, 400, -0.0075, 0.0075), Plan(64), &r).ok());
  EXPECT_LE(r.disp_min_q8, (-3 - 1.2) * 256);
  EXPECT_GE(r.disp_max_q8, (3 + 1.2) * 256);
  EXPECT_EQ(r.disp_min_q8 % (4 * Step(r, 64)), 0);
  EXPECT_EQ(r.disp_min_q8 + 63 * Step(r, 64), r.disp_max_q8);
}

TEST(LabelRange, StaysInsideTheDepthStagesLimits) {
  LabelRange r;
  // Points at infinity and close: the margin goes beyond infinity, inside the stage's limits.
  ASSERT_TRUE(PlanLabelRange(Rig(5, 1, 400, 0.0, 0.05), Plan(16), &r).ok());
  EXPECT_LT(r.disp_min_q8, 0);
  EXPECT_GT(r.disp_max_q8, r.disp_min_q8);
  EXPECT_LE(r.disp_max_q8 - r.disp_min_q8, 65535);
  // Points far beyond infinity: clamped to the stage's -65535.
  ASSERT_TRUE(PlanLabelRange(Rig(5, 100, 4000, -2, -1), Plan(64), &r).ok());
  EXPECT_GE(r.disp_min_q8, -65535);
  EXPECT_EQ(r.disp_min_q8 + 63 * Step(r, 64), r.disp_max_q8);
  // All points at one depth: still a quantum per label.
  ASSERT_TRUE(PlanLabelRange(Rig(5, 1, 400, 0.02, 0.02), Plan(64), &r).ok());
  EXPECT_EQ(Step(r, 64), 16);
  // Enormous parallax: clamped to 16 bits, labels still a whole step apart.
  ASSERT_TRUE(PlanLabelRange(Rig(5, 100, 4000, 1, 2), Plan(64), &r).ok());
  EXPECT_LE(r.disp_max_q8, 65535);
  EXPECT_GE(Step(r, 64), 1);
  EXPECT_EQ(r.disp_min_q8 + 63 * Step(r, 64), r.disp_max_q8);
}

TEST(LabelRange, TheSameFramesInAnyOrderGetTheSameLabels) {
  // A row of 5 and a cross of 5: the reference listed first, in the middle and last.
  MotionResult row = Rig(5, 1, 400, 0.01, 0.03);
  MotionResult cross = row;
  const double at[5][2] = {{0, -1}, {-1, 0}, {0, 0}, {1, 0}, {0, 1}};
  for (int32_t v = 0; v < 5; ++v) {
    cross.motion[v].translation[0] = at[v][0];
    cross.motion[v].translation[1] = at[v][1];
  }
  for (const MotionResult& m : {row, cross}) {
    LabelRange want;
    ASSERT_TRUE(PlanLabelRange(m, Plan(64), &want).ok());
    EXPECT_NEAR(want.px_per_inv_depth, 400, 1e-9);  // f b: one step, in a row or a cross
    for (const int32_t first : {0, 1}) {
      MotionResult listed = m;
      listed.reference = first ? 0 : 4;
      int32_t i = first ? 1 : 0;
      for (int32_t v = 0; v < 5; ++v) {
        if (v != m.reference) listed.motion[i++] = m.motion[v];
      }
      listed.motion[listed.reference] = m.motion[m.reference];
      LabelRange r;
      ASSERT_TRUE(PlanLabelRange(listed, Plan(64), &r).ok());
      EXPECT_NEAR(r.px_per_inv_depth, want.px_per_inv_depth, 1e-9);
      EXPECT_EQ(r.disp_min_q8, want.disp_min_q8);
      EXPECT_EQ(r.disp_max_q8, want.disp_max_q8);
    }
  }
}

TEST(LabelRange, ABadPlanIsAnInvalidArgument) {
  LabelRange r;
  LabelPlan p = Plan(16);
  p.lattice = 15;
  EXPECT_EQ(PlanLabelRange(Rig(5, 1, 400, 0.1, 0.3), p, &r).code(), Code::kInvalidArgument);
  p = Plan(1);
  EXPECT_EQ(PlanLabelRange(Rig(5, 1, 400, 0.1, 0.3), p, &r).code(), Code::kInvalidArgument);
  // Two labels, no lattice: still a range that covers the points.
  p = Plan(2);
  p.lattice = 0;
  ASSERT_TRUE(PlanLabelRange(Rig(5, 1, 400, 0.1, 0.3), p, &r).ok());
  EXPECT_LE(r.disp_min_q8, 40 * 256);
  EXPECT_GE(r.disp_max_q8, 120 * 256);
}

TEST(LabelRange, NoBaselineIsDegenerate) {
  LabelRange r;
  const Status s = PlanLabelRange(Rig(5, 0, 400, 0.1, 0.3), Plan(32), &r);
  EXPECT_EQ(s.code(), Code::kDegenerate);
  EXPECT_NE(std::string(s.message()).find("sideways"), std::string::npos) << s.message();
}

}  // namespace
}  // namespace lb
