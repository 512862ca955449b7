// One MJPEG frame decoded into RGB8 strips by the V4L2 sensor's decoder, as a USB camera sends it
// (quality 85, no Huffman tables), at 1280x720 and 1920x1080, in 4:2:2 (what UVC cameras send)
// and 4:2:0. One thread; the figures are in docs/cameras.md.
//   build/host/tests/bench/hal/mjpeg_bench
#include <benchmark/benchmark.h>

#include <vector>

#include "hal/v4l2/mjpeg_decoder.h"
#include "tests/hal/v4l2/jpeg_frames.h"

namespace lb {
namespace {

// Reads one byte a row, so the strips are really produced.
class TouchingSink : public FrameSink {
 public:
  uint64_t sum = 0;
  Status BeginFrame(const FrameInfo&) override { return Status::Ok(); }
  Status Rows(const FrameRows& rows) override {
    for (int32_t y = 0; y < rows.height; ++y) sum += rows.planes[0][rows.strides[0] * y];
    return Status::Ok();
  }
  Status EndFrame() override { return Status::Ok(); }
};

void BM_MjpegDecode(benchmark::State& state) {
  const int32_t width = static_cast<int32_t>(state.range(0));
  const int32_t height = static_cast<int32_t>(state.range(1));
  jpegtest::EncodeOptions options;
  options.quality = 85;
  options.sampling = state.range(2) == 422 ? jpegtest::Sampling::k422 : jpegtest::Sampling::k420;
  const std::vector<uint8_t> frame = jpegtest::WithoutHuffmanTables(
      jpegtest::Encode(jpegtest::TestPicture(width, height, 1), options));
  MjpegDecoder decoder;
  if (frame.empty() || !decoder.Configure(width, height).ok()) {
    state.SkipWithError("setup");
    return;
  }
  TouchingSink sink;
  for (auto _ : state) {
    bool began = false;
    const Status s = decoder.Decode(frame.data(), frame.size(), FrameInfo(), sink, &began);
    if (!s.ok()) state.SkipWithError(s.message());
  }
  benchmark::DoNotOptimize(sink.sum);
  state.counters["frame_KB"] = static_cast<double>(frame.size()) / 1024;
  state.counters["arena_KB"] = static_cast<double>(decoder.arena_bytes()) / 1024;
  state.counters["Mpx/s"] = benchmark::Counter(static_cast<double>(width) * height / 1e6,
                                               benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_MjpegDecode)
    ->Args({1280, 720, 422})
    ->Args({1920, 1080, 422})
    ->Args({1280, 720, 420})
    ->Args({1920, 1080, 420})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

}  // namespace
}  // namespace lb

BENCHMARK_MAIN();
