// What a WorkerPool run costs the stage that asks for it: a run of two small tasks (each a
// few hundred additions, well under a microsecond) on a pool of two workers, as the data term
// and the tracker ask for hundreds of times a photo. The time per run is the hand-over alone.
#include <benchmark/benchmark.h>

#include <cstdint>

#include "firmware/platform/worker_pool.h"

namespace lb {
namespace {

void BM_PoolRun(benchmark::State& state) {
  WorkerPool pool;
  if (!pool.Start(static_cast<int32_t>(state.range(0))).ok()) {
    return state.SkipWithError("cannot start the workers");
  }
  int64_t sums[kMaxWorkers] = {};
  auto task = [&](int32_t t, int32_t) {
    int64_t s = sums[t];
    for (int32_t i = 0; i < 256; ++i) s += i ^ t;
    sums[t] = s;
  };
  for (auto _ : state) {
    ParallelFor(pool, static_cast<int32_t>(state.range(0)), task);
    benchmark::DoNotOptimize(sums);
  }
}
BENCHMARK(BM_PoolRun)->ArgName("workers")->Arg(2)->Arg(4)->UseRealTime();

}  // namespace
}  // namespace lb

BENCHMARK_MAIN();
