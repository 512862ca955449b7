// The data term alone on Middlebury teddy (9 views, 450x375): Prepare (luma + census of every
// view) and ComputeRows over the 64 quarter-pixel labels the depth benchmark uses. And on a
// synthetic handheld burst (640x480, 7 views, its 33 labels, as depth_planes_accuracy_test): the
// plane sweep against the rectified shifts over the same labels, each with the C reference
// kernels (/0) and the SIMD ones (/1), so their ratio comes from one process.
//   build/host/tests/bench/depth/data_term_bench
#include <benchmark/benchmark.h>

#include <vector>

#include "algo/depth/data_term.h"
#include "tests/algo/depth/handheld.h"
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

struct Handheld {
  motiontest::Burst burst;
  handheld::Labels labels;
  std::vector<PlaneHomography> planes;  // label-major: one label's views together
  std::vector<uint8_t> memory;
  DataTerm term;
};

Handheld& Handheld640() {
  static Handheld f;
  static bool made = false;
  if (made) return f;
  made = true;
  if (!motiontest::MakeBurst(motiontest::Handheld(1), 640, 480, 7, &f.burst)) return f;
  f.labels = handheld::HandheldLabels(f.burst, 0.1);
  const DepthConfig& c = f.labels.config;
  const std::vector<PlaneHomography> by_view = handheld::Planes(f.burst, f.labels);
  f.planes.resize(by_view.size());
  for (int32_t v = 0; v < c.views; ++v) {
    for (int32_t l = 0; l < c.labels; ++l) f.planes[l * c.views + v] = by_view[v * c.labels + l];
  }
  Arena plan;
  DataTerm planner;
  planner.Carve(plan, c.width, c.height, c.views);
  f.memory.assign(plan.used() + Arena::kAlign, 0);
  Arena arena(Arena::AlignUp(f.memory.data()), plan.used());
  f.term.Carve(arena, c.width, c.height, c.views);
  f.term.SetParams(DataTermParams{}, c.reference);
  f.term.Prepare(f.burst.views.data());
  return f;
}

// Every label of the burst over the whole image; range(0): plane sweep (1) or shifts (0),
// range(1): SIMD kernels (1) or the C reference (0).
void BM_HandheldLabels(benchmark::State& state) {
  Handheld& f = Handheld640();
  if (f.planes.empty()) return state.SkipWithError("no synthetic burst");
  const DepthConfig& c = f.labels.config;
  const bool planes = state.range(0) != 0;
  f.term.UseSimd(state.range(1) != 0);
  std::vector<uint16_t> out(static_cast<size_t>(c.width) * c.height);
  for (auto _ : state) {
    for (int32_t l = 0; l < c.labels; ++l) {
      f.term.SetPlanes(planes ? f.planes.data() + l * c.views : nullptr);
      f.term.ComputeRows(c.disp_min_q8 + l * 64, 0, c.height, out.data(), c.width);
      benchmark::DoNotOptimize(out.data());
    }
  }
  f.term.UseSimd(true);
}
BENCHMARK(BM_HandheldLabels)
    ->ArgNames({"planes", "simd"})
    ->ArgsProduct({{1, 0}, {0, 1}})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace lb

BENCHMARK_MAIN();
