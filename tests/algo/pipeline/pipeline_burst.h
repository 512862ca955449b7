// The synthetic bursts of the pipeline tests (a seeded scene through the synthetic sensor, the
// pipeline configured once on its own aligned block), checksums of what the pipeline holds and
// renders, and the board's default path with its allocation count after Configure.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <memory>

#include "algo/pipeline/pipeline.h"
#include "firmware/platform/arena_block.h"
#include "firmware/platform/worker_pool.h"
#include "sim/synthetic/synthetic_sensor.h"
#include "tests/support/alloc_counter.h"

namespace lb::pipelinetest {

struct Burst {
  std::unique_ptr<SyntheticSensor> sensor;
  SensorMode mode;
  PipelineConfig config;
  ArenaBlock arena;
  Pipeline pipeline;
  WorkerPool pool;  // started by ConfigurePipeline when config.workers > 1

  // A small rectified burst with labels over the scene's true disparity range.
  void Setup(int32_t width, int32_t height, int32_t frames) {
    SceneParams params;
    params.seed = 7;
    ASSERT_NO_FATAL_FAILURE(Open(params, width, height, frames));
    config.labels = 24;
    config.disp_min_q8 = 0;
    config.disp_max_q8 = sensor->scene().disparity_max_q8(1) + 256;
    config.max_blur_radius = 12;
    ConfigurePipeline();
  }

  // The board's default path (firmware/daemon/config.cc, DaemonJobDefaults): a handheld burst
  // and auto geometry, so the motion stage recovers the poses and sets the label range; the
  // board's 32 labels and the default blur radius (and working size, unless config's was set).
  void SetupBoard(int32_t width, int32_t height, int32_t frames, double max_translation) {
    SceneParams params;
    params.seed = 7;
    params.geometry = ViewGeometry::kHandheld;
    params.max_translation = max_translation;
    ASSERT_NO_FATAL_FAILURE(Open(params, width, height, frames));
    config.labels = 32;
    config.geometry = ViewGeometry::kAuto;
    ConfigurePipeline();
  }

  // The sensor, and the configuration's frame size, count and reference from its mode.
  void Open(const SceneParams& params, int32_t width, int32_t height, int32_t frames) {
    sensor = std::make_unique<SyntheticSensor>(params);
    SensorConfig sc;
    sc.width = width;
    sc.height = height;
    sc.frames = frames;
    ASSERT_TRUE(sensor->Configure(sc, &mode).ok());
    config.width = mode.width;
    config.height = mode.height;
    config.frames = mode.frames;
    config.reference = sensor->scene().reference();
  }

  // The pipeline on its own aligned block of the bytes it asks for.
  void ConfigurePipeline() {
    size_t bytes = 0;
    ASSERT_TRUE(Pipeline::RequiredBytes(config, &bytes).ok());
    ASSERT_TRUE(arena.Reserve(bytes, "for the pipeline").ok());
    Status s = pipeline.Configure(config, arena.data(), bytes);
    ASSERT_TRUE(s.ok()) << s.message();
    ASSERT_TRUE(pool.Start(config.workers).ok());
    pipeline.SetRunner(&pool);
  }
};

inline uint64_t Fnv(uint64_t h, const uint8_t* p, size_t n) {
  for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

// FNV-1a of an image's samples, row by row (padding excluded).
template <typename T>
inline uint64_t ImageChecksum(ImageView<const T> img) {
  uint64_t h = 1469598103934665603ull;
  for (int32_t y = 0; y < img.height; ++y) {
    h = Fnv(h, reinterpret_cast<const uint8_t*>(img.Row(y)),
            sizeof(T) * static_cast<size_t>(img.width) * img.channels);
  }
  return h;
}

// FNV-1a over every rendered sample, plane by plane within each strip.
inline uint64_t RenderChecksum(Pipeline& p, const RenderParams& params, int32_t* rows_seen) {
  uint64_t h = 1469598103934665603ull;
  *rows_seen = 0;
  EXPECT_TRUE(p.BeginRender(params).ok());
  for (;;) {
    ConstPlanarU8 strip;
    int32_t y0 = 0, rows = 0;
    Status s = p.NextStrip(&strip, &y0, &rows);
    EXPECT_TRUE(s.ok()) << s.message();
    if (!s.ok() || rows == 0) break;
    EXPECT_EQ(y0, *rows_seen);
    for (int plane = 0; plane < 3; ++plane) {
      const ConstImageU8& img = strip.planes[plane];
      const int32_t n = plane == 0 ? rows : (rows + 1) / 2;
      for (int32_t y = 0; y < n; ++y) {
        for (int32_t x = 0; x < img.width; ++x) h = (h ^ img.Row(y)[x]) * 1099511628211ull;
      }
    }
    *rows_seen += rows;
  }
  return h;
}

// Capture, depth (the motion stage included) and every rendered strip of the board's default
// path allocate nothing once the pipeline is configured, with `threads` workers running.
inline void ExpectBoardPathAllocatesNothing(int32_t width, int32_t height,
                                            int32_t max_working_width = 640,
                                            int32_t max_working_height = 480,
                                            double max_translation = 0.01, int32_t threads = 1) {
  Burst b;
  b.config.workers = threads;
  b.config.max_working_width = max_working_width;
  b.config.max_working_height = max_working_height;
  b.SetupBoard(width, height, 5, max_translation);
  ASSERT_GT(b.pipeline.working_scale(), 1) << "the frames are downscaled for depth";
  RenderParams params;
  params.f_number = 2.0f;
  const size_t before = testing::AllocationCount();
  const Status captured = b.sensor->CaptureBurst(b.pipeline);
  const Status depth = captured.ok() ? b.pipeline.ComputeDepth() : captured;
  int32_t rows = 0;
  if (depth.ok()) (void)RenderChecksum(b.pipeline, params, &rows);
  const size_t after = testing::AllocationCount();
  ASSERT_TRUE(captured.ok()) << captured.message();
  ASSERT_TRUE(depth.ok()) << depth.message();
  EXPECT_TRUE(b.pipeline.depth_warning().ok())
      << "the motion stage gave up: " << b.pipeline.depth_warning().message();
  EXPECT_EQ(rows, height);
  EXPECT_EQ(after - before, 0u) << "heap allocations during capture, motion, depth and render";
}

}  // namespace lb::pipelinetest
