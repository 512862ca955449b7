// The data term alone on Middlebury teddy (9 views, 450x375): Prepare (luma + census of every
// view) and ComputeRows over the 64 quarter-pixel labels the depth benchmark uses.
//   build/host/tests/bench/depth/data_term_bench
#include <benchmark/benchmark.h>

#include <vector>

#include "algo/depth/data_term.h"
#include "tests/algo/depth/middlebury.h"

namespace lb {
namespace {

struct Fixture {
  middlebury::Set set;
  std::vector<ConstImageU8> views;
  std::vector<uint8_t> memory;
  DataTerm term;
  bool ok = false;
};

Fixture& Teddy() {
  static Fixture f;
  static bool tried = false;
  if (tried) return f;
  tried = true;
  const std::string dir = middlebury::DataDir();
  if (dir.empty() || !middlebury::Load(dir, "teddy", &f.set).ok()) return f;
  f.views = f.set.Views();
  const int32_t n = static_cast<int32_t>(f.views.size());
  Arena plan;
  DataTerm planner;
  planner.Carve(plan, f.set.width, f.set.height, n);
  f.memory.assign(plan.used() + Arena::kAlign, 0);
  void* const base = Arena::AlignUp(f.memory.data());
  Arena arena(base, plan.used());
  f.term.Carve(arena, f.set.width, f.set.height, n);
  f.term.SetParams(DataTermParams{}, f.set.reference);
  f.term.Prepare(f.views.data());
  f.ok = !arena.overflowed();
  return f;
}

void BM_DataTermPrepare(benchmark::State& state) {
  Fixture& f = Teddy();
  if (!f.ok) return state.SkipWithError("../shared/data/middlebury/teddy is absent");
  for (auto _ : state) f.term.Prepare(f.views.data());
}
BENCHMARK(BM_DataTermPrepare)->Unit(benchmark::kMillisecond);

// All 64 labels (disparities 0..63/4 px per view step), as one winner-take-all pass does.
void BM_DataTermComputeRows(benchmark::State& state) {
  Fixture& f = Teddy();
  if (!f.ok) return state.SkipWithError("../shared/data/middlebury/teddy is absent");
  std::vector<uint16_t> out(static_cast<size_t>(f.set.width) * f.set.height);
  for (auto _ : state) {
    for (int32_t label = 0; label < 64; ++label) {
      f.term.ComputeRows(label * 64, 0, f.set.height, out.data(), f.set.width);
      benchmark::DoNotOptimize(out.data());
    }
  }
}
BENCHMARK(BM_DataTermComputeRows)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace lb

BENCHMARK_MAIN();
