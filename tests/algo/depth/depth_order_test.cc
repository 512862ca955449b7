// The views' occlusions tell which end of the labels is near (depth_order.h): a textured square
// in front of a textured wall, two views. Whichever way the labels run, the vote names the
// square's end.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "algo/depth/depth_order.h"
#include "algo/motion/camera.h"

namespace lb {
namespace {

constexpr int32_t kW = 96, kH = 64, kLabels = 16;
constexpr int32_t kWallShift = 1, kSquareShift = 9;  // px the view moves each surface by

uint8_t Texture(int32_t x, int32_t y, int32_t seed) {
  uint32_t h = static_cast<uint32_t>(x) * 73856093u ^ static_cast<uint32_t>(y) * 19349663u ^
               static_cast<uint32_t>(seed) * 83492791u;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  return static_cast<uint8_t>(h >> 24);
}

bool InSquare(int32_t x, int32_t y) { return x >= 32 && x < 64 && y >= 16 && y < 48; }

struct Scene {
  std::vector<uint8_t> ref, view;
  std::vector<uint8_t> labels;
  std::vector<PlaneHomography> planes;  // 2 views x kLabels
};

// Label `wall` holds the wall, `square` the square; label l shifts the view by shift(l) px.
Scene Make(int32_t wall, int32_t square) {
  Scene s;
  s.ref.resize(kW * kH * 3);
  s.view.resize(kW * kH * 3);
  s.labels.resize(kW * kH);
  auto colour = [](int32_t x, int32_t y, bool sq, uint8_t* out) {
    for (int k = 0; k < 3; ++k) out[k] = Texture(x, y, sq ? 7 + k : 1 + k);
  };
  for (int32_t y = 0; y < kH; ++y) {
    for (int32_t x = 0; x < kW; ++x) {
      const bool sq = InSquare(x, y);
      colour(x, y, sq, &s.ref[(y * kW + x) * 3]);
      s.labels[y * kW + x] = static_cast<uint8_t>(sq ? square : wall);
      // The view sees the square moved left by kSquareShift over the wall moved by kWallShift.
      const int32_t xs = x + kSquareShift;
      if (InSquare(xs, y)) {
        colour(xs, y, true, &s.view[(y * kW + x) * 3]);
      } else {
        colour(x + kWallShift, y, false, &s.view[(y * kW + x) * 3]);
      }
    }
  }
  // Label l maps x to x - shift: the wall's label to -kWallShift, the square's to
  // -kSquareShift, the others in between (a rig of identity rotation, t along x).
  const CameraIntrinsics k = DefaultIntrinsics(kW, kH);
  s.planes.resize(2 * kLabels);
  for (int32_t l = 0; l < kLabels; ++l) {
    const double t = (l - wall) / static_cast<double>(square - wall);
    ViewMotion m;
    m.translation[0] = -(kWallShift + t * (kSquareShift - kWallShift)) / k.fx;
    s.planes[kLabels + l] = MakePlaneHomography(k, m, 1.0);
    s.planes[l] = MakePlaneHomography(k, ViewMotion{}, 1.0);
  }
  return s;
}

DepthOrderVotes Vote(const Scene& s) {
  const ConstImageU8 views[2] = {MakeView(s.ref.data(), kW, kH, 3),
                                 MakeView(s.view.data(), kW, kH, 3)};
  std::vector<uint8_t> scratch(DepthOrderScratchBytes(kW, kH));
  return VoteDepthOrder(views, 2, 0, s.labels.data(), kLabels, s.planes.data(), DepthOrderParams(),
                        scratch.data());
}

TEST(DepthOrder, TheSquaresEndIsNearWhicheverWayTheLabelsRun) {
  const DepthOrderVotes up = Vote(Make(2, 13));  // the square on the high labels
  EXPECT_GT(up.high_near, 4 * up.low_near) << up.high_near << " vs " << up.low_near;
  EXPECT_GT(up.high_near, 100);
  const DepthOrderVotes down = Vote(Make(13, 2));  // the same scene, labels mirrored
  EXPECT_GT(down.low_near, 4 * down.high_near) << down.low_near << " vs " << down.high_near;
}

TEST(DepthOrder, OneSurfaceCastsNoVote) {
  Scene s = Make(2, 13);
  for (auto& l : s.labels) l = 2;
  const DepthOrderVotes v = Vote(s);
  EXPECT_EQ(v.high_near + v.low_near, 0);
}

}  // namespace
}  // namespace lb
