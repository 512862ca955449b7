// The motion stage on a synthetic handheld burst: 7 frames at the working resolution 640x480,
// one thread (pyramids, corners, tracking, bundle adjustment and checks), and beside it the whole
// pipeline on the same burst with auto geometry (ingest, motion, depth, render), so the motion
// stage's share of a run is a ratio of two figures from one process; and the stage on one
// worker against two.
//   build/host/tests/bench/motion/motion_bench
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <vector>

#include "algo/motion/motion_stage.h"
#include "algo/pipeline/pipeline.h"
#include "firmware/platform/worker_pool.h"
#include "sim/synthetic/synthetic_sensor.h"
#include "tests/algo/motion/burst.h"

namespace lb {
namespace {

void BM_MotionStage7x640x480(benchmark::State& state) {
  motiontest::Burst b;
  if (!motiontest::MakeBurst(motiontest::Handheld(1), 640, 480, 7, &b)) {
    state.SkipWithError("scene");
    return;
  }
  MotionConfig config;
  config.width = 640;
  config.height = 480;
  config.views = 7;
  std::vector<uint8_t> memory(MotionStage::RequiredBytes(config));
  Arena arena(memory.data(), memory.size());
  MotionStage stage;
  if (!stage.Configure(config, arena).ok()) {
    state.SkipWithError("configure");
    return;
  }
  MotionResult r;
  for (auto _ : state) {
    const Status st = stage.Estimate(b.views.data(), b.scene.reference(), b.intrinsics, &r);
    if (!st.ok()) state.SkipWithError(st.message());
    benchmark::DoNotOptimize(r);
  }
  state.counters["points"] = r.points;
  state.counters["arena_MB"] = static_cast<double>(memory.size()) / (1 << 20);
}
BENCHMARK(BM_MotionStage7x640x480)->Unit(benchmark::kMillisecond)->MinTime(2.0);

// The same stage on one worker and on two (the board's pool) by turns, wall times: the counters
// are each side's median and the median of the per-turn ratios (one / two), the scaling.
void BM_MotionStageTwoWorkers(benchmark::State& state) {
  motiontest::Burst b;
  if (!motiontest::MakeBurst(motiontest::Handheld(1), 640, 480, 7, &b)) {
    return state.SkipWithError("scene");
  }
  MotionConfig config;
  config.width = 640;
  config.height = 480;
  config.views = 7;
  config.workers = 2;
  WorkerPool pool;
  if (!pool.Start(config.workers).ok()) return state.SkipWithError("no worker threads");
  std::vector<uint8_t> memory[2];
  MotionStage stage[2];
  for (int32_t i = 0; i < 2; ++i) {
    memory[i].resize(MotionStage::RequiredBytes(config));
    Arena arena(memory[i].data(), memory[i].size());
    if (!stage[i].Configure(config, arena).ok()) return state.SkipWithError("configure");
  }
  stage[1].SetRunner(&pool);
  MotionResult r;
  std::vector<double> ms[2], ratios;
  using Clock = std::chrono::steady_clock;
  for (auto _ : state) {
    for (int32_t i = 0; i < 2; ++i) {
      const Clock::time_point t0 = Clock::now();
      const Status st = stage[i].Estimate(b.views.data(), b.scene.reference(), b.intrinsics, &r);
      if (!st.ok()) state.SkipWithError(st.message());
      benchmark::DoNotOptimize(r);
      ms[i].push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    }
    ratios.push_back(ms[0].back() / ms[1].back());
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
  };
  state.counters["one_ms"] = median(ms[0]);
  state.counters["two_ms"] = median(ms[1]);
  state.counters["ratio"] = median(ratios);
}
BENCHMARK(BM_MotionStageTwoWorkers)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(4.0);

// Whole run, 640x480 frames (working resolution = full resolution), 7 frames, 64 labels.
void BM_PipelineAuto7x640x480(benchmark::State& state) {
  SyntheticSensor sensor(motiontest::Handheld(1));
  SensorConfig sc;
  sc.width = 640;
  sc.height = 480;
  sc.frames = 7;
  SensorMode mode;
  if (!sensor.Configure(sc, &mode).ok()) {
    state.SkipWithError("sensor");
    return;
  }
  PipelineConfig c;
  c.width = mode.width;
  c.height = mode.height;
  c.frames = mode.frames;
  c.reference = sensor.scene().reference();
  c.geometry = ViewGeometry::kAuto;
  c.focal_px = mode.focal_px;
  size_t bytes = 0;
  if (!Pipeline::RequiredBytes(c, &bytes).ok()) {
    state.SkipWithError("config");
    return;
  }
  std::vector<uint8_t> memory(bytes + Arena::kAlign);
  void* const base = Arena::AlignUp(memory.data());
  Pipeline p;
  if (!p.Configure(c, base, bytes).ok()) {
    state.SkipWithError("configure");
    return;
  }
  RenderParams render;
  for (auto _ : state) {
    p.ResetBurst();
    Status s = sensor.CaptureBurst(p);
    if (s.ok()) s = p.ComputeDepth();
    if (s.ok()) s = p.BeginRender(render);
    for (int32_t rows = 1; s.ok() && rows > 0;) {
      ConstPlanarU8 strip;
      int32_t y0 = 0;
      s = p.NextStrip(&strip, &y0, &rows);
    }
    if (!s.ok()) state.SkipWithError(s.message());
    if (!p.depth_warning().ok()) state.SkipWithError(p.depth_warning().message());
  }
  state.counters["arena_MB"] = static_cast<double>(bytes) / (1 << 20);
}
BENCHMARK(BM_PipelineAuto7x640x480)->Unit(benchmark::kMillisecond)->MinTime(2.0);

}  // namespace
}  // namespace lb

BENCHMARK_MAIN();
