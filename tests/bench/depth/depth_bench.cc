// The depth stage on Middlebury teddy (9 views, 450x375, 64 quarter-pixel labels), one thread,
// and - when OpenCV is installed - OpenCV's StereoSGBM on the same set's im2/im6 pair, so the
// ratio is measured side by side on the same machine.
// And the plane sweep against the rectified shifts on a synthetic handheld burst (the case
// depth_planes_accuracy_test prints), in CPU time.
//   build/host/tests/bench/depth/depth_bench --benchmark_counters_tabular=true
// BM_TeddyOverSgbm and BM_HandheldPlanesOverRectified give the ratios, alternated call by call.
// BM_FatteningTrimTeddy: the trim of the near side's overreach on teddy's map.
// BM_HandheldPlanesTwoWorkers: the plane sweep with two workers, the winner-take-all striped
// against one stripe.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include "algo/depth/depth_stage.h"
#include "algo/depth/fattening_trim.h"
#include "firmware/platform/worker_pool.h"
#include "tests/algo/depth/handheld.h"
#include "tests/algo/depth/middlebury.h"

#ifdef LB_HAVE_OPENCV
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#endif

namespace lb {
namespace {

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

const middlebury::Set* Teddy() {
  static middlebury::Set set;
  static bool loaded = false;
  if (!loaded) {
    const std::string dir = middlebury::DataDir();
    if (dir.empty() || !middlebury::Load(dir, "teddy", &set).ok()) return nullptr;
    loaded = true;
  }
  return &set;
}

// Teddy's 64 quarter-pixel labels (0..63 px over its 4 view steps between im2 and im6).
DepthConfig TeddyConfig(const middlebury::Set& set) {
  DepthConfig c;
  c.width = set.width;
  c.height = set.height;
  c.views = static_cast<int32_t>(set.views.size());
  c.reference = set.reference;
  c.labels = 64;
  c.disp_max_q8 = 63 * 64;
  return c;
}

// Teddy's depth stage, configured in memory of its own, and the set's views. Open is false, the
// benchmark skipped with the reason, when the data is absent or the stage refuses.
struct TeddyStage {
  const middlebury::Set* set = nullptr;
  DepthConfig config;
  std::vector<uint8_t> memory;
  DepthStage stage;
  std::vector<ConstImageU8> views;

  bool Open(benchmark::State& state, bool subpixel = false) {
    set = Teddy();
    if (!set) {
      state.SkipWithError("../shared/data/middlebury/teddy is absent");
      return false;
    }
    config = TeddyConfig(*set);
    config.subpixel = subpixel;
    const size_t bytes = DepthStage::RequiredBytes(config);
    memory.assign(bytes + Arena::kAlign, 0);
    Arena arena(Arena::AlignUp(memory.data()), bytes);
    if (!stage.Configure(config, arena).ok()) {
      state.SkipWithError("configure failed");
      return false;
    }
    views = set->Views();
    return true;
  }
};

void BM_DepthStageTeddy(benchmark::State& state) {
  TeddyStage t;
  // The refinement costs one more pass of the data term.
  if (!t.Open(state, state.range(0) != 0)) return;
  const middlebury::Set* set = t.set;
  const DepthConfig& c = t.config;
  DepthStage& stage = t.stage;
  const std::vector<ConstImageU8>& views = t.views;
  std::vector<uint16_t> disp(static_cast<size_t>(c.width) * c.height);
  const ImageU16 out = MakeView(disp.data(), c.width, c.height);
  for (auto _ : state) {
    if (!stage.Compute(views.data(), out).ok()) state.SkipWithError("compute failed");
    benchmark::DoNotOptimize(disp.data());
  }
  state.counters["labels"] = c.labels;
  state.counters["cycles"] = stage.stats().cycles;
  state.counters["arena_MiB"] = static_cast<double>(stage.stats().arena_bytes) / (1 << 20);
  state.counters["cut_px_per_move"] =
      static_cast<double>(stage.stats().cut_pixels) / (c.labels * stage.stats().cycles + 1e-9);
  state.counters["bad_pct"] = middlebury::BadPixelPercent(*set, out.AsConst());
}
// Arg 0: the label disparities (what refocus depth writes); 1: with the sub-label refinement.
BENCHMARK(BM_DepthStageTeddy)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->MinTime(3.0);

// The trim of the near side's overreach (fattening_trim.h) on teddy's map, as the pipeline runs
// it after the stage, on 1 and 2 workers; the stage's own time is BM_DepthStageTeddy/1.
void BM_FatteningTrimTeddy(benchmark::State& state) {
  TeddyStage t;
  if (!t.Open(state)) return;
  const DepthConfig& c = t.config;
  const std::vector<ConstImageU8>& views = t.views;
  std::vector<uint16_t> map(static_cast<size_t>(c.width) * c.height);
  if (!t.stage.Compute(views.data(), MakeView(map.data(), c.width, c.height)).ok()) {
    state.SkipWithError("the depth stage failed");
    return;
  }
  const int32_t workers = static_cast<int32_t>(state.range(0));
  const size_t trim_bytes = FatteningTrim::RequiredBytes(c.width, workers);
  std::vector<uint8_t> rows(trim_bytes + Arena::kAlign);
  Arena rows_arena(Arena::AlignUp(rows.data()), trim_bytes);
  FatteningTrim trim;
  trim.Carve(rows_arena, c.width, workers);
  WorkerPool pool;
  if (!pool.Start(workers).ok()) {
    state.SkipWithError("no workers");
    return;
  }
  trim.SetRunner(&pool);
  std::vector<uint16_t> disp(map.size());
  int64_t moved = 0;
  for (auto _ : state) {
    moved = trim.Run(views[static_cast<size_t>(c.reference)],
                     MakeView(map.data(), c.width, c.height).AsConst(),
                     MakeView(disp.data(), c.width, c.height), FatteningTrim::LabelStepQ8(c));
    benchmark::DoNotOptimize(disp.data());
  }
  state.counters["moved_pct"] =
      100.0 * static_cast<double>(moved) / static_cast<double>(map.size());
  state.counters["s_per_px"] = benchmark::Counter(
      static_cast<double>(map.size()),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_FatteningTrimTeddy)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);

// The 640x480, 7 views, 64 labels configuration the memory bound is stated for, on teddy's
// views cropped/tiled to that size (time only; there is no ground truth at this size).
void BM_DepthStage640x480(benchmark::State& state) {
  const middlebury::Set* set = Teddy();
  if (!set) {
    state.SkipWithError("../shared/data/middlebury/teddy is absent");
    return;
  }
  DepthConfig c;
  c.width = 640;
  c.height = 480;
  c.views = 7;
  c.reference = 3;
  c.labels = 64;
  c.disp_max_q8 = 63 * 64;
  std::vector<std::vector<uint8_t>> pixels(7, std::vector<uint8_t>(640 * 480 * 3));
  for (int32_t v = 0; v < 7; ++v) {
    for (int32_t y = 0; y < 480; ++y) {
      for (int32_t x = 0; x < 640; ++x) {
        // Mirror-tile the set's view v+1 so the scene stays continuous.
        const int32_t sx = (x / set->width) % 2 ? set->width - 1 - x % set->width : x % set->width;
        const int32_t sy =
            (y / set->height) % 2 ? set->height - 1 - y % set->height : y % set->height;
        for (int c3 = 0; c3 < 3; ++c3)
          pixels[v][(y * 640 + x) * 3 + c3] = set->views[v + 1][(sy * set->width + sx) * 3 + c3];
      }
    }
  }
  const size_t bytes = DepthStage::RequiredBytes(c);
  std::vector<uint8_t> memory(bytes + Arena::kAlign);
  void* const base = Arena::AlignUp(memory.data());
  Arena arena(base, bytes);
  DepthStage stage;
  if (!stage.Configure(c, arena).ok()) {
    state.SkipWithError("configure failed");
    return;
  }
  std::vector<ConstImageU8> views;
  for (const auto& p : pixels) views.push_back(MakeView(p.data(), 640, 480, 3));
  std::vector<uint16_t> disp(640 * 480);
  for (auto _ : state) {
    if (!stage.Compute(views.data(), MakeView(disp.data(), 640, 480)).ok())
      state.SkipWithError("compute failed");
  }
  state.counters["labels"] = c.labels;
  state.counters["cycles"] = stage.stats().cycles;
  state.counters["arena_MiB"] = static_cast<double>(bytes) / (1 << 20);
}
BENCHMARK(BM_DepthStage640x480)->Unit(benchmark::kMillisecond)->MinTime(3.0);

// The synthetic handheld burst below, made once (nullptr when it cannot be).
const motiontest::Burst* HandheldBurst() {
  static motiontest::Burst burst;
  static const bool made = motiontest::MakeBurst(motiontest::Handheld(1), 640, 480, 7, &burst);
  return made ? &burst : nullptr;
}

// A synthetic handheld burst at 640x480, 7 views, with its true poses and 33 labels (as
// depth_planes_accuracy_test's speed case): range(0) 1 for the plane sweep, 0 for the rectified
// shifts over the same labels.
void BM_HandheldDepth640x480(benchmark::State& state) {
  const motiontest::Burst* made = HandheldBurst();
  if (made == nullptr) return state.SkipWithError("no synthetic burst");
  const motiontest::Burst& burst = *made;
  const handheld::Labels l = handheld::HandheldLabels(burst, 0.1);
  DepthConfig c = l.config;
  const bool planes = state.range(0) != 0;
  c.geometry = planes ? ViewGeometry::kKnownPoses : ViewGeometry::kRectified;
  handheld::Stage s;
  if (!s.Configure(c).ok()) return state.SkipWithError("configure failed");
  const std::vector<PlaneHomography> homographies = handheld::Planes(burst, l);
  for (auto _ : state) {
    if (planes && !s.depth.SetPlanes(homographies.data()).ok()) state.SkipWithError("planes");
    if (!s.Compute(burst.views.data()).ok()) state.SkipWithError("compute failed");
  }
  state.counters["labels"] = c.labels;
}
BENCHMARK(BM_HandheldDepth640x480)
    ->ArgName("planes")
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);

// The plane sweep's ratio to the rectified shifts on that burst, taken so that a busy machine
// slows both alike: one compute of each by turns, each timed on its own; the counters are each
// side's median and the median of the per-turn ratios.
void BM_HandheldPlanesOverRectified(benchmark::State& state) {
  const motiontest::Burst* made = HandheldBurst();
  if (made == nullptr) return state.SkipWithError("no synthetic burst");
  const motiontest::Burst& burst = *made;
  const handheld::Labels l = handheld::HandheldLabels(burst, 0.1);
  DepthConfig c = l.config;
  handheld::Stage sweep, shifts;
  c.geometry = ViewGeometry::kKnownPoses;
  if (!sweep.Configure(c).ok()) return state.SkipWithError("configure failed");
  c.geometry = ViewGeometry::kRectified;
  if (!shifts.Configure(c).ok()) return state.SkipWithError("configure failed");
  const std::vector<PlaneHomography> homographies = handheld::Planes(burst, l);
  std::vector<double> planes_ms, rect_ms, ratios;
  using Clock = std::chrono::steady_clock;
  for (auto _ : state) {
    const Clock::time_point t0 = Clock::now();
    if (!sweep.depth.SetPlanes(homographies.data()).ok()) state.SkipWithError("planes");
    if (!sweep.Compute(burst.views.data()).ok()) state.SkipWithError("compute failed");
    const Clock::time_point t1 = Clock::now();
    if (!shifts.Compute(burst.views.data()).ok()) state.SkipWithError("compute failed");
    const Clock::time_point t2 = Clock::now();
    planes_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    rect_ms.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
    ratios.push_back(planes_ms.back() / rect_ms.back());
  }
  state.counters["planes_ms"] = Median(planes_ms);
  state.counters["rectified_ms"] = Median(rect_ms);
  state.counters["ratio"] = Median(ratios);
}
BENCHMARK(BM_HandheldPlanesOverRectified)->Unit(benchmark::kMillisecond)->MinTime(6.0);

// The plane sweep on that burst with two workers (the board's pool), the winner-take-all in one
// stripe of block rows per worker against all of it on one, by turns as above: wall times, the
// counters each side's median and the median of the per-turn ratios (one stripe / striped).
void BM_HandheldPlanesTwoWorkers(benchmark::State& state) {
  const motiontest::Burst* made = HandheldBurst();
  if (made == nullptr) return state.SkipWithError("no synthetic burst");
  const motiontest::Burst& burst = *made;
  const handheld::Labels l = handheld::HandheldLabels(burst, 0.1);
  DepthConfig c = l.config;
  c.geometry = ViewGeometry::kKnownPoses;
  c.workers = 2;
  WorkerPool pool;
  if (!pool.Start(c.workers).ok()) return state.SkipWithError("no worker threads");
  handheld::Stage striped, one;
  if (!striped.Configure(c).ok() || !one.Configure(c).ok()) {
    return state.SkipWithError("configure failed");
  }
  striped.depth.SetRunner(&pool);
  one.depth.SetRunner(&pool);
  DepthStageProbe::StripedWinners(one.depth, false);
  const std::vector<PlaneHomography> homographies = handheld::Planes(burst, l);
  std::vector<double> striped_ms, one_ms, ratios;
  using Clock = std::chrono::steady_clock;
  for (auto _ : state) {
    const Clock::time_point t0 = Clock::now();
    if (!striped.depth.SetPlanes(homographies.data()).ok()) state.SkipWithError("planes");
    if (!striped.Compute(burst.views.data()).ok()) state.SkipWithError("compute failed");
    const Clock::time_point t1 = Clock::now();
    if (!one.depth.SetPlanes(homographies.data()).ok()) state.SkipWithError("planes");
    if (!one.Compute(burst.views.data()).ok()) state.SkipWithError("compute failed");
    const Clock::time_point t2 = Clock::now();
    striped_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    one_ms.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
    ratios.push_back(one_ms.back() / striped_ms.back());
  }
  state.counters["striped_ms"] = Median(striped_ms);
  state.counters["one_stripe_ms"] = Median(one_ms);
  state.counters["ratio"] = Median(ratios);
}
BENCHMARK(BM_HandheldPlanesTwoWorkers)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(6.0);

#ifdef LB_HAVE_OPENCV
// Dense output (no uniqueness, left-right or speckle rejection), so bad_pct scores every pixel
// as ours does; P1/P2 are OpenCV's usual 8/32 x channels x block area.
cv::Ptr<cv::StereoSGBM> TeddySgbm() {
  const int block = 5;
  return cv::StereoSGBM::create(0, 64, block, 8 * 3 * block * block, 32 * 3 * block * block, -1, 63,
                                0, 0, 0, cv::StereoSGBM::MODE_SGBM);
}

// Two-view SGBM on im2/im6 (disparities 0..63 px over 4 view steps, the same depth range as the
// 64 quarter-pixel labels above), single thread.
void BM_OpenCvSgbmTeddy(benchmark::State& state) {
  const middlebury::Set* set = Teddy();
  if (!set) {
    state.SkipWithError("../shared/data/middlebury/teddy is absent");
    return;
  }
  cv::setNumThreads(1);
  // OpenCV wants BGR; the cost is colour-order independent, so the RGB bytes are used as they are.
  const cv::Mat left(set->height, set->width, CV_8UC3, const_cast<uint8_t*>(set->views[2].data()));
  const cv::Mat right(set->height, set->width, CV_8UC3, const_cast<uint8_t*>(set->views[6].data()));
  const cv::Ptr<cv::StereoSGBM> sgbm = TeddySgbm();
  cv::Mat disp;
  for (auto _ : state) {
    sgbm->compute(left, right, disp);
    benchmark::DoNotOptimize(disp.data);
  }
  // SGBM gives 1/16 px over im2-im6; the score wants px per view step in Q8.
  std::vector<uint16_t> q8(static_cast<size_t>(set->width) * set->height);
  for (int32_t y = 0; y < set->height; ++y)
    for (int32_t x = 0; x < set->width; ++x) {
      const int16_t d = disp.at<int16_t>(y, x);
      q8[y * set->width + x] = static_cast<uint16_t>(d < 0 ? 0 : d * 4);  // /16 px, /4 steps, *256
    }
  state.counters["labels"] = 64;
  state.counters["bad_pct"] =
      middlebury::BadPixelPercent(*set, MakeView(q8.data(), set->width, set->height).AsConst());
}
BENCHMARK(BM_OpenCvSgbmTeddy)->Unit(benchmark::kMillisecond)->MinTime(3.0);

// The ratio the bound is stated for, taken so that a busy machine slows both sides alike: one
// depth compute (one thread, with the sub-label fit the renderer's pipeline runs: a little more
// than the label disparities alone, BM_DepthStageTeddy/1 against /0) and one SGBM compute by
// turns, each timed on its own; the counters are each side's median and the median of the
// per-turn ratios.
void BM_TeddyOverSgbm(benchmark::State& state) {
  TeddyStage t;
  if (!t.Open(state)) return;
  const middlebury::Set* set = t.set;
  const DepthConfig& c = t.config;
  DepthStage& stage = t.stage;
  const std::vector<ConstImageU8>& views = t.views;
  std::vector<uint16_t> disp(static_cast<size_t>(c.width) * c.height);
  const ImageU16 out = MakeView(disp.data(), c.width, c.height);
  cv::setNumThreads(1);
  const cv::Mat left(set->height, set->width, CV_8UC3, const_cast<uint8_t*>(set->views[2].data()));
  const cv::Mat right(set->height, set->width, CV_8UC3, const_cast<uint8_t*>(set->views[6].data()));
  const cv::Ptr<cv::StereoSGBM> sgbm = TeddySgbm();
  cv::Mat sgbm_disp;
  std::vector<double> ours, theirs, ratios;
  using Clock = std::chrono::steady_clock;
  for (auto _ : state) {
    const Clock::time_point t0 = Clock::now();
    if (!stage.Compute(views.data(), out).ok()) state.SkipWithError("compute failed");
    const Clock::time_point t1 = Clock::now();
    sgbm->compute(left, right, sgbm_disp);
    const Clock::time_point t2 = Clock::now();
    benchmark::DoNotOptimize(disp.data());
    benchmark::DoNotOptimize(sgbm_disp.data);
    ours.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    theirs.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
    ratios.push_back(ours.back() / theirs.back());
  }
  state.counters["depth_ms"] = Median(ours);
  state.counters["sgbm_ms"] = Median(theirs);
  state.counters["ratio"] = Median(ratios);
}
BENCHMARK(BM_TeddyOverSgbm)->Unit(benchmark::kMillisecond)->MinTime(6.0);
#endif

}  // namespace
}  // namespace lb

BENCHMARK_MAIN();
