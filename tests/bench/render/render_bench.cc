// Render stage at 12 MP (4056x3040), one thread: Begin plus every strip, for a scene of layered
// depths (a far wall, a slanted ground, objects at several depths), focus on the middle object.
// And the map a 12 MP photo carries (depth_refine.h: the 579x434 depth grid onto 1352x1013), on
// 1 and 2 workers.
//   build/<release>/tests/bench/render/render_bench --benchmark_filter=Render
//   build/<release>/tests/bench/render/render_bench --benchmark_filter=Map
#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

#include "algo/render/depth_refine.h"
#include "algo/render/render_stage.h"
#include "firmware/platform/worker_pool.h"

namespace lb {
namespace {

struct Scene {
  int32_t w, h, scale, ww, wh;
  std::vector<uint8_t> y, cb, cr;
  std::vector<uint16_t> disp;
  Scene(int32_t width, int32_t height, int32_t s)
      : w(width), h(height), scale(s), ww(width / s), wh(height / s) {
    const int32_t cw = (w + 1) / 2, ch = (h + 1) / 2;
    y.resize(static_cast<size_t>(w) * h);
    cb.resize(static_cast<size_t>(cw) * ch);
    cr.resize(cb.size());
    uint32_t state = 12345;
    for (size_t i = 0; i < y.size(); ++i) {
      state = state * 1664525u + 1013904223u;
      y[i] = static_cast<uint8_t>(((i % w) / 7 + (i / w) / 5) * 3 + (state >> 28));
    }
    for (size_t i = 0; i < cb.size(); ++i) cb[i] = static_cast<uint8_t>(100 + (i % cw) / 40);
    for (size_t i = 0; i < cr.size(); ++i) cr[i] = static_cast<uint8_t>(150 - (i / cw) / 30);
    disp.resize(static_cast<size_t>(ww) * wh);
    for (int32_t j = 0; j < wh; ++j) {
      for (int32_t i = 0; i < ww; ++i) {
        uint16_t d = 1 << 8;  // far wall
        if (j > wh * 3 / 4) d = static_cast<uint16_t>(256 + (j - wh * 3 / 4) * 2560 / (wh / 4));
        if (i > ww / 5 && i < ww / 2 && j > wh / 5 && j < wh * 7 / 10) d = 4 << 8;  // focus
        const int32_t dx = i - ww * 2 / 3, dy = j - wh * 2 / 5;
        if (dx * dx + dy * dy < ww * ww / 30) d = 8 << 8;  // near disc
        disp[static_cast<size_t>(j) * ww + i] = d;
      }
    }
  }
};

void BM_Render12MP(benchmark::State& state) {
  const int32_t max_radius = static_cast<int32_t>(state.range(0));
  static const Scene scene(4056, 3040, 7);
  RenderConfig config;
  config.width = scene.w, config.height = scene.h, config.working_scale = scene.scale;
  config.working_width = scene.ww, config.working_height = scene.wh;
  config.max_radius = max_radius;
  const size_t bytes = RenderStage::RequiredBytes(config);
  std::vector<uint8_t> block(bytes + Arena::kAlign);
  Arena arena(block.data() + (Arena::kAlign - reinterpret_cast<uintptr_t>(block.data()) % 64),
              bytes);
  RenderStage stage;
  if (!stage.Configure(config, arena).ok()) {
    state.SkipWithError("configure failed");
    return;
  }
  ConstPlanarU8 ref;
  ref.count = 3;
  ref.planes[0] = MakeView(scene.y.data(), scene.w, scene.h).AsConst();
  ref.planes[1] = MakeView(scene.cb.data(), (scene.w + 1) / 2, (scene.h + 1) / 2).AsConst();
  ref.planes[2] = MakeView(scene.cr.data(), (scene.w + 1) / 2, (scene.h + 1) / 2).AsConst();
  RenderParams params;
  params.f_number = 2.8f;
  params.focus = {scene.w / 4, scene.h / 3, scene.w / 5, scene.h / 4};
  params.aperture.blades = static_cast<int32_t>(state.range(1));
  uint64_t sum = 0;
  for (auto _ : state) {
    if (!stage.Begin(ref, MakeView(scene.disp.data(), scene.ww, scene.wh).AsConst(), params).ok()) {
      state.SkipWithError("begin failed");
      return;
    }
    for (int32_t rows = 1; rows > 0;) {
      ConstPlanarU8 strip;
      int32_t y0 = 0;
      if (!stage.NextStrip(&strip, &y0, &rows).ok()) break;
      if (rows > 0) sum += strip.planes[0].Row(0)[y0 % scene.w];
    }
  }
  benchmark::DoNotOptimize(sum);
  state.counters["arena_MiB"] = static_cast<double>(bytes) / (1 << 20);
  state.counters["Mpx/s"] = benchmark::Counter(static_cast<double>(scene.w) * scene.h / 1e6,
                                               benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_Render12MP)
    ->Args({32, 0})
    ->Args({32, 6})
    ->Args({16, 0})
    ->Args({8, 0})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.5);

void BM_Map12MP(benchmark::State& state) {
  static const Scene scene(4056, 3040, 6);  // the default working size's 676x506
  RefineConfig config;
  config.width = scene.w, config.height = scene.h;
  config.work_scale = scene.scale, config.work_width = scene.ww, config.work_height = scene.wh;
  config.map_scale = DepthRefiner::MapScale(scene.w, scene.h, scene.scale);
  config.map_width = scene.w / config.map_scale, config.map_height = scene.h / config.map_scale;
  config.workers = static_cast<int32_t>(state.range(0));
  const size_t bytes = DepthRefiner::RequiredBytes(config);
  std::vector<uint8_t> block(bytes + Arena::kAlign);
  Arena arena(Arena::AlignUp(block.data()), bytes);
  DepthRefiner refiner;
  refiner.Carve(config, arena);
  WorkerPool pool;
  if (!pool.Start(config.workers).ok()) {
    state.SkipWithError("no workers");
    return;
  }
  refiner.SetRunner(&pool);
  ConstPlanarU8 ref;
  ref.count = 3;
  ref.planes[0] = MakeView(scene.y.data(), scene.w, scene.h).AsConst();
  ref.planes[1] = MakeView(scene.cb.data(), (scene.w + 1) / 2, (scene.h + 1) / 2).AsConst();
  ref.planes[2] = MakeView(scene.cr.data(), (scene.w + 1) / 2, (scene.h + 1) / 2).AsConst();
  std::vector<uint16_t> map(static_cast<size_t>(config.map_width) * config.map_height);
  std::vector<uint8_t> confidence(static_cast<size_t>(scene.ww) * scene.wh, 200);
  std::vector<uint8_t> map_confidence(map.size());
  for (auto _ : state) {
    refiner.Run(ref, MakeView(scene.disp.data(), scene.ww, scene.wh).AsConst(),
                MakeView(confidence.data(), scene.ww, scene.wh).AsConst(),
                MakeView(map.data(), config.map_width, config.map_height),
                MakeView(map_confidence.data(), config.map_width, config.map_height));
  }
  benchmark::DoNotOptimize(map.data());
  state.counters["scratch_KiB"] = static_cast<double>(bytes) / 1024;
}
BENCHMARK(BM_Map12MP)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);

}  // namespace
}  // namespace lb

BENCHMARK_MAIN();
