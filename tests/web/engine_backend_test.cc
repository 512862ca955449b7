// The web page's renderer as the server calls it: a synthetic refocusable photo described,
// previewed, rendered and saved beside the original; repeated taps served from the loaded photo;
// the queue bounded (a newer preview supersedes a waiting one, a full queue says busy) while the
// camera holds the render thread; that thread at low priority.
#include "firmware/web/engine_backend.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "firmware/app/job.h"
#include "firmware/platform/log.h"
#include "sim/synthetic/synthetic_sensor.h"
#include "tests/firmware/codecs/jpeg_test_util.h"

namespace lb {
namespace {

using test::DecodeYcc;
using test::ReadFile;
using test::ScratchDir;

class VectorSink final : public ByteSink {
 public:
  explicit VectorSink(size_t bound = size_t{64} << 20) : bound_(bound) {}
  bool Append(const uint8_t* data, size_t size) override {
    if (bytes.size() + size > bound_) return false;
    bytes.insert(bytes.end(), data, data + size);
    return true;
  }
  std::vector<uint8_t> bytes;

 private:
  size_t bound_;
};

class QuietSink final : public LogSink {
 public:
  void Write(LogLevel, const char* text) override { lines.emplace_back(text); }
  std::vector<std::string> lines;
};

class EngineBackendTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new ScratchDir();
    SyntheticSensor sensor;
    Job job;
    JobOptions o;
    o.sensor.width = 320;
    o.sensor.height = 240;
    o.pipeline.labels = 32;
    o.threads = 1;
    ASSERT_TRUE(job.Configure(&sensor, o).ok());
    ASSERT_TRUE(job.Run(dir_->Path("IMG_1.jpg").c_str(), nullptr).ok());
  }
  static void TearDownTestSuite() { delete dir_; }
  static std::string Photo() { return dir_->Path("IMG_1.jpg"); }

  QuietSink sink_;
  Log log_{&sink_, LogLevel::kDebug};
  std::atomic<bool> busy_{false};
  static ScratchDir* dir_;
};
ScratchDir* EngineBackendTest::dir_ = nullptr;

RefocusParams Tap(float x, float y) {
  RefocusParams p;
  p.x0 = p.x1 = x;
  p.y0 = p.y1 = y;
  p.f_number = 2.0f;
  return p;
}

TEST_F(EngineBackendTest, DescribesRendersAndSaves) {
  EngineBackend backend(640, 480, 2, &log_, &busy_);
  ASSERT_TRUE(backend.Ready().ok());
  PhotoInfo info;
  ASSERT_TRUE(backend.Describe(Photo().c_str(), &info).ok());
  EXPECT_EQ(info.width, 320);
  EXPECT_EQ(info.height, 240);
  EXPECT_TRUE(info.refocusable);
  EXPECT_FALSE(info.depth_guess) << "a textured scene's depth is not a guess";
  EXPECT_NEAR(info.current.x0, 0.5f, 0.05f);  // the default focus: the central ninth

  VectorSink preview, full;
  ASSERT_TRUE(backend.Render(Photo().c_str(), Tap(0.2f, 0.8f), true, &preview).ok());
  ASSERT_TRUE(backend.Render(Photo().c_str(), Tap(0.2f, 0.8f), false, &full).ok());
  int32_t w = 0, h = 0;
  std::vector<uint8_t> ycc;
  std::string error;
  ASSERT_TRUE(DecodeYcc(full.bytes, &w, &h, &ycc, &error)) << error;
  EXPECT_EQ(w, 320);
  ASSERT_TRUE(DecodeYcc(preview.bytes, &w, &h, &ycc, &error)) << error;
  EXPECT_LE(std::max(w, h), RefocusBackend::kPreviewWidth);

  const std::vector<uint8_t> before = ReadFile(Photo());
  const std::string out = dir_->Path("IMG_1_refocused.jpg");
  ASSERT_TRUE(backend.Save(Photo().c_str(), Tap(0.2f, 0.8f), out.c_str()).ok());
  EXPECT_EQ(ReadFile(Photo()), before);  // the original untouched
  PhotoInfo saved;
  ASSERT_TRUE(backend.Describe(out.c_str(), &saved).ok());
  EXPECT_TRUE(saved.refocusable);
  EXPECT_NEAR(saved.current.x0, 0.2f, 0.03f);
  EXPECT_NEAR(saved.current.y0, 0.8f, 0.03f);
  // Never over an existing photo.
  EXPECT_FALSE(backend.Save(Photo().c_str(), Tap(0.5f, 0.5f), out.c_str()).ok());
  EXPECT_EQ(backend.Save(Photo().c_str(), Tap(0.5f, 0.5f), Photo().c_str()).code(),
            Code::kInvalidArgument);
  EXPECT_EQ(ReadFile(Photo()), before);
  // Bad requests are refused, not rendered.
  RefocusParams wide = Tap(0.5f, 0.5f);
  wide.f_number = 0.5f;
  VectorSink none;
  EXPECT_EQ(backend.Render(Photo().c_str(), wide, true, &none).code(), Code::kInvalidArgument);
  wide.f_number = 22.5f;
  EXPECT_EQ(backend.Render(Photo().c_str(), wide, true, &none).code(), Code::kInvalidArgument);
  // What a setting accepts, the page renders too.
  RefocusParams closed = Tap(0.5f, 0.5f);
  closed.f_number = 22.0f;
  VectorSink small;
  EXPECT_TRUE(backend.Render(Photo().c_str(), closed, true, &small).ok());
  EXPECT_GT(small.bytes.size(), 1000u);
  VectorSink tiny(100);
  EXPECT_EQ(backend.Render(Photo().c_str(), Tap(0.5f, 0.5f), true, &tiny).code(),
            Code::kOutOfMemory);
  EXPECT_EQ(backend.Describe(dir_->Path("absent.jpg").c_str(), &info).code(), Code::kNotFound);
}

TEST_F(EngineBackendTest, RepeatedTapsDoNotReadTheFileAgain) {
  EngineBackend backend(640, 480, 1, &log_, &busy_);
  PhotoInfo info;
  ASSERT_TRUE(backend.Describe(Photo().c_str(), &info).ok());
  for (int i = 0; i < 5; ++i) {
    VectorSink jpeg;
    ASSERT_TRUE(backend.Render(Photo().c_str(), Tap(0.1f * i, 0.5f), true, &jpeg).ok());
  }
  EXPECT_EQ(backend.loads(), 1);
}

TEST_F(EngineBackendTest, PhotosItCannotRefocusAreStillDescribed) {
  EngineBackend backend(160, 120, 1, &log_, &busy_);  // sized below the photo
  PhotoInfo info;
  ASSERT_TRUE(backend.Describe(Photo().c_str(), &info).ok());
  EXPECT_FALSE(info.refocusable);
  EXPECT_EQ(info.width, 320);
  VectorSink jpeg;
  // The same decision for a render: a photo the page cannot refocus (422), not a server fault.
  EXPECT_EQ(backend.Render(Photo().c_str(), Tap(0.5f, 0.5f), true, &jpeg).code(),
            Code::kUnsupported);
}

TEST_F(EngineBackendTest, QueueIsBoundedAndPreviewsSupersede) {
  busy_ = true;  // the camera holds the render thread at its first strip
  EngineBackend backend(640, 480, 1, &log_, &busy_);
  ASSERT_TRUE(backend.Ready().ok());
  const std::string path = Photo();
  Status first, older_preview, second_full, newer_preview;
  VectorSink a, b, c, d, e;
  std::thread t1([&] { first = backend.Render(path.c_str(), Tap(0.2f, 0.2f), false, &a); });
  auto wait_for = [&](int n) {
    for (int i = 0; i < 5000 && backend.queued() != n; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return backend.queued() == n;
  };
  for (int i = 0; i < 5000 && backend.loads() == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_TRUE(wait_for(0));  // taken: it waits for the camera
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  std::thread t2([&] { older_preview = backend.Render(path.c_str(), Tap(0.3f, 0.3f), true, &b); });
  ASSERT_TRUE(wait_for(1));
  std::thread t3([&] { second_full = backend.Render(path.c_str(), Tap(0.4f, 0.4f), false, &c); });
  ASSERT_TRUE(wait_for(2));
  // Full: a third render is refused at once.
  EXPECT_EQ(backend.Render(path.c_str(), Tap(0.5f, 0.5f), false, &d).code(), Code::kBusy);
  // A newer preview of the same photo takes the waiting preview's place.
  std::thread t4([&] { newer_preview = backend.Render(path.c_str(), Tap(0.6f, 0.6f), true, &e); });
  t2.join();
  EXPECT_EQ(older_preview.code(), Code::kBusy) << older_preview.message();
  EXPECT_TRUE(b.bytes.empty());
  busy_ = false;
  t1.join();
  t3.join();
  t4.join();
  EXPECT_TRUE(first.ok()) << first.message();
  EXPECT_TRUE(second_full.ok()) << second_full.message();
  EXPECT_TRUE(newer_preview.ok()) << newer_preview.message();
  EXPECT_FALSE(e.bytes.empty());
}

TEST_F(EngineBackendTest, WaitingRequestsGiveUpWhileTheCameraWorks) {
  busy_ = true;
  EngineBackend backend(640, 480, 1, &log_, &busy_, /*wait_limit_ms=*/100);
  const std::string path = Photo();
  Status first;
  VectorSink a, b;
  std::thread t1([&] { first = backend.Render(path.c_str(), Tap(0.2f, 0.2f), false, &a); });
  for (int i = 0; i < 5000 && backend.loads() == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(backend.Render(path.c_str(), Tap(0.5f, 0.5f), true, &b).code(), Code::kBusy);
  EXPECT_EQ(backend.queued(), 0);
  busy_ = false;
  t1.join();
  EXPECT_TRUE(first.ok()) << first.message();
}

TEST_F(EngineBackendTest, RenderThreadRunsAtLowPriority) {
  EngineBackend backend(640, 480, 1, &log_, &busy_);
  ASSERT_TRUE(backend.Ready().ok());
  errno = 0;
  const int mine = getpriority(PRIO_PROCESS, 0);
  const int theirs = getpriority(PRIO_PROCESS, static_cast<id_t>(backend.render_tid()));
  EXPECT_EQ(theirs, std::min(19, mine + EngineBackend::kNice));
}

TEST(DisplayedToStored, FollowsTheOrientation) {
  RefocusParams p;
  p.x0 = p.x1 = 0.25f;
  p.y0 = p.y1 = 0.1f;
  // Orientation 6: the stored image is turned 90 degrees clockwise to be shown.
  FocusRegion r = DisplayedToStored(p, 400, 300, 6);
  EXPECT_NEAR(r.x + r.width / 2, 0.1 * 400, 1);
  EXPECT_NEAR(r.y + r.height / 2, 0.75 * 300, 1);
  r = DisplayedToStored(p, 400, 300, 1);
  EXPECT_NEAR(r.x + r.width / 2, 100, 1);
  EXPECT_NEAR(r.y + r.height / 2, 30, 1);
  // A dragged rectangle stays a rectangle.
  p.x1 = 0.75f;
  p.y1 = 0.9f;
  r = DisplayedToStored(p, 400, 300, 3);
  EXPECT_EQ(r.x, 100);
  EXPECT_EQ(r.width, 200);
  EXPECT_EQ(r.y, 30);
}

}  // namespace
}  // namespace lb
