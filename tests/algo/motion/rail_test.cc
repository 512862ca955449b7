// The rail test on poses made by hand: a line at equal steps is a rail, and each way of leaving
// one (off the line, unequal steps, backwards, along the optical axis, too few frames) is not.
#include "algo/motion/rail.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace lb {
namespace {

// `views` poses with the reference in the middle, translation (v - ref) * step along `dir`.
struct Rig {
  ViewMotion motion[kMaxRailViews];
  int32_t views = 5, reference = 2;
  explicit Rig(double dx, double dy, double dz, int32_t n = 5) : views(n), reference(n / 2) {
    for (int32_t v = 0; v < views; ++v) {
      motion[v].translation[0] = (v - reference) * dx;
      motion[v].translation[1] = (v - reference) * dy;
      motion[v].translation[2] = (v - reference) * dz;
    }
  }
};

TEST(Rail, EqualStepsOnALineAreARailAndTheHeldTurnIsAcrossIt) {
  Rig rig(0.02, 0, 0.001);
  double axis[3] = {};
  ASSERT_TRUE(IsRail(rig.motion, rig.views, rig.reference, {}, axis));
  // A rail along x: the turn that shifts the image along it is about y.
  EXPECT_NEAR(axis[0], 0, 1e-12);
  EXPECT_NEAR(std::fabs(axis[1]), 1, 1e-12);
  EXPECT_EQ(axis[2], 0);
  Rig diagonal(0.02, 0.02, 0);
  ASSERT_TRUE(IsRail(diagonal.motion, diagonal.views, diagonal.reference, {}, axis));
  EXPECT_NEAR(std::hypot(axis[0], axis[1]), 1, 1e-12);
  EXPECT_NEAR(axis[0] * 0.02 + axis[1] * 0.02, 0, 1e-12) << "the axis is across the rail";
}

TEST(Rail, AFrameOffTheLineIsNoRail) {
  Rig rig(0.02, 0, 0);
  double axis[3] = {};
  // The line is the frames' mean direction: the last frame 0.04 rad up leaves it 0.027 off, the
  // others 0.013, within 0.05.
  rig.motion[4].translation[1] = 0.04 * 0.04;
  EXPECT_TRUE(IsRail(rig.motion, rig.views, rig.reference, {}, axis));
  rig.motion[4].translation[1] = 0.04 * 0.1;  // 0.1 rad up: 0.066 off the line
  EXPECT_FALSE(IsRail(rig.motion, rig.views, rig.reference, {}, axis));
  EXPECT_TRUE(IsRail(rig.motion, rig.views, rig.reference, {0.1, 0.1}, axis)) << "wider bound";
}

TEST(Rail, UnequalStepsAreNoRail) {
  Rig rig(0.02, 0, 0);
  double axis[3] = {};
  rig.motion[0].translation[0] *= 1.3;
  EXPECT_FALSE(IsRail(rig.motion, rig.views, rig.reference, {}, axis));
  EXPECT_TRUE(IsRail(rig.motion, rig.views, rig.reference, {0.05, 0.5}, axis));
}

TEST(Rail, AFrameThatWentBackIsNoRail) {
  Rig rig(0.02, 0, 0);
  double axis[3] = {};
  rig.motion[3].translation[0] = -0.02;
  EXPECT_FALSE(IsRail(rig.motion, rig.views, rig.reference, {}, axis));
}

TEST(Rail, TheListsOrderPlaysNoPart) {
  // The rig's frames listed with the reference first, then last, and shuffled: still a rail,
  // about the same axis up to its sign; a frame that went back is no rail in any order.
  Rig rig(0.02, 0.001, 0);
  double want[3] = {};
  ASSERT_TRUE(IsRail(rig.motion, rig.views, rig.reference, {}, want));
  for (const auto& order :
       {std::vector<int32_t>{2, 0, 1, 3, 4}, std::vector<int32_t>{0, 1, 3, 4, 2},
        std::vector<int32_t>{4, 1, 2, 0, 3}}) {
    ViewMotion listed[kMaxRailViews];
    int32_t reference = -1;
    for (int32_t i = 0; i < 5; ++i) {
      listed[i] = rig.motion[order[i]];
      if (order[i] == rig.reference) reference = i;
    }
    double axis[3] = {};
    ASSERT_TRUE(IsRail(listed, 5, reference, {}, axis));
    EXPECT_NEAR(std::fabs(axis[0] * want[0] + axis[1] * want[1] + axis[2] * want[2]), 1, 1e-12);
    // The first two other frames listed: the second moved onto the first's place.
    const int32_t a = reference == 0 ? 1 : 0, b = reference <= 1 ? 2 : 1;
    listed[b] = listed[a];
    EXPECT_FALSE(IsRail(listed, 5, reference, {}, axis)) << "two frames at one place";
  }
}

TEST(Rail, ALineAlongTheOpticalAxisTwoFramesOrNoToleranceAreNoRail) {
  double axis[3] = {};
  Rig forward(0, 0, 0.02);
  EXPECT_FALSE(IsRail(forward.motion, forward.views, forward.reference, {}, axis));
  Rig two(0.02, 0, 0, 2);
  EXPECT_FALSE(IsRail(two.motion, two.views, two.reference, {}, axis));
  Rig rig(0.02, 0, 0);
  EXPECT_FALSE(IsRail(rig.motion, rig.views, rig.reference, {0, 0.1}, axis));
  Rig still(0, 0, 0);
  EXPECT_FALSE(IsRail(still.motion, still.views, still.reference, {}, axis));
}

}  // namespace
}  // namespace lb
