// A caller of the page's renderer whose request the render thread has taken, while the render
// outlasts the wait limit (the camera holds it): the caller must sleep until its render is done,
// not poll a deadline that has already passed.
#include <gtest/gtest.h>
#include <pthread.h>
#include <time.h>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "firmware/app/job.h"
#include "firmware/platform/log.h"
#include "firmware/web/engine_backend.h"
#include "sim/synthetic/synthetic_sensor.h"
#include "tests/firmware/codecs/jpeg_test_util.h"

namespace lb {
namespace {

class Sink final : public ByteSink {
 public:
  bool Append(const uint8_t* data, size_t size) override {
    bytes.insert(bytes.end(), data, data + size);
    return true;
  }
  std::vector<uint8_t> bytes;
};

class NoLog final : public LogSink {
 public:
  void Write(LogLevel, const char*) override {}
};

double CpuSeconds(clockid_t clock) {
  timespec t{};
  clock_gettime(clock, &t);
  return static_cast<double>(t.tv_sec) + t.tv_nsec * 1e-9;
}

TEST(EngineBackendWaitTest, ACallerPastTheWaitLimitSleepsUntilItsRenderIsDone) {
  test::ScratchDir dir;
  const std::string photo = dir.Path("IMG_1.jpg");
  {
    SyntheticSensor sensor;
    Job job;
    JobOptions o;
    o.sensor.width = 320;
    o.sensor.height = 240;
    o.pipeline.labels = 16;
    o.threads = 1;
    ASSERT_TRUE(job.Configure(&sensor, o).ok());
    ASSERT_TRUE(job.Run(photo.c_str(), nullptr).ok());
  }
  NoLog quiet;
  Log log(&quiet, LogLevel::kDebug);
  std::atomic<bool> camera_busy{true};  // holds the render once taken: a render that lasts
  EngineBackend backend(640, 480, 1, &log, &camera_busy, /*wait_limit_ms=*/100);
  ASSERT_TRUE(backend.Ready().ok());

  Status result(Code::kInternal, "not run");
  Sink jpeg;
  RefocusParams tap;
  tap.f_number = 2.0f;
  std::thread caller([&] { result = backend.Render(photo.c_str(), tap, true, &jpeg); });
  clockid_t caller_cpu;
  ASSERT_EQ(pthread_getcpuclockid(caller.native_handle(), &caller_cpu), 0);
  for (int i = 0; i < 2500 && (backend.loads() == 0 || backend.queued() != 0); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_EQ(backend.loads(), 1) << "the render thread took the request";
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // well past the 100 ms limit

  const auto wall0 = std::chrono::steady_clock::now();
  const double cpu0 = CpuSeconds(caller_cpu);
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));
  const double cpu = CpuSeconds(caller_cpu) - cpu0;
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  camera_busy = false;
  caller.join();
  EXPECT_TRUE(result.ok()) << result.message();
  EXPECT_FALSE(jpeg.bytes.empty());
  EXPECT_LT(cpu, 0.05 * wall) << "the waiting caller used " << cpu << " s of CPU in " << wall
                              << " s";
}

}  // namespace
}  // namespace lb
