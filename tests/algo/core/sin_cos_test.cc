#include "algo/core/sin_cos.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace lb {
namespace {

TEST(SinCos, AgreesWithLibmOverTwoTurnsEachWay) {
  for (double deg = -720; deg <= 720; deg += 7.5) {
    double s, c;
    SinCosDeg(deg, &s, &c);
    EXPECT_NEAR(s, std::sin(deg * M_PI / 180), 1e-9) << deg;
    EXPECT_NEAR(c, std::cos(deg * M_PI / 180), 1e-9) << deg;
  }
}

// The synthetic scene's angles (half its field of view, its boards' tilts, a hand's turns) lie
// within a quarter turn, where the series is exact to a few units in the last place.
TEST(SinCos, QuarterTurnIsExactToAFewUlps) {
  double worst = 0;
  for (double deg = -90; deg <= 90; deg += 0.0625) {
    double s, c;
    SinCosDeg(deg, &s, &c);
    worst = std::fmax(worst, std::fabs(s - std::sin(deg * M_PI / 180)));
    worst = std::fmax(worst, std::fabs(c - std::cos(deg * M_PI / 180)));
  }
  std::printf("quarter turn: worst error %.3g\n", worst);
  EXPECT_LT(worst, 2e-15);  // a few ulps of 1
}

}  // namespace
}  // namespace lb
