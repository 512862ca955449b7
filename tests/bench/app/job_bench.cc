// The photo a board takes, end to end, from frames already in memory (as a sensor hands them
// over) to the committed refocusable JPEG: 12 MP (4056x3040), 5 frames, the board's defaults
// (refocusd: auto geometry, 32 labels), at 1, 2 and 4 threads in one process (4: a 4-core
// board's default; on a 2-core host, the pool with more threads than cores), with the stage split
// (capture = ingest and downscale, depth = motion stage and labeling, render = render + JPEG and
// XMP, written and fsynced; xmp = building the refocusable XMP within it, on a side thread when
// there are 2 threads). The synthetic scene is rendered once, before timing.
//   build/host/tests/bench/app/job_bench --benchmark_repetitions=5
//   (LB_BENCH_SIZE=WxH for another size)
#include <benchmark/benchmark.h>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "firmware/app/job.h"
#include "firmware/daemon/config.h"
#include "sim/synthetic/synthetic_sensor.h"

namespace lb {
namespace {

// A burst recorded once from another sensor and handed over again at every capture, in the
// same strips and format.
class ReplaySensor final : public Sensor, private FrameSink {
 public:
  Status Record(Sensor& source, const SensorConfig& config) {
    LB_RETURN_IF_ERROR(source.Configure(config, &mode_));
    frames_.assign(static_cast<size_t>(mode_.frames), {});
    return source.CaptureBurst(*this);
  }
  const char* name() const override { return "replay"; }
  Status Configure(const SensorConfig&, SensorMode* mode) override {
    *mode = mode_;
    return Status::Ok();
  }
  Status CaptureBurst(FrameSink& sink) override {
    for (const Frame& f : frames_) {
      LB_RETURN_IF_ERROR(sink.BeginFrame(f.info));
      const ptrdiff_t stride = static_cast<ptrdiff_t>(f.info.width) * BytesPerPixel(f.info.format);
      for (int32_t y0 = 0; y0 < f.info.height; y0 += kStripRows) {
        FrameRows rows;
        rows.y0 = y0;
        rows.height = f.info.height - y0 < kStripRows ? f.info.height - y0 : kStripRows;
        rows.planes[0] = f.pixels.data() + y0 * stride;
        rows.strides[0] = stride;
        LB_RETURN_IF_ERROR(sink.Rows(rows));
      }
      LB_RETURN_IF_ERROR(sink.EndFrame());
    }
    return Status::Ok();
  }

 private:
  static constexpr int32_t kStripRows = 16;
  struct Frame {
    FrameInfo info;
    std::vector<uint8_t> pixels;
  };
  Status BeginFrame(const FrameInfo& info) override {
    if (BytesPerPixel(info.format) == 0) {
      return Status(Code::kUnsupported, "replay: %s frames", PixelFormatName(info.format));
    }
    current_ = &frames_[static_cast<size_t>(info.index)];
    current_->info = info;
    current_->pixels.resize(static_cast<size_t>(info.width) * info.height *
                            BytesPerPixel(info.format));
    return Status::Ok();
  }
  Status Rows(const FrameRows& rows) override {
    const size_t row_bytes =
        static_cast<size_t>(current_->info.width) * BytesPerPixel(current_->info.format);
    for (int32_t y = 0; y < rows.height; ++y) {
      std::copy_n(rows.planes[0] + y * rows.strides[0], row_bytes,
                  current_->pixels.data() + (rows.y0 + y) * row_bytes);
    }
    return Status::Ok();
  }
  Status EndFrame() override { return Status::Ok(); }

  SensorMode mode_;
  std::vector<Frame> frames_;
  Frame* current_ = nullptr;
};

SensorConfig BenchSize() {
  SensorConfig c;
  c.width = 4056;
  c.height = 3040;
  if (const char* size = getenv("LB_BENCH_SIZE")) {
    if (sscanf(size, "%dx%d", &c.width, &c.height) != 2) c.width = c.height = 0;
  }
  c.frames = 5;
  return c;
}

ReplaySensor* RecordedBurst() {
  static ReplaySensor* replay = [] {
    SceneParams params;
    params.geometry = ViewGeometry::kHandheld;
    SyntheticSensor synthetic(params);
    auto* r = new ReplaySensor;
    const Status s = r->Record(synthetic, BenchSize());
    if (!s.ok()) fprintf(stderr, "job_bench: %s\n", s.message());
    return r;
  }();
  return replay;
}

void BM_Photo(benchmark::State& state) {
  JobOptions options = DaemonJobDefaults();
  options.sensor = BenchSize();
  options.threads = static_cast<int32_t>(state.range(0));
  Job job;
  Status s = job.Configure(RecordedBurst(), options);
  if (!s.ok()) {
    state.SkipWithError(s.message());
    return;
  }
  const char* dir = getenv("TMPDIR");
  const std::string out = std::string(dir != nullptr ? dir : "/tmp") + "/job_bench_" +
                          std::to_string(getpid()) + ".jpg";
  double capture = 0, motion = 0, depth = 0, render = 0, metadata = 0, wait = 0;
  for (auto _ : state) {
    JobReport report;
    s = job.Run(out.c_str(), &report);
    if (!s.ok() || !report.warning.ok()) {
      state.SkipWithError(s.ok() ? report.warning.message() : s.message());
      break;
    }
    capture += report.capture_s;
    motion += report.motion_s;
    depth += report.depth_s;
    render += report.render_s;
    metadata += report.metadata_s;
    wait += report.metadata_wait_s;
  }
  unlink(out.c_str());
  const double n = static_cast<double>(state.iterations());
  state.counters["capture_ms"] = 1000 * capture / n;
  state.counters["depth_ms"] = 1000 * depth / n;
  state.counters["motion_ms"] = 1000 * motion / n;  // within depth_ms: before the labeling
  state.counters["render_jpeg_ms"] = 1000 * render / n;
  // Within render_jpeg_ms: the XMP's build (beside the render with 2 threads) and the wait for it.
  state.counters["xmp_ms"] = 1000 * metadata / n;
  state.counters["xmp_wait_ms"] = 1000 * wait / n;
  state.counters["threads"] = static_cast<double>(job.pipeline().config().workers);
}
BENCHMARK(BM_Photo)
    ->Arg(1)
    ->Arg(2)
    ->Arg(4)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);

}  // namespace
}  // namespace lb

BENCHMARK_MAIN();
