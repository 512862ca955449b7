// Runs inside the throw-away VM (tests/vm) with the vimc driver: the libcamera sensor captures
// bursts through libcamera's vimc pipeline handler. Skips where libcamera lists no camera,
// fails instead inside the VM (LB_REQUIRE_DEVICES).
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <vector>

#include "hal/libcamera/libcamera_sensor.h"

namespace lb {
namespace {

class FrameCheck : public FrameSink {
 public:
  std::vector<FrameInfo> frames;
  std::vector<int> distinct;  // different byte values in the middle row
  Status BeginFrame(const FrameInfo& info) override {
    frames.push_back(info);
    return Status::Ok();
  }
  Status Rows(const FrameRows& rows) override {
    const FrameInfo& f = frames.back();
    EXPECT_EQ(rows.y0, 0);
    EXPECT_EQ(rows.height, f.height);
    int bytes = f.width * (f.format == PixelFormat::kNv12 ? 1 : BytesPerPixel(f.format));
    EXPECT_GE(rows.strides[0], bytes);
    bool seen[256] = {};
    int n = 0;
    const uint8_t* row = rows.planes[0] + rows.strides[0] * (rows.height / 2);
    for (int x = 0; x < bytes; ++x) {
      if (!seen[row[x]]) ++n;
      seen[row[x]] = true;
    }
    distinct.push_back(n);
    return Status::Ok();
  }
  Status EndFrame() override { return Status::Ok(); }
};

TEST(VimcTest, CapturesFiveFrameBurstsThroughLibcamera) {
  LibcameraSensor sensor(LibcameraOptions{});
  SensorConfig config;
  config.width = 640;
  config.height = 480;
  config.frames = 5;
  config.timeout_ms = 5000;
  SensorMode mode;
  Status s = sensor.Configure(config, &mode);
  if (s.code() == Code::kNotFound && !getenv("LB_REQUIRE_DEVICES")) GTEST_SKIP() << s.message();
  ASSERT_TRUE(s.ok()) << s.message();
  printf("libcamera: camera '%s' %dx%d %s\n", sensor.camera_id(), mode.width, mode.height,
         PixelFormatName(mode.format));
  EXPECT_GT(mode.width, 0);
  EXPECT_GT(mode.height, 0);
  // Two bursts on one configuration: the requests are reused.
  for (int burst = 0; burst < 2; ++burst) {
    FrameCheck sink;
    s = sensor.CaptureBurst(sink);
    ASSERT_TRUE(s.ok()) << "burst " << burst << ": " << s.message();
    ASSERT_EQ(sink.frames.size(), 5u);
    for (size_t i = 0; i < 5; ++i) {
      EXPECT_EQ(sink.frames[i].index, static_cast<int32_t>(i));
      EXPECT_EQ(sink.frames[i].width, mode.width);
      EXPECT_GT(sink.distinct[i], 4) << "vimc's test pattern should not be flat";
      if (i > 0) {
        EXPECT_EQ(sink.frames[i].sequence, sink.frames[i - 1].sequence + 1);
        EXPECT_GT(sink.frames[i].timestamp_ns, sink.frames[i - 1].timestamp_ns);
      }
    }
    printf("libcamera burst %d: sequence %u..%u, exposure held %d, white balance held %d\n", burst,
           sink.frames[0].sequence, sink.frames[4].sequence, sensor.exposure_held(),
           sensor.white_balance_held());
  }
  // Released and configured again.
  sensor.Stop();
  s = sensor.Configure(config, &mode);
  ASSERT_TRUE(s.ok()) << s.message();
  FrameCheck sink;
  s = sensor.CaptureBurst(sink);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(sink.frames.size(), 5u);
}

}  // namespace
}  // namespace lb
