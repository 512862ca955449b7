// The web page's renders of a 12 MP photo: the tap -> preview render (longer side
// 1024 px, from the downscaled original and depth map, encoded to JPEG in memory), the full-size
// re-render (encoded in memory, as the page receives it) and loading the photo (read, XMP walk,
// GImage and depth decode, preview inputs). The photo is the synthetic camera's own (made once,
// before timing, with the daemon's job). One engine, sized for 4056x3040; threads as the range.
//   chrt -f 10 build/host/tests/bench/app/preview_bench --benchmark_repetitions=5
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "firmware/app/focus.h"
#include "firmware/app/job.h"
#include "firmware/app/refocus_engine.h"
#include "sim/synthetic/synthetic_sensor.h"

namespace lb {
namespace {

constexpr int32_t kWidth = 4056, kHeight = 3040;

const std::string& Photo() {
  static const std::string path = [] {
    char dir[] = "/tmp/lb_preview_bench_XXXXXX";
    std::string p = mkdtemp(dir) ? std::string(dir) + "/IMG_0001.jpg" : "";
    SceneParams params;
    params.geometry = ViewGeometry::kHandheld;
    SyntheticSensor sensor(params);
    Job job;
    JobOptions o;
    o.sensor.width = kWidth;
    o.sensor.height = kHeight;
    o.pipeline.labels = 32;
    Status s = job.Configure(&sensor, o);
    if (s.ok()) s = job.Run(p.c_str(), nullptr);
    if (!s.ok()) fprintf(stderr, "preview_bench: %s\n", s.message());
    return p;
  }();
  return path;
}

RefocusEngine* Engine(int32_t threads) {
  static RefocusEngine* engines[17] = {};
  if (engines[threads] == nullptr) {
    auto* e = new RefocusEngine;
    RefocusEngineConfig c;
    c.max_width = kWidth;
    c.max_height = kHeight;
    c.threads = threads;
    Status s = e->Configure(c);
    if (s.ok()) s = e->Load(Photo().c_str());
    if (!s.ok()) fprintf(stderr, "preview_bench: %s\n", s.message());
    engines[threads] = e;
  }
  return engines[threads];
}

// Taps alternate between a near and a far point, as a user trying the page would.
RenderParams Tap(int64_t i) {
  RenderParams p;
  p.focus =
      (i & 1) ? FocusAtPoint(kWidth / 5, kHeight * 4 / 5) : FocusAtPoint(kWidth / 2, kHeight / 3);
  p.f_number = 2.8f;
  return p;
}

void BM_Preview1024(benchmark::State& state) {
  RefocusEngine* e = Engine(static_cast<int32_t>(state.range(0)));
  int64_t i = 0;
  for (auto _ : state) {
    Status s = e->RenderPreview(Tap(i++));
    if (!s.ok()) state.SkipWithError(s.message());
  }
  state.counters["width"] = e->photo().preview_width;
  state.counters["jpeg_KiB"] = static_cast<double>(e->output_size()) / 1024.0;
}
BENCHMARK(BM_Preview1024)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Full12MP(benchmark::State& state) {
  RefocusEngine* e = Engine(static_cast<int32_t>(state.range(0)));
  int64_t i = 0;
  for (auto _ : state) {
    Status s = e->RenderFull(Tap(i++));
    if (!s.ok()) state.SkipWithError(s.message());
  }
  state.counters["jpeg_MiB"] = static_cast<double>(e->output_size()) / (1 << 20);
}
BENCHMARK(BM_Full12MP)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Load12MP(benchmark::State& state) {
  RefocusEngine* e = Engine(1);
  for (auto _ : state) {
    Status s = e->Load(Photo().c_str());
    if (!s.ok()) state.SkipWithError(s.message());
  }
  state.counters["reserved_MiB"] = static_cast<double>(e->reserved_bytes()) / (1 << 20);
}
BENCHMARK(BM_Load12MP)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace lb

BENCHMARK_MAIN();
