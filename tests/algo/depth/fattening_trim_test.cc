#include "algo/depth/fattening_trim.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace lb {
namespace {

constexpr int32_t kW = 48, kH = 32;
constexpr uint16_t kFar = 10 << 8, kNear = 14 << 8;
constexpr int32_t kStep = DepthConfig::kSmoothSpacingQ8;  // labels as fine as that

struct Scene {
  std::vector<uint8_t> rgb = std::vector<uint8_t>(static_cast<size_t>(kW) * kH * 3);
  std::vector<uint16_t> disp = std::vector<uint16_t>(static_cast<size_t>(kW) * kH);
  ConstImageU8 Reference() const { return {rgb.data(), kW, kH, 3, kW * 3}; }
  ImageU16 Map() { return {disp.data(), kW, kH, 1, kW}; }
  uint16_t At(int32_t x, int32_t y) const { return disp[static_cast<size_t>(y) * kW + x]; }
};

// A textured near block (columns < edge) in front of a textured far wall of another colour.
Scene TwoSurfaces(int32_t edge) {
  Scene s;
  uint32_t seed = 7;
  for (int32_t y = 0; y < kH; ++y) {
    for (int32_t x = 0; x < kW; ++x) {
      seed = seed * 1664525u + 1013904223u;
      const int32_t grain = static_cast<int32_t>(seed >> 30);  // 0..3
      uint8_t* p = &s.rgb[(static_cast<size_t>(y) * kW + x) * 3];
      const bool near = x < edge;
      p[0] = static_cast<uint8_t>((near ? 200 : 60) + grain);
      p[1] = static_cast<uint8_t>((near ? 90 : 120) + grain);
      p[2] = static_cast<uint8_t>((near ? 40 : 170) + grain);
    }
  }
  return s;
}

// Runs the trim of `s`'s map on one worker (the map is replaced); returns the pixels moved.
int64_t Trim(Scene* s) {
  const size_t bytes = FatteningTrim::RequiredBytes(kW, 1);
  std::vector<uint8_t> block(bytes + Arena::kAlign);
  Arena arena(Arena::AlignUp(block.data()), bytes);
  FatteningTrim trim;
  trim.Carve(arena, kW, 1);
  const std::vector<uint16_t> in = s->disp;
  return trim.Run(s->Reference(), MakeView(in.data(), kW, kH).AsConst(), s->Map(), kStep);
}

TEST(FatteningTrim, TheNearSidesOverreachReturnsToThePhotosEdge) {
  constexpr int32_t kEdge = 20, kOverreach = 2;
  Scene s = TwoSurfaces(kEdge);
  for (int32_t y = 0; y < kH; ++y)
    for (int32_t x = 0; x < kW; ++x)
      s.disp[static_cast<size_t>(y) * kW + x] = x < kEdge + kOverreach ? kNear : kFar;
  const int64_t moved = Trim(&s);
  EXPECT_EQ(moved, int64_t{kOverreach} * kH);
  for (int32_t y = 0; y < kH; ++y)
    for (int32_t x = 0; x < kW; ++x)
      ASSERT_EQ(s.At(x, y), x < kEdge ? kNear : kFar) << "at " << x << "," << y;
}

TEST(FatteningTrim, ThePixelsAreNeverPulledNearer) {
  // The far side over the near block's edge: not the data term's bias, left as it is.
  constexpr int32_t kEdge = 20;
  Scene s = TwoSurfaces(kEdge);
  for (int32_t y = 0; y < kH; ++y)
    for (int32_t x = 0; x < kW; ++x)
      s.disp[static_cast<size_t>(y) * kW + x] = x < kEdge - 3 ? kNear : kFar;
  const std::vector<uint16_t> before = s.disp;
  EXPECT_EQ(Trim(&s), 0);
  EXPECT_EQ(s.disp, before);
}

TEST(FatteningTrim, ASlantedSurfaceKeepsItsSlopeUpToTheBorders) {
  // One colour, a ramp of 0.125 px a pixel: every window spans more than a step, and each is
  // centred, so its median is its centre, at the borders too.
  Scene s = TwoSurfaces(0);
  for (size_t i = 0; i < s.rgb.size(); ++i) s.rgb[i] = 128;
  for (int32_t y = 0; y < kH; ++y)
    for (int32_t x = 0; x < kW; ++x)
      s.disp[static_cast<size_t>(y) * kW + x] = static_cast<uint16_t>(kFar + 32 * x + 8 * y);
  const std::vector<uint16_t> before = s.disp;
  EXPECT_EQ(Trim(&s), 0);
  EXPECT_EQ(s.disp, before);
}

TEST(FatteningTrim, SmallStepsAreNotEdges) {
  // The overreach of a step no larger than kStep is left: within the labels' own noise.
  constexpr int32_t kEdge = 20;
  Scene s = TwoSurfaces(kEdge);
  for (int32_t y = 0; y < kH; ++y)
    for (int32_t x = 0; x < kW; ++x)
      s.disp[static_cast<size_t>(y) * kW + x] = x < kEdge + 3 ? kFar + kStep : kFar;
  const std::vector<uint16_t> before = s.disp;
  EXPECT_EQ(Trim(&s), 0);
  EXPECT_EQ(s.disp, before);
}

// Bands on several workers read only the map they were given: the same bits as one worker.
class CountingRunner final : public TaskRunner {
 public:
  int32_t workers() const override { return 3; }
  void Run(int32_t tasks, TaskFn fn, void* context) override {
    for (int32_t t = tasks - 1; t >= 0; --t) fn(context, t, t % 3);  // last band first
    runs += tasks;
  }
  int32_t runs = 0;
};

TEST(FatteningTrim, AnyNumberOfWorkersGivesTheSameMap) {
  Scene s = TwoSurfaces(20);
  for (int32_t y = 0; y < kH; ++y)
    for (int32_t x = 0; x < kW; ++x)
      s.disp[static_cast<size_t>(y) * kW + x] =
          static_cast<uint16_t>(x < 22 + (y % 5) ? kNear : kFar + 4 * y);
  Scene one = s;
  const int64_t moved_one = Trim(&one);
  ASSERT_GT(moved_one, 0);
  const size_t bytes = FatteningTrim::RequiredBytes(kW, 3);
  std::vector<uint8_t> block(bytes + Arena::kAlign);
  Arena arena(Arena::AlignUp(block.data()), bytes);
  FatteningTrim trim;
  trim.Carve(arena, kW, 3);
  CountingRunner runner;
  trim.SetRunner(&runner);
  const std::vector<uint16_t> in = s.disp;
  EXPECT_EQ(trim.Run(s.Reference(), MakeView(in.data(), kW, kH).AsConst(), s.Map(), kStep),
            moved_one);
  EXPECT_GT(runner.runs, 1);
  EXPECT_EQ(s.disp, one.disp);
}

}  // namespace
}  // namespace lb
