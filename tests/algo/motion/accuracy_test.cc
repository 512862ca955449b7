// Motion accuracy over many seeded handheld bursts (640x480, 5-7 frames, rotations up to 1
// degree, translations up to 1 % of the scene depth), against the scene's true poses. Prints
// the distributions; LB_MOTION_SEEDS sets the number of bursts (docs/accuracy.md's figures use
// 30). The bounds are the motion stage's targets (rotation within 0.05 degree, translation
// direction within 2 degrees), on frames whose pixels integrate their area (4 x 4 samples, as a
// sensor's do). Point-sampled frames of the scene's hard-edged patterns move the tracked corners
// by a fraction of a pixel, so on those the worst directions miss the target: printed beside,
// with a looser guard against regressions.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "algo/motion/motion_stage.h"
#include "tests/algo/motion/burst.h"

namespace lb {
namespace {

double Percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(p * (v.size() - 1) + 0.5)];
}

// The motion stage with `config` (its size and views set from the burst) on `b`.
Status EstimateBurst(const motiontest::Burst& b, MotionConfig config, MotionResult* r) {
  config.width = b.width;
  config.height = b.height;
  config.views = b.scene.views();
  std::vector<uint8_t> memory(MotionStage::RequiredBytes(config));
  Arena arena(memory.data(), memory.size());
  MotionStage stage;
  LB_RETURN_IF_ERROR(stage.Configure(config, arena));
  return stage.Estimate(b.views.data(), b.scene.reference(), b.intrinsics, r);
}

struct Figures {
  std::vector<double> rot, dir, rms;
};

void RunSeeds(int32_t pixel_samples, Figures* f) {
  const char* env = std::getenv("LB_MOTION_SEEDS");
  const int32_t seeds = env ? std::atoi(env) : 3;
  for (int32_t s = 0; s < seeds; ++s) {
    const int32_t views = 5 + s % 3;
    motiontest::Burst b;
    ASSERT_TRUE(
        motiontest::MakeBurst(motiontest::Handheld(100 + s), 640, 480, views, &b, pixel_samples));
    MotionResult r;
    const Status st = EstimateBurst(b, MotionConfig(), &r);
    ASSERT_TRUE(st.ok()) << "seed " << 100 + s << ": " << st.message();
    EXPECT_FALSE(r.rail) << "seed " << 100 + s << ": a hand does not move on a line at equal steps";
    double worst_rot = 0, worst_dir = 0;
    for (int32_t v = 0; v < views; ++v) {
      if (v == b.scene.reference()) continue;
      const double rot = motiontest::RotationErrorDeg(r.motion[v], b.scene.pose(v));
      const double dir = motiontest::TranslationErrorDeg(r.motion[v], b.scene.pose(v));
      worst_rot = std::max(worst_rot, rot);
      worst_dir = std::max(worst_dir, dir);
      f->rot.push_back(rot);
      f->dir.push_back(dir);
    }
    f->rms.push_back(r.rms_px);
    printf(
        "seed %d (%d views, %dx%d samples a pixel): %d points, rms %.3f px, worst rotation %.4f "
        "deg, worst direction %.3f deg\n",
        100 + s, views, pixel_samples, pixel_samples, r.points, r.rms_px, worst_rot, worst_dir);
  }
  ASSERT_FALSE(f->rot.empty());
  printf("rotation error (deg) over %zu views: median %.4f p90 %.4f max %.4f\n", f->rot.size(),
         Percentile(f->rot, 0.5), Percentile(f->rot, 0.9), Percentile(f->rot, 1.0));
  printf("translation direction error (deg): median %.3f p90 %.3f max %.3f\n",
         Percentile(f->dir, 0.5), Percentile(f->dir, 0.9), Percentile(f->dir, 1.0));
  printf("reprojection rms (px): median %.3f max %.3f\n", Percentile(f->rms, 0.5),
         Percentile(f->rms, 1.0));
}

TEST(MotionAccuracy, HandheldBurstsOverSeeds) {
  Figures f;
  ASSERT_NO_FATAL_FAILURE(RunSeeds(4, &f));
  EXPECT_LT(Percentile(f.rot, 1.0), 0.05);
  EXPECT_LT(Percentile(f.dir, 1.0), 2.0);
}

TEST(MotionAccuracy, PointSampledBurstsOverSeeds) {
  Figures f;
  ASSERT_NO_FATAL_FAILURE(RunSeeds(1, &f));
  EXPECT_LT(Percentile(f.rot, 1.0), 0.05);
  EXPECT_LT(Percentile(f.dir, 0.5), 2.0);
  EXPECT_LT(Percentile(f.dir, 0.9), 3.0);
}

// A lens nobody told: the frames of a wide handheld burst show the focal length; where they show
// less (a narrow view) the estimate must not wander further off than the guess.
TEST(MotionAccuracy, TheFramesTellTheFocalLengthWhereTheyCan) {
  for (const double fov : {65.0, 25.0}) {
    SceneParams params = motiontest::Handheld(11);
    params.fov_deg = fov;
    params.max_translation = 0.01 * std::tan(fov * M_PI / 360) / std::tan(32.5 * M_PI / 180);
    motiontest::Burst b;
    ASSERT_TRUE(motiontest::MakeBurst(params, 640, 480, 7, &b, 4));
    const double truth = b.intrinsics.fx;
    for (const double told : {1.25, 0.8}) {
      b.intrinsics.fx = b.intrinsics.fy = truth * told;
      MotionConfig config;
      config.estimate_focal = true;
      MotionResult r;
      const Status st = EstimateBurst(b, config, &r);
      ASSERT_TRUE(st.ok()) << st.message();
      const double found = r.intrinsics.fx / truth;
      printf("%.0f degrees, told %.2fx: found %.3fx the true focal length\n", fov, told, found);
      // Never further from the truth than the guess, and close to it where the view is wide.
      EXPECT_LE(std::fabs(found - 1), std::fabs(told - 1) + 0.02) << fov << " told " << told;
      if (fov > 40) {
        EXPECT_NEAR(found, 1.0, 0.1) << "told " << told;
      }
    }
  }
}

}  // namespace
}  // namespace lb
