// The depth map's confidence through the pipeline: next to the disparity map at the working size,
// kept through the render that takes over the depth stage's memory, with the whole burst's share
// of low-confidence pixels; off by the configuration, with the same disparity map.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "algo/pipeline/pipeline.h"
#include "tests/algo/pipeline/pipeline_burst.h"

namespace lb {
namespace {

using pipelinetest::Burst;
using pipelinetest::ImageChecksum;
using pipelinetest::RenderChecksum;

TEST(PipelineConfidence, TheMapSitsNextToTheDisparityAndOutlivesTheRender) {
  Burst b;
  b.config.confidence = true;
  b.Setup(192, 144, 5);
  ASSERT_TRUE(b.sensor->CaptureBurst(b.pipeline).ok());
  ASSERT_TRUE(b.pipeline.ComputeDepth().ok());
  const ConstImageU8 confidence = b.pipeline.confidence();
  const int32_t w = b.pipeline.working_width(), h = b.pipeline.working_height();
  ASSERT_EQ(confidence.width, w);
  ASSERT_EQ(confidence.height, h);
  ASSERT_NE(confidence.data, nullptr);
  // The scene is textured: most of its depth is sure.
  const int32_t permille = b.pipeline.low_confidence_permille();
  RecordProperty("low_confidence_permille", std::to_string(permille));
  EXPECT_LT(permille, Pipeline::kRetakePermille);
  // Wrong depth (off the truth by more than 1 px) is commoner where the map is unsure.
  std::vector<uint16_t> truth(static_cast<size_t>(w) * h);
  ASSERT_TRUE(
      b.sensor->scene().DisparityRows(b.pipeline.working_scale(), 0, h, truth.data(), w).ok());
  const int32_t bias = DepthStage::MapBiasQ8(b.pipeline.disp_min_q8());
  int64_t low = 0, low_wrong = 0, wrong = 0, guesses = 0;
  for (int32_t y = 0; y < h; ++y) {
    for (int32_t x = 0; x < w; ++x) {
      const bool bad =
          std::abs(b.pipeline.disparity_q8().Row(y)[x] - bias - truth[y * w + x]) > 256;
      const bool unsure = confidence.Row(y)[x] < DepthStage::kLowConfidence;
      guesses += confidence.Row(y)[x] < Pipeline::kGuessConfidence;
      low += unsure ? 1 : 0;
      low_wrong += unsure && bad ? 1 : 0;
      wrong += bad ? 1 : 0;
    }
  }
  EXPECT_EQ(guesses * 1000 / (int64_t{w} * h), permille);
  RecordProperty("wrong_low", std::to_string(low_wrong) + " of " + std::to_string(low));
  RecordProperty("wrong_high",
                 std::to_string(wrong - low_wrong) + " of " + std::to_string(int64_t{w} * h - low));
  if (low > 0 && wrong > low_wrong) {
    EXPECT_GE(low_wrong * (int64_t{w} * h - low), 3 * (wrong - low_wrong) * low);
  }
  const uint64_t before = ImageChecksum(confidence);
  int32_t rows = 0;
  (void)RenderChecksum(b.pipeline, RenderParams(), &rows);
  EXPECT_EQ(rows, b.config.height);
  EXPECT_EQ(ImageChecksum(b.pipeline.confidence()), before);
}

TEST(PipelineConfidence, OffItLeavesTheDisparityAndCarvesLess) {
  Burst on;
  on.config.confidence = true;
  on.Setup(160, 120, 5);
  ASSERT_TRUE(on.sensor->CaptureBurst(on.pipeline).ok());
  ASSERT_TRUE(on.pipeline.ComputeDepth().ok());
  Burst off;
  SceneParams scene;
  scene.seed = 7;
  ASSERT_NO_FATAL_FAILURE(off.Open(scene, 160, 120, 5));
  off.config = on.config;
  off.config.confidence = false;
  ASSERT_NO_FATAL_FAILURE(off.ConfigurePipeline());
  ASSERT_TRUE(off.sensor->CaptureBurst(off.pipeline).ok());
  ASSERT_TRUE(off.pipeline.ComputeDepth().ok());
  EXPECT_EQ(ImageChecksum(off.pipeline.disparity_q8()), ImageChecksum(on.pipeline.disparity_q8()));
  EXPECT_EQ(off.pipeline.confidence().data, nullptr);
  EXPECT_EQ(off.pipeline.low_confidence_permille(), 0);
  size_t with = 0, without = 0;
  ASSERT_TRUE(Pipeline::RequiredBytes(on.config, &with).ok());
  ASSERT_TRUE(Pipeline::RequiredBytes(off.config, &without).ok());
  EXPECT_LT(without, with);
}

}  // namespace
}  // namespace lb
