// Writing a 12 MP photo: the rendered strips encoded as they come, the all-in-focus
// original encoded whole (GImage), the refocusable XMP built (the depth map as a 16-bit PNG,
// base64, extended-XMP segments), with or without Dynamic Depth beside GDepth (its Device
// element and its items, the same depth PNG and original again, raw), with or without the
// map's confidence (an 8-bit PNG in both formats), and the finished file
// written, fsynced and renamed. The pictures are the synthetic burst's own reference frame and
// depth (computed once, before timing), so the encoders see camera-like content.
//   build/host/tests/bench/app/writing_bench --benchmark_repetitions=5
#include <benchmark/benchmark.h>

#include <unistd.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "algo/pipeline/pipeline.h"
#include "firmware/app/refocusable.h"
#include "firmware/codecs/jpeg_writer.h"
#include "firmware/storage/atomic_file.h"
#include "sim/synthetic/synthetic_sensor.h"

namespace lb {
namespace {

constexpr int32_t kWidth = 4056, kHeight = 3040;

// The pipeline after depth on the synthetic 12 MP burst: its reference and disparity.
Pipeline* Burst() {
  static Pipeline* pipeline = [] {
    SceneParams params;
    params.geometry = ViewGeometry::kHandheld;
    SyntheticSensor sensor(params);
    SensorConfig sc;
    sc.width = kWidth;
    sc.height = kHeight;
    SensorMode mode;
    auto* p = new Pipeline;
    PipelineConfig c;
    c.width = kWidth;
    c.height = kHeight;
    c.frames = 5;
    c.reference = 2;
    c.labels = 32;
    c.geometry = ViewGeometry::kAuto;
    size_t bytes = 0;
    Status s = sensor.Configure(sc, &mode);
    if (s.ok()) s = Pipeline::RequiredBytes(c, &bytes);
    void* arena = s.ok() ? aligned_alloc(Arena::kAlign, Arena::RoundUp(bytes)) : nullptr;
    if (s.ok()) s = p->Configure(c, arena, bytes);
    if (s.ok()) s = sensor.CaptureBurst(*p);
    if (s.ok()) s = p->ComputeDepth();
    if (!s.ok()) fprintf(stderr, "writing_bench: %s\n", s.message());
    return p;
  }();
  return pipeline;
}

// The reference's rows as the render stage hands them over: 16 luma rows a strip.
Status WriteReferenceStrips(const ConstPlanarU8& ref, JpegWriter* writer) {
  for (int32_t y0 = 0; y0 < kHeight; y0 += 16) {
    ConstPlanarU8 strip = ref;
    const int32_t rows = kHeight - y0 < 16 ? kHeight - y0 : 16;
    for (int p = 0; p < 3; ++p) {
      const int32_t y = p == 0 ? y0 : y0 / 2;
      strip.planes[p].data = ref.planes[p].Row(y);
      strip.planes[p].height = p == 0 ? rows : (rows + 1) / 2;
    }
    LB_RETURN_IF_ERROR(writer->WriteStrip(strip, rows));
  }
  return Status::Ok();
}

void BM_PhotoFromStrips(benchmark::State& state) {
  const ConstPlanarU8 ref = Burst()->reference();
  std::vector<uint8_t> out;
  for (auto _ : state) {
    JpegWriter writer;
    Status s = writer.BeginMemory(&out, kWidth, kHeight, 92, JpegMetadata{});
    if (s.ok()) s = WriteReferenceStrips(ref, &writer);
    if (s.ok()) s = writer.Finish();
    if (!s.ok()) state.SkipWithError(s.message());
  }
  state.counters["MB"] = static_cast<double>(out.size()) / 1e6;
}
BENCHMARK(BM_PhotoFromStrips)->Unit(benchmark::kMillisecond)->MinTime(2.0);

void BM_OriginalWhole(benchmark::State& state) {
  const ConstPlanarU8 ref = Burst()->reference();
  std::vector<uint8_t> jpeg;
  for (auto _ : state) {
    const Status s = EncodeYCbCr420(ref, 92, &jpeg);
    if (!s.ok()) state.SkipWithError(s.message());
  }
  state.counters["MB"] = static_cast<double>(jpeg.size()) / 1e6;
}
BENCHMARK(BM_OriginalWhole)->Unit(benchmark::kMillisecond)->MinTime(2.0);

void BM_RefocusableXmp(benchmark::State& state) {
  Pipeline& p = *Burst();
  std::vector<uint8_t> original;
  if (!EncodeYCbCr420(p.reference(), 92, &original).ok()) state.SkipWithError("original");
  FocusUsed focus;
  focus.focus_disp_q8 = (p.map_min_q8() + p.map_max_q8()) / 2;
  const bool dynamic_depth = state.range(0) != 0;
  // The map's confidence (GDepth:Confidence, and Dynamic Depth's item), as every photo carries.
  const ConstImageU8 confidence = state.range(1) != 0 ? p.map_confidence() : ConstImageU8();
  size_t bytes = 0, items = 0;
  std::vector<uint8_t> after_eoi;
  for (auto _ : state) {
    std::vector<JpegSegment> segments;
    DynamicDepthTrailer dd;
    Status s =
        BuildRefocusableSegments(p.map_q8(), {p.map_min_q8(), p.map_max_q8()}, original, focus,
                                 kWidth, &segments, dynamic_depth ? &dd : nullptr, confidence);
    // The items as the job writes them after the image, here into memory.
    after_eoi.clear();
    if (s.ok() && dynamic_depth) {
      s = WriteDynamicDepthItems(dd.xmp, dd.extras, [&after_eoi](const uint8_t* d, size_t n) {
        after_eoi.insert(after_eoi.end(), d, d + n);
        return Status::Ok();
      });
    }
    if (!s.ok()) state.SkipWithError(s.message());
    bytes = after_eoi.size();
    items = after_eoi.size();
    for (const JpegSegment& seg : segments) bytes += seg.payload.size();
  }
  state.counters["MB"] = static_cast<double>(bytes) / 1e6;
  state.counters["items_MB"] = static_cast<double>(items) / 1e6;
}
// Args (0, 0): GDepth only; (1, 0): Dynamic Depth beside it; (1, 1): both with the confidence
// map, as the product writes.
BENCHMARK(BM_RefocusableXmp)
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);

// The finished photo's bytes through the storage rule: a hidden temporary, fsync, rename and
// the folder's fsync, on TMPDIR (a card on the board).
void BM_Commit(benchmark::State& state) {
  const std::vector<uint8_t> bytes(static_cast<size_t>(state.range(0)) << 20, 0x5a);
  const char* dir = getenv("TMPDIR");
  const std::string path = std::string(dir != nullptr ? dir : "/tmp") + "/writing_bench_" +
                           std::to_string(getpid()) + ".jpg";
  for (auto _ : state) {
    AtomicFile file;
    Status s = file.Open(path.c_str());
    if (s.ok()) s = file.Write(bytes.data(), bytes.size());
    if (s.ok()) s = file.Commit();
    if (!s.ok()) state.SkipWithError(s.message());
  }
  unlink(path.c_str());
}
// Arg: MiB. 4 and 6: the synthetic 12 MP photo without and with Dynamic Depth's items.
BENCHMARK(BM_Commit)
    ->Arg(4)
    ->Arg(6)
    ->Arg(12)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);

}  // namespace
}  // namespace lb

BENCHMARK_MAIN();
