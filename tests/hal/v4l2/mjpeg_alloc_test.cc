// Nothing is allocated after Configure on the MJPEG path, libjpeg included. The repository's
// alloc_counter wraps malloc at link time, which cannot see the calls libjpeg makes inside its
// shared library; this binary counts every allocation of the process instead. Under ASan through
// its malloc hooks; otherwise by defining malloc and its kin here, which the dynamic linker then
// binds every library's calls to, forwarding to glibc's own allocator. The first test proves the
// counter sees an allocation made inside libjpeg, so a decoder that let libjpeg's default memory
// manager run would fail the others.
#include <gtest/gtest.h>

#include <atomic>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <vector>

#include "hal/v4l2/mjpeg_decoder.h"
#include "hal/v4l2/v4l2_sensor.h"
#include "tests/hal/v4l2/fake_v4l2.h"
#include "tests/hal/v4l2/jpeg_frames.h"

namespace {
std::atomic<size_t> g_allocations{0};
void Count() { g_allocations.fetch_add(1, std::memory_order_relaxed); }
}  // namespace

#if defined(__SANITIZE_ADDRESS__)
extern "C" int __sanitizer_install_malloc_and_free_hooks(void (*)(const volatile void*, size_t),
                                                         void (*)(const volatile void*));
namespace {
void OnMalloc(const volatile void*, size_t) { Count(); }
void OnFree(const volatile void*) {}
// Both hooks are required: ASan refuses the pair with either missing.
const bool g_hooked = __sanitizer_install_malloc_and_free_hooks(OnMalloc, OnFree) != 0;
}  // namespace
#else
extern "C" {
void* __libc_malloc(size_t size);
void* __libc_calloc(size_t n, size_t size);
void* __libc_realloc(void* p, size_t size);
void* __libc_memalign(size_t align, size_t size);
void __libc_free(void* p);

void* malloc(size_t size) noexcept {
  Count();
  return __libc_malloc(size);
}
void* calloc(size_t n, size_t size) noexcept {
  Count();
  return __libc_calloc(n, size);
}
void* realloc(void* p, size_t size) noexcept {
  Count();
  return __libc_realloc(p, size);
}
void* memalign(size_t align, size_t size) noexcept {
  Count();
  return __libc_memalign(align, size);
}
void* aligned_alloc(size_t align, size_t size) noexcept {
  Count();
  return __libc_memalign(align, size);
}
int posix_memalign(void** out, size_t align, size_t size) noexcept {
  Count();
  void* p = __libc_memalign(align, size);
  if (p == nullptr) return 12;  // ENOMEM
  *out = p;
  return 0;
}
void free(void* p) noexcept { __libc_free(p); }
}
namespace {
const bool g_hooked = true;
}  // namespace
#endif

namespace lb {
namespace {

size_t Allocations() { return g_allocations.load(); }

// Checks strip order and sums the pixels, in fixed memory.
class CountingSink : public FrameSink {
 public:
  int frames = 0, ended = 0, bad = 0;
  uint64_t sum = 0;
  Status BeginFrame(const FrameInfo& info) override {
    ++frames;
    height_ = info.height;
    width_ = info.width;
    next_ = 0;
    return Status::Ok();
  }
  Status Rows(const FrameRows& rows) override {
    if (rows.y0 != next_) ++bad;
    for (int32_t y = 0; y < rows.height; ++y) {
      for (int32_t x = 0; x < width_ * 3; ++x) sum += rows.planes[0][rows.strides[0] * y + x];
    }
    next_ = rows.y0 + rows.height;
    return Status::Ok();
  }
  Status EndFrame() override {
    if (next_ != height_) ++bad;
    ++ended;
    return Status::Ok();
  }

 private:
  int32_t width_ = 0, height_ = 0, next_ = 0;
};

struct FixedLog {
  char last[512] = {};
  int lines = 0;
  static void Write(void* context, const char* line) {
    auto* log = static_cast<FixedLog*>(context);
    snprintf(log->last, sizeof(log->last), "%s", line);
    ++log->lines;
  }
};

TEST(MjpegAllocationTest, CounterSeesMallocsMadeInsideLibjpeg) {
  ASSERT_TRUE(g_hooked);
  const std::vector<uint8_t> jpeg = jpegtest::Encode(jpegtest::TestPicture(64, 48, 1), {});
  const size_t before = Allocations();
  const jpegtest::Rgb decoded = jpegtest::DecodeWithLibjpeg(jpeg);  // libjpeg's own manager
  const size_t during = Allocations() - before;
  ASSERT_EQ(decoded.width, 64);
  // The picture's vector is one; libjpeg's pools are the rest.
  EXPECT_GE(during, 3u);
}

TEST(MjpegAllocationTest, DecoderAllocatesNothingAfterConfigure) {
  std::vector<std::vector<uint8_t>> frames;
  for (jpegtest::Sampling sampling :
       {jpegtest::Sampling::k422, jpegtest::Sampling::k420, jpegtest::Sampling::k444}) {
    jpegtest::EncodeOptions options;
    options.sampling = sampling;
    frames.push_back(jpegtest::Encode(jpegtest::TestPicture(320, 240, 2), options));
    frames.push_back(jpegtest::WithoutHuffmanTables(frames.back()));
  }
  frames.push_back(std::vector<uint8_t>(frames[0].begin(), frames[0].begin() + 900));  // corrupt
  MjpegDecoder decoder;
  ASSERT_TRUE(decoder.Configure(320, 240).ok());
  CountingSink sink;
  int failures = 0;
  const size_t before = Allocations();
  for (int round = 0; round < 3; ++round) {
    for (const std::vector<uint8_t>& f : frames) {
      bool began = false;
      failures += !decoder.Decode(f.data(), f.size(), FrameInfo(), sink, &began).ok();
    }
  }
  const size_t during = Allocations() - before;
  EXPECT_EQ(during, 0u);
  EXPECT_EQ(failures, 3);
  EXPECT_EQ(sink.ended, 18);
  EXPECT_EQ(sink.bad, 0);
  EXPECT_GT(decoder.arena_allocations(), 100u);  // libjpeg's requests went to the arena
}

TEST(MjpegAllocationTest, MjpegBurstsAllocateNothingAfterConfigure) {
  FakeV4l2 dev;
  dev.formats = {V4L2_PIX_FMT_MJPEG};
  dev.width = 640;
  dev.height = 480;
  for (uint32_t i = 0; i < 6; ++i) {
    dev.jpeg_frames.push_back(
        jpegtest::WithoutHuffmanTables(jpegtest::Encode(jpegtest::TestPicture(640, 480, i), {})));
  }
  dev.jpeg_frames[2].resize(dev.jpeg_frames[2].size() / 2);  // one skipped, with a log line
  FixedLog log;
  V4l2Options options;
  options.buffers = 3;
  options.log = FixedLog::Write;
  options.log_context = &log;
  V4l2Sensor sensor(options, &dev);
  SensorMode mode;
  SensorConfig config;
  config.frames = 5;
  config.timeout_ms = 50;
  ASSERT_TRUE(sensor.Configure(config, &mode).ok());
  ASSERT_EQ(sensor.fourcc(), V4L2_PIX_FMT_MJPEG);
  CountingSink first, second;
  const size_t before = Allocations();
  const Status a = sensor.CaptureBurst(first);
  const Status b = sensor.CaptureBurst(second);
  const size_t during = Allocations() - before;
  ASSERT_TRUE(a.ok()) << a.message();
  ASSERT_TRUE(b.ok()) << b.message();
  EXPECT_EQ(during, 0u);
  EXPECT_EQ(first.ended, 5);
  EXPECT_EQ(second.ended, 5);
  EXPECT_EQ(first.sum, second.sum);
  EXPECT_EQ(log.lines, 2);
  EXPECT_NE(strstr(log.last, "truncated"), nullptr) << log.last;
  EXPECT_GT(sensor.decoder().arena_allocations(), 0u);
}

}  // namespace
}  // namespace lb
