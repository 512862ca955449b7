// Runs inside the throw-away VM (tests/vm) against the real vivid driver: the V4L2 sensor
// captures bursts, and vivid's error-injection controls produce the faults the sensor must
// survive. Skips (exit 77) where no vivid node exists, e.g. on the build host.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "hal/v4l2/v4l2_sensor.h"

namespace lb {
namespace {

std::string FindVivid() {
  for (int i = 0; i < 16; ++i) {
    char path[64];
    snprintf(path, sizeof(path), "/sys/class/video4linux/video%d/name", i);
    FILE* f = fopen(path, "r");
    if (!f) continue;
    char name[64] = {};
    bool vivid = fgets(name, sizeof(name), f) && strstr(name, "vivid");
    fclose(f);
    if (vivid) return "/dev/video" + std::to_string(i);
  }
  return "";
}

// Sets a vivid control found by its name; 0 when not found.
bool SetControl(const std::string& device, const char* name, int32_t value) {
  int fd = open(device.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0) return false;
  v4l2_query_ext_ctrl q;
  memset(&q, 0, sizeof(q));
  q.id = V4L2_CTRL_FLAG_NEXT_CTRL;
  bool done = false;
  while (!done && ioctl(fd, VIDIOC_QUERY_EXT_CTRL, &q) == 0) {
    if (strcmp(q.name, name) == 0) {
      v4l2_control c = {q.id, value};
      done = ioctl(fd, VIDIOC_S_CTRL, &c) == 0;
      break;
    }
    q.id |= V4L2_CTRL_FLAG_NEXT_CTRL;
  }
  close(fd);
  return done;
}

class FrameCheck : public FrameSink {
 public:
  std::vector<FrameInfo> frames;
  std::vector<int> distinct_values;  // per frame: how many different bytes the first row holds
  Status BeginFrame(const FrameInfo& info) override {
    frames.push_back(info);
    return Status::Ok();
  }
  Status Rows(const FrameRows& rows) override {
    bool seen[256] = {};
    int distinct = 0;
    const FrameInfo& f = frames.back();
    int bytes = f.width * (f.format == PixelFormat::kNv12 ? 1 : BytesPerPixel(f.format));
    for (int x = 0; x < bytes; ++x) {
      uint8_t v = rows.planes[0][rows.strides[0] * (rows.height / 2) + x];
      if (!seen[v]) ++distinct;
      seen[v] = true;
    }
    distinct_values.push_back(distinct);
    EXPECT_EQ(rows.height, f.height);
    if (f.format == PixelFormat::kNv12) {
      EXPECT_NE(rows.planes[1], nullptr);
    }
    return Status::Ok();
  }
  Status EndFrame() override { return Status::Ok(); }
};

class VividTest : public ::testing::Test {
 protected:
  void SetUp() override {
    device_ = FindVivid();
    if (device_.empty()) {
      // Inside the VM the driver must be there; elsewhere its absence is a skip.
      if (getenv("LB_REQUIRE_DEVICES")) FAIL() << "no vivid capture node";
      GTEST_SKIP() << "no vivid capture node";
    }
    ASSERT_TRUE(SetControl(device_, "Percentage of Dropped Buffers", 0));
  }
  V4l2Options Options(uint32_t fourcc = 0) {
    V4l2Options o;
    o.device = device_.c_str();
    o.fourcc = fourcc;
    o.fps = 5;  // what vivid's pattern generator keeps up with under emulation
    return o;
  }
  static SensorConfig Burst(int frames = 5, int timeout_ms = 3000) {
    SensorConfig c;
    c.width = 640;  // one of vivid's webcam sizes
    c.height = 360;
    c.frames = frames;
    c.timeout_ms = timeout_ms;
    return c;
  }
  std::string device_;
};

TEST_F(VividTest, CapturesAFiveFrameBurst) {
  V4l2Sensor sensor(Options());
  SensorMode mode;
  Status s = sensor.Configure(Burst(), &mode);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(mode.format, PixelFormat::kYuyv);
  EXPECT_EQ(mode.width, 640);
  EXPECT_EQ(mode.height, 360);
  FrameCheck sink;
  s = sensor.CaptureBurst(sink);
  ASSERT_TRUE(s.ok()) << s.message();
  ASSERT_EQ(sink.frames.size(), 5u);
  for (size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(sink.frames[i].index, static_cast<int32_t>(i));
    if (i > 0) {
      EXPECT_EQ(sink.frames[i].sequence, sink.frames[i - 1].sequence + 1);
      EXPECT_GT(sink.frames[i].timestamp_ns, sink.frames[i - 1].timestamp_ns);
    }
    EXPECT_GT(sink.distinct_values[i], 4) << "vivid's test pattern should not be flat";
  }
  printf("vivid: 5 frames %dx%d %s, sequence %u..%u\n", mode.width, mode.height,
         PixelFormatName(mode.format), sink.frames[0].sequence, sink.frames[4].sequence);
}

TEST_F(VividTest, Nv12AndRgb24) {
  for (uint32_t fourcc : {V4L2_PIX_FMT_NV12, V4L2_PIX_FMT_RGB24, V4L2_PIX_FMT_BGR24}) {
    V4l2Sensor sensor(Options(fourcc));
    SensorMode mode;
    Status s = sensor.Configure(Burst(2), &mode);
    ASSERT_TRUE(s.ok()) << s.message();
    FrameCheck sink;
    s = sensor.CaptureBurst(sink);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_EQ(sink.frames.size(), 2u);
  }
}

TEST_F(VividTest, SensorThatStopsDeliveringTimesOutThenRecovers) {
  V4l2Sensor sensor(Options());
  SensorMode mode;
  ASSERT_TRUE(sensor.Configure(Burst(5, 1500), &mode).ok());
  ASSERT_TRUE(SetControl(device_, "Percentage of Dropped Buffers", 100));
  FrameCheck sink;
  Status s = sensor.CaptureBurst(sink);
  EXPECT_EQ(s.code(), Code::kTimeout) << s.message();
  printf("stalled sensor: %s\n", s.message());
  ASSERT_TRUE(SetControl(device_, "Percentage of Dropped Buffers", 0));
  FrameCheck again;
  s = sensor.CaptureBurst(again);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(again.frames.size(), 5u);
}

TEST_F(VividTest, DroppedFrameIsDetectedThenRecovers) {
  V4l2Sensor sensor(Options());
  SensorMode mode;
  ASSERT_TRUE(sensor.Configure(Burst(6), &mode).ok());
  ASSERT_TRUE(SetControl(device_, "Percentage of Dropped Buffers", 50));
  // With half the buffers dropped a six-frame burst survives with probability 1/32; three
  // bursts in a row with 1/32768.
  Status s;
  for (int attempt = 0; attempt < 3; ++attempt) {
    FrameCheck sink;
    s = sensor.CaptureBurst(sink);
    if (!s.ok()) break;
  }
  EXPECT_EQ(s.code(), Code::kCorruptData) << s.message();
  EXPECT_NE(std::string(s.message()).find("dropped"), std::string::npos) << s.message();
  printf("dropped frame: %s\n", s.message());
  ASSERT_TRUE(SetControl(device_, "Percentage of Dropped Buffers", 0));
  FrameCheck again;
  s = sensor.CaptureBurst(again);
  ASSERT_TRUE(s.ok()) << s.message();
}

TEST_F(VividTest, BufferFlaggedBadIsDetected) {
  V4l2Sensor sensor(Options());
  SensorMode mode;
  ASSERT_TRUE(sensor.Configure(Burst(3), &mode).ok());
  ASSERT_TRUE(SetControl(device_, "Inject V4L2_BUF_FLAG_ERROR", 1));
  FrameCheck sink;
  Status s = sensor.CaptureBurst(sink);
  EXPECT_EQ(s.code(), Code::kCorruptData) << s.message();
  printf("flagged buffer: %s\n", s.message());
  FrameCheck again;
  s = sensor.CaptureBurst(again);
  ASSERT_TRUE(s.ok()) << s.message();
}

TEST_F(VividTest, UnpluggedCameraIsReportedAndComesBack) {
  V4l2Sensor sensor(Options());
  SensorMode mode;
  ASSERT_TRUE(sensor.Configure(Burst(3), &mode).ok());
  // vivid's Disconnect acts like a USB unplug until every open handle is closed.
  ASSERT_TRUE(SetControl(device_, "Disconnect", 1));
  FrameCheck sink;
  Status s = sensor.CaptureBurst(sink);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(std::string(s.message()).find("No such device"), std::string::npos) << s.message();
  printf("unplugged camera: %s\n", s.message());
  sensor.Stop();
  s = sensor.Configure(Burst(3), &mode);
  ASSERT_TRUE(s.ok()) << s.message();
  FrameCheck again;
  s = sensor.CaptureBurst(again);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(again.frames.size(), 3u);
}

TEST_F(VividTest, SecondOpenerFindsTheDeviceBusy) {
  V4l2Sensor first(Options());
  SensorMode mode;
  ASSERT_TRUE(first.Configure(Burst(), &mode).ok());
  V4l2Sensor second(Options());
  Status s = second.Configure(Burst(), &mode);
  EXPECT_EQ(s.code(), Code::kBusy) << s.message();
  printf("busy device: %s\n", s.message());
  first.Stop();
  s = second.Configure(Burst(), &mode);
  EXPECT_TRUE(s.ok()) << s.message();
}

}  // namespace
}  // namespace lb
