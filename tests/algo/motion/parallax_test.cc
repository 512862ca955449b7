// The parallax measurement against figures worked by hand: a sideways translation moves a point
// at inverse depth w by f * t * (w - w_ref) px against the reference depth, whatever the turn.
#include "algo/motion/parallax.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace lb {
namespace {

struct Points {
  std::vector<double> xy, w, scratch;
  ParallaxPoints p;
  // n points on a row through the principal point of a 640 x 480 view (f = 500), inverse
  // depths 1 + i / n.
  explicit Points(int32_t n) : xy(2 * n), w(n), scratch(n) {
    for (int32_t i = 0; i < n; ++i) {
      xy[2 * i] = 319.5;  // index coordinates: the centre of the frame
      xy[2 * i + 1] = 239.5;
      w[i] = 1 + static_cast<double>(i) / n;
    }
    p.xy = xy.data();
    p.inv_depth = w.data();
    p.count = n;
    p.inv_depth_ref = 1;
    p.measured = {500, 500, 320, 240};
    p.projected = p.measured;
  }
};

TEST(Parallax, ASidewaysStepMovesEachPointByFocalTimesStepTimesItsDepthOffset) {
  Points pts(100);
  ViewMotion m;
  m.translation[0] = 0.01;
  // Point i moves by 500 * 0.01 * i / 100 px; the 90th percentile of 100 is the 90th (index 89).
  EXPECT_NEAR(ParallaxPx(pts.p, m, pts.scratch.data()), 5.0 * 89 / 100, 1e-9);
  m.translation[0] = -0.01;  // the other way: the same distance
  EXPECT_NEAR(ParallaxPx(pts.p, m, pts.scratch.data()), 5.0 * 89 / 100, 1e-9);
}

TEST(Parallax, ATurnAloneShowsNoParallax) {
  Points pts(50);
  ViewMotion m;
  const double a = 0.02;  // about y
  m.rotation[0][0] = std::cos(a);
  m.rotation[0][2] = std::sin(a);
  m.rotation[2][0] = -std::sin(a);
  m.rotation[2][2] = std::cos(a);
  EXPECT_LT(ParallaxPx(pts.p, m, pts.scratch.data()), 1e-9);
}

TEST(Parallax, TheProjectedFocalLengthScalesIt) {
  Points pts(10);
  ViewMotion m;
  m.translation[1] = 0.02;
  const double at500 = ParallaxPx(pts.p, m, pts.scratch.data());
  pts.p.projected = {1000, 1000, 320, 240};
  EXPECT_NEAR(ParallaxPx(pts.p, m, pts.scratch.data()), 2 * at500, 1e-9);
  EXPECT_NEAR(at500, 500 * 0.02 * 0.8, 1e-9);  // 10 points: index 8, w - 1 = 0.8
}

}  // namespace
}  // namespace lb
