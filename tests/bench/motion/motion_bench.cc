// The motion stage on a synthetic handheld burst: 7 frames at the working resolution 640x480,
// one thread (pyramids, corners, tracking, bundle adjustment and checks).
//   build/host/tests/bench/motion/motion_bench
#include <benchmark/benchmark.h>

#include <vector>

#include "algo/motion/motion_stage.h"
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

}  // namespace
}  // namespace lb

BENCHMARK_MAIN();
