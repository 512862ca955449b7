// Accuracy on the Middlebury sets with every view and one set of parameters (the defaults):
// bad pixels (error over 1 px in the units of the evaluated pair, nonocc mask) at most the
// bounds below. The bounds hold for the label output (subpixel off); the sub-label refinement,
// made for the rendering, is measured and printed beside it (it moves whole-pixel estimates off
// tsukuba's whole-pixel truth). Skipped when ../shared/data/middlebury is absent. Run in
// Release: label `data`.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <vector>

#include "algo/depth/depth_stage.h"
#include "tests/algo/depth/middlebury.h"

namespace lb {
namespace {

// Labels: quarter pixels per view step from 0 to 15.75 px for every set, as the product would
// run without knowing the scene.
DepthConfig MiddleburyConfig(const middlebury::Set& set) {
  DepthConfig c;
  c.width = set.width;
  c.height = set.height;
  c.views = static_cast<int32_t>(set.views.size());
  c.reference = set.reference;
  c.labels = 64;
  c.disp_min_q8 = 0;
  c.disp_max_q8 = 63 * 64;
  return c;
}

void Check(const char* name, double bound) {
  const std::string dir = middlebury::DataDir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/middlebury is absent: nothing to measure";
  middlebury::Set set;
  const Status loaded = middlebury::Load(dir, name, &set);
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  const DepthConfig c = MiddleburyConfig(set);
  const size_t bytes = DepthStage::RequiredBytes(c);
  std::vector<uint8_t> memory(bytes + Arena::kAlign);
  void* const base = Arena::AlignUp(memory.data());
  const std::vector<ConstImageU8> views = set.Views();
  std::vector<uint16_t> disp(static_cast<size_t>(set.width) * set.height);
  const ImageU16 out = MakeView(disp.data(), set.width, set.height);
  double bad[2] = {0, 0};
  for (int refine = 0; refine < 2; ++refine) {
    DepthConfig rc = c;
    rc.subpixel = refine == 1;
    Arena arena(base, bytes);
    DepthStage stage;
    ASSERT_TRUE(stage.Configure(rc, arena).ok());
    const Status computed = stage.Compute(views.data(), out);
    ASSERT_TRUE(computed.ok()) << computed.message();
    bad[refine] = middlebury::BadPixelPercent(set, out.AsConst());
    std::printf("%s: %.2f %% bad (%s; bound %.1f %%), %d labels, %d cycles, energy %lld -> %lld\n",
                name, bad[refine], refine ? "sub-label refined" : "labels", bound, c.labels,
                stage.stats().cycles, static_cast<long long>(stage.stats().initial_energy),
                static_cast<long long>(stage.stats().energy));
  }
  ::testing::Test::RecordProperty("bad_percent", std::to_string(bad[0]));
  ::testing::Test::RecordProperty("bad_percent_refined", std::to_string(bad[1]));
  EXPECT_LE(bad[0], bound) << name;
}

// A move sets only the max-flow nodes a free node can reach (expansion_move.cc: Reach); the
// others keep whatever an earlier graph left there. So garbage in all of them before every move
// must change no label and no energy, in full and in restricted moves, on a real scene (the
// synthetic ones in depth_stage_test rarely put a free node where a wrong read would show).
TEST(MiddleburyTest, MovesReadNoSolverNodeTheyDidNotSet) {
  const std::string dir = middlebury::DataDir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/middlebury is absent: nothing to measure";
  middlebury::Set set;
  ASSERT_TRUE(middlebury::Load(dir, "tsukuba", &set).ok());
  DepthConfig c = MiddleburyConfig(set);
  c.max_cycles = 0;  // winner-take-all labels: the moves below have work to do
  const size_t bytes = DepthStage::RequiredBytes(c);
  std::vector<uint8_t> memory[2];
  DepthStage stages[2];
  const std::vector<ConstImageU8> views = set.Views();
  std::vector<uint16_t> disp(static_cast<size_t>(set.width) * set.height);
  for (int i = 0; i < 2; ++i) {
    memory[i].assign(bytes + Arena::kAlign, 0);
    Arena arena(Arena::AlignUp(memory[i].data()), bytes);
    ASSERT_TRUE(stages[i].Configure(c, arena).ok());
    ASSERT_TRUE(stages[i].Compute(views.data(), MakeView(disp.data(), set.width, set.height)).ok());
  }
  DepthStage &clean = stages[0], &poisoned = stages[1];
  const size_t n = disp.size();
  int32_t lowered = 0;
  for (int32_t window : {DepthConfig::kMaxLabels, 2, 1}) {
    for (int32_t alpha = 0; alpha < c.labels; ++alpha) {
      DepthStageProbe::PoisonSolver(poisoned, alpha % 2 == 0 ? 0x5a : 0xa5);
      const bool a = DepthStageProbe::ExpandMove(clean, alpha, window);
      ASSERT_EQ(DepthStageProbe::ExpandMove(poisoned, alpha, window), a) << alpha;
      ASSERT_EQ(memcmp(poisoned.labels(), clean.labels(), n), 0)
          << "window " << window << ", alpha " << alpha;
      ASSERT_EQ(DepthStageProbe::TrackedEnergy(poisoned), DepthStageProbe::TrackedEnergy(clean));
      lowered += a ? 1 : 0;
    }
  }
  EXPECT_GT(lowered, 0) << "no move lowered the energy: the comparison saw no cut";
}

TEST(MiddleburyTest, Tsukuba) { Check("tsukuba", 2.0); }
TEST(MiddleburyTest, Venus) { Check("venus", 0.8); }
TEST(MiddleburyTest, Teddy) { Check("teddy", 4.5); }

}  // namespace
}  // namespace lb
