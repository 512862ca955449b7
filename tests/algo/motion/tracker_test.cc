#include "algo/motion/tracker.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "algo/motion/corners.h"
#include "algo/motion/pyramid.h"
#include "tests/algo/motion/burst.h"

namespace lb {
namespace {

// Where the scene puts reference pixel (x, y) (index coordinates) in `view`, from the true
// inverse depth and pose.
bool TruePosition(const Scene& s, int32_t view, int32_t x, int32_t y, double* vx, double* vy) {
  uint16_t rho_q12 = 0;
  std::vector<uint16_t> row(s.width());
  if (!s.InverseDepthRows(1, y, 1, row.data(), s.width()).ok()) return false;
  rho_q12 = row[x];
  const double rho = rho_q12 / 4096.0;
  const CameraIntrinsics& k = s.intrinsics();
  const double r[3] = {(x + 0.5 - k.cx) / k.fx, (y + 0.5 - k.cy) / k.fy, 1.0};
  const ViewMotion& p = s.pose(view);
  double a[3];
  for (int i = 0; i < 3; ++i) {
    a[i] = p.rotation[i][0] * r[0] + p.rotation[i][1] * r[1] + p.rotation[i][2] * r[2] +
           rho * p.translation[i];
  }
  *vx = k.fx * a[0] / a[2] + k.cx - 0.5;
  *vy = k.fy * a[1] / a[2] + k.cy - 0.5;
  return true;
}

TEST(Tracker, FollowsSceneCornersToTheirTruePositions) {
  constexpr int32_t kW = 640, kH = 480;
  motiontest::Burst b;
  ASSERT_TRUE(motiontest::MakeBurst(motiontest::Handheld(4), kW, kH, 3, &b));
  std::vector<uint8_t> memory(4 << 20);
  Arena arena(memory.data(), memory.size());
  GreyPyramid ref, view;
  CornerDetector det;
  Tracker tracker;
  ASSERT_TRUE(ref.Carve(kW, kH, 4, arena).ok());
  ASSERT_TRUE(view.Carve(kW, kH, 4, arena).ok());
  ASSERT_TRUE(det.Carve(kW, kH, 32, arena).ok());
  ASSERT_TRUE(tracker.Carve(TrackerParams(), arena).ok());
  ASSERT_FALSE(arena.overflowed());
  const int32_t refv = b.scene.reference();
  ASSERT_TRUE(ref.Build(b.views[refv]).ok());
  std::vector<Corner> corners(det.max_corners());
  const int32_t n = det.Detect(ref.level(0), 4000000, 1000, corners.data());
  ASSERT_GT(n, 100);
  std::vector<int32_t> xs(n), ys(n);
  for (int32_t i = 0; i < n; ++i) {
    xs[i] = corners[i].x << 16;
    ys[i] = corners[i].y << 16;
  }
  for (int32_t v = 0; v < 3; ++v) {
    if (v == refv) continue;
    ASSERT_TRUE(view.Build(b.views[v]).ok());
    std::vector<int32_t> dx(n, 0), dy(n, 0);
    std::vector<uint8_t> ok(n);
    tracker.Track(ref, view, xs.data(), ys.data(), n, dx.data(), dy.data(), ok.data());
    // Windows on one surface only: at depth edges the window holds two motions.
    std::vector<double> err;
    double sx = 0, sy = 0;
    std::vector<uint16_t> rows(static_cast<size_t>(kW) * 9);
    for (int32_t i = 0; i < n; ++i) {
      double tx, ty;
      if (!ok[i] || !TruePosition(b.scene, v, corners[i].x, corners[i].y, &tx, &ty)) continue;
      ASSERT_TRUE(b.scene.InverseDepthRows(1, corners[i].y - 4, 9, rows.data(), kW).ok());
      int32_t lo = 65535, hi = 0;
      for (int32_t yy = 0; yy < 9; ++yy) {
        for (int32_t xx = -4; xx <= 4; ++xx) {
          lo = std::min<int32_t>(lo, rows[yy * kW + corners[i].x + xx]);
          hi = std::max<int32_t>(hi, rows[yy * kW + corners[i].x + xx]);
        }
      }
      if (hi - lo >= 8) continue;
      const double ex = corners[i].x + dx[i] / 65536.0 - tx;
      const double ey = corners[i].y + dy[i] / 65536.0 - ty;
      sx += ex;
      sy += ey;
      err.push_back(std::hypot(ex, ey));
    }
    int32_t followed = 0;
    for (int32_t i = 0; i < n; ++i) followed += ok[i];
    EXPECT_GT(followed, n / 2) << "most corners are followed";
    ASSERT_GT(err.size(), static_cast<size_t>(n) / 3);
    std::sort(err.begin(), err.end());
    const double median = err[err.size() / 2], p90 = err[err.size() * 9 / 10];
    printf(
        "view %d: %zu of %d corners on one surface followed, error median %.3f p90 %.3f px, "
        "bias %.3f %.3f px\n",
        v, err.size(), n, median, p90, sx / err.size(), sy / err.size());
    // The scene's hard-edged patterns are point sampled (edges on whole pixels): ~0.3 px per
    // corner at worst, but no bias shared by the corners.
    EXPECT_LT(median, 0.25);
    EXPECT_LT(p90, 0.5);
    EXPECT_LT(std::fabs(sx / err.size()), 0.05);
    EXPECT_LT(std::fabs(sy / err.size()), 0.05);
  }
}

}  // namespace
}  // namespace lb

namespace lb {
namespace {

// A smooth texture (periods of 9..31 px) sampled at (x + sx, y + sy): a pure subpixel shift.
void Smooth(std::vector<uint8_t>* img, int32_t w, int32_t h, double sx, double sy) {
  img->resize(static_cast<size_t>(w) * h);
  for (int32_t y = 0; y < h; ++y) {
    for (int32_t x = 0; x < w; ++x) {
      const double u = x + sx, v = y + sy;
      const double f = 128 + 40 * std::sin(u * 0.37 + 0.2 * v) +
                       35 * std::cos(v * 0.29 - 0.11 * u) +
                       25 * std::sin(0.21 * u + 0.23 * v + 1.0);
      (*img)[static_cast<size_t>(y) * w + x] = static_cast<uint8_t>(std::lround(f));
    }
  }
}

// The smooth texture plus coarse waves (periods of 50..120 px), which the coarse levels see.
void Multiscale(std::vector<uint8_t>* img, int32_t w, int32_t h, double sx, double sy) {
  Smooth(img, w, h, sx, sy);
  for (int32_t y = 0; y < h; ++y) {
    for (int32_t x = 0; x < w; ++x) {
      const double u = x + sx, v = y + sy;
      const double f = 0.5 * (*img)[static_cast<size_t>(y) * w + x] + 64 +
                       30 * std::sin(u * 0.07 + 0.03 * v) + 25 * std::cos(v * 0.11 - 0.05 * u);
      (*img)[static_cast<size_t>(y) * w + x] = static_cast<uint8_t>(std::lround(f));
    }
  }
}

// Tracks the points (xs, ys) from grey image a into b (kW x kH) over `levels` pyramid levels.
struct Tracked {
  std::vector<int32_t> dx, dy;
  std::vector<uint8_t> ok;
};
constexpr int32_t kW = 320, kH = 240;
Tracked TrackPoints(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b, int32_t levels,
                    const std::vector<int32_t>& xs, const std::vector<int32_t>& ys) {
  std::vector<uint8_t> memory(1 << 20);
  Arena arena(memory.data(), memory.size());
  GreyPyramid pa, pb;
  Tracker tracker;
  Tracked t;
  if (!pa.Carve(kW, kH, levels, arena).ok() || !pb.Carve(kW, kH, levels, arena).ok() ||
      !tracker.Carve(TrackerParams(), arena).ok() ||
      !pa.Build(MakeView(a.data(), kW, kH).AsConst()).ok() ||
      !pb.Build(MakeView(b.data(), kW, kH).AsConst()).ok()) {
    ADD_FAILURE() << "tracker set-up";
    return t;
  }
  const int32_t n = static_cast<int32_t>(xs.size());
  t.dx.assign(n, 0);
  t.dy.assign(n, 0);
  t.ok.assign(n, 0);
  tracker.Track(pa, pb, xs.data(), ys.data(), n, t.dx.data(), t.dy.data(), t.ok.data());
  return t;
}

TEST(Tracker, RecoversASubpixelShift) {
  std::vector<uint8_t> a, b;
  const double sx = 5.37, sy = -3.81;
  Smooth(&a, kW, kH, 0, 0);
  Smooth(&b, kW, kH, -sx, -sy);  // content moves by (+sx, +sy)
  std::vector<int32_t> xs, ys;
  for (int32_t y = 40; y < kH - 40; y += 20) {
    for (int32_t x = 40; x < kW - 40; x += 20) {
      xs.push_back(x << 16);
      ys.push_back(y << 16);
    }
  }
  const Tracked t = TrackPoints(a, b, 3, xs, ys);
  ASSERT_EQ(t.ok.size(), xs.size());
  for (size_t i = 0; i < xs.size(); ++i) {
    ASSERT_TRUE(t.ok[i]) << i;
    // Bilinear sampling of the 9 px periods costs a little: 1/16 px.
    EXPECT_NEAR(t.dx[i] / 65536.0, sx, 1.0 / 16) << i;
    EXPECT_NEAR(t.dy[i] / 65536.0, sy, 1.0 / 16) << i;
  }
}

// Points close to the frame's edge, moved further than the finest levels alone can follow: the
// coarse levels, too small for the point's own window there, measure the patch next to it.
TEST(Tracker, FollowsPointsNearTheBorderOverLongMotions) {
  std::vector<uint8_t> a, b;
  const double sx = 13.4, sy = 7.6;  // beyond the ~5 px that levels 0 and 1 reach on their own
  Multiscale(&a, kW, kH, 0, 0);
  Multiscale(&b, kW, kH, -sx, -sy);
  // 8 px from the left and top edges: level 3's window (11 px wide on a 40x30 image) cannot be
  // centred there; the far edges are left out, where the content moves out of the frame.
  std::vector<int32_t> xs, ys;
  for (int32_t y = 8; y < kH - 40; y += 16) {
    xs.push_back(8 << 16);
    ys.push_back(y << 16);
  }
  for (int32_t x = 24; x < kW - 40; x += 16) {
    xs.push_back(x << 16);
    ys.push_back(8 << 16);
  }
  const Tracked t = TrackPoints(a, b, 4, xs, ys);
  ASSERT_EQ(t.ok.size(), xs.size());
  for (size_t i = 0; i < xs.size(); ++i) {
    ASSERT_TRUE(t.ok[i]) << "point " << (xs[i] >> 16) << "," << (ys[i] >> 16);
    // Half the window hangs over a 9 px period at the edge: 1/8 px.
    EXPECT_NEAR(t.dx[i] / 65536.0, sx, 1.0 / 8) << i;
    EXPECT_NEAR(t.dy[i] / 65536.0, sy, 1.0 / 8) << i;
  }
}

}  // namespace
}  // namespace lb
