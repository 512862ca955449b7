#include "hal/v4l2/v4l2_sensor.h"

#include <errno.h>
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <string>
#include <vector>

#include "tests/hal/v4l2/fake_v4l2.h"

namespace lb {
namespace {

// Checks every delivered row against the fake's pattern, so a wrong buffer, stride or plane
// offset shows up as a mismatch.
class CheckingSink : public FrameSink {
 public:
  std::vector<FrameInfo> frames;
  int strips = 0;
  int mismatches = 0;
  int fail_at = -1;  // BeginFrame of this frame fails

  Status BeginFrame(const FrameInfo& info) override {
    if (info.index == fail_at) return Status(Code::kOutOfMemory, "sink full");
    frames.push_back(info);
    return Status::Ok();
  }
  Status Rows(const FrameRows& rows) override {
    ++strips;
    const FrameInfo& f = frames.back();
    EXPECT_EQ(rows.y0, 0);
    EXPECT_EQ(rows.height, f.height);
    int bpp = f.format == PixelFormat::kNv12 ? 1 : BytesPerPixel(f.format);
    // The fake numbers the frames of a stream; index == stream frame here.
    uint32_t n = static_cast<uint32_t>(f.index);
    for (int32_t y = 0; y < rows.height; ++y) {
      for (int32_t x = 0; x < f.width * bpp; ++x) {
        if (rows.planes[0][y * rows.strides[0] + x] != FakeV4l2::Pattern(n, 0, y, x)) ++mismatches;
      }
    }
    if (f.format == PixelFormat::kNv12) {
      for (int32_t y = 0; y < rows.height / 2; ++y) {
        for (int32_t x = 0; x < f.width; ++x) {
          if (rows.planes[1][y * rows.strides[1] + x] != FakeV4l2::Pattern(n, 1, y, x)) {
            ++mismatches;
          }
        }
      }
    }
    return Status::Ok();
  }
  Status EndFrame() override { return Status::Ok(); }
};

SensorConfig Burst(int frames = 5) {
  SensorConfig c;
  c.frames = frames;
  c.timeout_ms = 50;
  return c;
}

bool Contains(const Status& s, const char* text) {
  return std::string(s.message()).find(text) != std::string::npos;
}

TEST(V4l2SensorTest, CapturesAFiveFrameBurstStraightFromTheBuffers) {
  FakeV4l2 dev;
  V4l2Sensor sensor(V4l2Options{}, &dev);
  SensorMode mode;
  ASSERT_TRUE(sensor.Configure(Burst(), &mode).ok());
  EXPECT_EQ(mode.format, PixelFormat::kYuyv);
  EXPECT_EQ(mode.width, 64);
  EXPECT_EQ(mode.height, 48);
  EXPECT_EQ(mode.frames, 5);
  EXPECT_EQ(sensor.layout().stride, 64 * 2 + 16);
  EXPECT_EQ(dev.granted_buffers, 5u);  // one per frame by default

  CheckingSink sink;
  Status s = sensor.CaptureBurst(sink);
  ASSERT_TRUE(s.ok()) << s.message();
  ASSERT_EQ(sink.frames.size(), 5u);
  EXPECT_EQ(sink.strips, 5);
  EXPECT_EQ(sink.mismatches, 0);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(sink.frames[i].index, i);
    EXPECT_EQ(sink.frames[i].sequence, static_cast<uint32_t>(i));
    EXPECT_EQ(sink.frames[i].timestamp_ns, (100 + i) * 1000000000LL);
  }
  EXPECT_FALSE(dev.streaming);  // stopped after the burst
}

TEST(V4l2SensorTest, NegotiatesNv12AndRgb24AndTheRequestedSize) {
  for (uint32_t fourcc : {V4L2_PIX_FMT_NV12, V4L2_PIX_FMT_RGB24}) {
    FakeV4l2 dev;
    V4l2Options options;
    options.fourcc = fourcc;
    V4l2Sensor sensor(options, &dev);
    SensorConfig config = Burst(3);
    config.width = 32;
    config.height = 20;
    SensorMode mode;
    ASSERT_TRUE(sensor.Configure(config, &mode).ok());
    EXPECT_EQ(mode.width, 32);
    EXPECT_EQ(mode.height, 20);
    CheckingSink sink;
    ASSERT_TRUE(sensor.CaptureBurst(sink).ok());
    ASSERT_EQ(sink.frames.size(), 3u);
    EXPECT_EQ(sink.frames[0].format,
              fourcc == V4L2_PIX_FMT_NV12 ? PixelFormat::kNv12 : PixelFormat::kRgb8);
    EXPECT_EQ(sink.mismatches, 0);
  }
}

TEST(V4l2SensorTest, FallsBackToBgrWhenThatIsAllTheDeviceHas) {
  FakeV4l2 dev;
  dev.formats = {V4L2_PIX_FMT_MJPEG, V4L2_PIX_FMT_BGR24};
  V4l2Sensor sensor(V4l2Options{}, &dev);
  SensorMode mode;
  ASSERT_TRUE(sensor.Configure(Burst(), &mode).ok());
  EXPECT_EQ(mode.format, PixelFormat::kBgr8);
}

TEST(V4l2SensorTest, SetsTheRequestedFrameRate) {
  FakeV4l2 dev;
  V4l2Options options;
  options.fps = 5;
  V4l2Sensor sensor(options, &dev);
  SensorMode mode;
  ASSERT_TRUE(sensor.Configure(Burst(), &mode).ok());
  EXPECT_EQ(dev.fps, 5u);
  options.fps = 5000;
  V4l2Sensor too_fast(options, &dev);
  EXPECT_EQ(too_fast.Configure(Burst(), &mode).code(), Code::kInvalidArgument);
}

TEST(V4l2SensorTest, BurstLongerThanTheBuffersRequeues) {
  FakeV4l2 dev;
  V4l2Options options;
  options.buffers = 2;
  V4l2Sensor sensor(options, &dev);
  SensorMode mode;
  ASSERT_TRUE(sensor.Configure(Burst(7), &mode).ok());
  CheckingSink sink;
  Status s = sensor.CaptureBurst(sink);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(sink.frames.size(), 7u);
  EXPECT_EQ(sink.mismatches, 0);
}

TEST(V4l2SensorTest, SensorThatStopsDeliveringTimesOutAndRecovers) {
  FakeV4l2 dev;
  dev.stall_after = 2;
  V4l2Sensor sensor(V4l2Options{}, &dev);
  SensorMode mode;
  ASSERT_TRUE(sensor.Configure(Burst(), &mode).ok());
  CheckingSink sink;
  Status s = sensor.CaptureBurst(sink);
  EXPECT_EQ(s.code(), Code::kTimeout);
  EXPECT_TRUE(Contains(s, "/dev/video0")) << s.message();
  EXPECT_TRUE(Contains(s, "50 ms")) << s.message();
  EXPECT_FALSE(dev.streaming);

  dev.stall_after = -1;
  CheckingSink again;
  s = sensor.CaptureBurst(again);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(again.frames.size(), 5u);
}

TEST(V4l2SensorTest, DroppedFrameAbandonsTheBurstAndTheNextOneWorks) {
  FakeV4l2 dev;
  dev.skip_at = 3;
  dev.skip_count = 2;
  V4l2Sensor sensor(V4l2Options{}, &dev);
  SensorMode mode;
  ASSERT_TRUE(sensor.Configure(Burst(), &mode).ok());
  CheckingSink sink;
  Status s = sensor.CaptureBurst(sink);
  EXPECT_EQ(s.code(), Code::kCorruptData);
  EXPECT_TRUE(Contains(s, "2 frame(s) dropped before sequence 5")) << s.message();
  EXPECT_EQ(sink.frames.size(), 3u);
  EXPECT_FALSE(dev.streaming);

  dev.skip_at = -1;
  CheckingSink again;
  ASSERT_TRUE(sensor.CaptureBurst(again).ok());
  EXPECT_EQ(again.frames.size(), 5u);
}

TEST(V4l2SensorTest, BufferFlaggedBadAbandonsTheBurst) {
  FakeV4l2 dev;
  dev.error_flag_at = 1;
  V4l2Sensor sensor(V4l2Options{}, &dev);
  SensorMode mode;
  ASSERT_TRUE(sensor.Configure(Burst(), &mode).ok());
  CheckingSink sink;
  Status s = sensor.CaptureBurst(sink);
  EXPECT_EQ(s.code(), Code::kCorruptData);
  EXPECT_TRUE(Contains(s, "flagged bad")) << s.message();
}

TEST(V4l2SensorTest, IoctlErrorsNameTheCallTheDeviceAndTheErrno) {
  struct Case {
    unsigned long request;
    const char* name;
    bool at_capture;
  };
  const Case cases[] = {
      {VIDIOC_QUERYCAP, "VIDIOC_QUERYCAP", false}, {VIDIOC_ENUM_FMT, "VIDIOC_ENUM_FMT", false},
      {VIDIOC_S_FMT, "VIDIOC_S_FMT", false},       {VIDIOC_REQBUFS, "VIDIOC_REQBUFS", false},
      {VIDIOC_QUERYBUF, "VIDIOC_QUERYBUF", false}, {VIDIOC_QBUF, "VIDIOC_QBUF", true},
      {VIDIOC_STREAMON, "VIDIOC_STREAMON", true},  {VIDIOC_DQBUF, "VIDIOC_DQBUF", true}};
  for (const Case& c : cases) {
    FakeV4l2 dev;
    dev.fail_request = c.request;
    dev.fail_errno = EIO;
    V4l2Options options;
    options.device = "/dev/video7";
    options.fps = 10;
    V4l2Sensor sensor(options, &dev);
    SensorMode mode;
    Status s = sensor.Configure(Burst(), &mode);
    if (c.at_capture) {
      ASSERT_TRUE(s.ok()) << c.name << ": " << s.message();
      CheckingSink sink;
      s = sensor.CaptureBurst(sink);
    }
    EXPECT_EQ(s.code(), Code::kIoError) << c.name;
    EXPECT_TRUE(Contains(s, c.name)) << s.message();
    EXPECT_TRUE(Contains(s, "/dev/video7")) << s.message();
    EXPECT_TRUE(Contains(s, "errno 5")) << s.message();
    EXPECT_TRUE(Contains(s, "Input/output error")) << s.message();
    sensor.Stop();
    EXPECT_EQ(dev.open_fds, 0) << c.name;
    EXPECT_EQ(dev.mapped, 0) << c.name;
  }
}

TEST(V4l2SensorTest, BusyDeviceSaysSo) {
  FakeV4l2 dev;
  dev.fail_request = VIDIOC_S_FMT;
  dev.fail_errno = EBUSY;
  V4l2Sensor sensor(V4l2Options{}, &dev);
  SensorMode mode;
  Status s = sensor.Configure(Burst(), &mode);
  EXPECT_EQ(s.code(), Code::kBusy);
  EXPECT_TRUE(Contains(s, "Device or resource busy")) << s.message();
  EXPECT_EQ(dev.open_fds, 0);  // a failed Configure releases what it took
}

TEST(V4l2SensorTest, MissingDeviceIsNotFound) {
  FakeV4l2 dev;
  dev.exists = false;
  V4l2Options options;
  options.device = "/dev/video9";
  V4l2Sensor sensor(options, &dev);
  SensorMode mode;
  Status s = sensor.Configure(Burst(), &mode);
  EXPECT_EQ(s.code(), Code::kNotFound);
  EXPECT_TRUE(Contains(s, "/dev/video9")) << s.message();
}

TEST(V4l2SensorTest, RefusesNodesThatAreNotStreamingCapture) {
  FakeV4l2 dev;
  dev.caps = V4L2_CAP_VIDEO_CAPTURE_MPLANE | V4L2_CAP_STREAMING;
  V4l2Sensor sensor(V4l2Options{}, &dev);
  SensorMode mode;
  EXPECT_EQ(sensor.Configure(Burst(), &mode).code(), Code::kUnsupported);
  EXPECT_EQ(dev.open_fds, 0);
}

TEST(V4l2SensorTest, TooFewBuffersGrantedIsReported) {
  FakeV4l2 dev;
  dev.max_buffers = 1;
  V4l2Sensor sensor(V4l2Options{}, &dev);
  SensorMode mode;
  Status s = sensor.Configure(Burst(), &mode);
  EXPECT_EQ(s.code(), Code::kUnsupported);
  EXPECT_TRUE(Contains(s, "granted 1 buffers")) << s.message();
  EXPECT_EQ(dev.open_fds, 0);
  EXPECT_EQ(dev.mapped, 0);
}

TEST(V4l2SensorTest, BadBurstSettingsAreRejectedBeforeOpening) {
  FakeV4l2 dev;
  V4l2Sensor sensor(V4l2Options{}, &dev);
  SensorMode mode;
  SensorConfig c = Burst(0);
  EXPECT_EQ(sensor.Configure(c, &mode).code(), Code::kInvalidArgument);
  c = Burst(5);
  c.timeout_ms = 0;
  EXPECT_EQ(sensor.Configure(c, &mode).code(), Code::kInvalidArgument);
  EXPECT_EQ(dev.open_fds, 0);
  CheckingSink sink;
  EXPECT_EQ(sensor.CaptureBurst(sink).code(), Code::kInvalidArgument);
}

TEST(V4l2SensorTest, SinkErrorStopsTheStreamAndIsPassedOn) {
  FakeV4l2 dev;
  V4l2Sensor sensor(V4l2Options{}, &dev);
  SensorMode mode;
  ASSERT_TRUE(sensor.Configure(Burst(), &mode).ok());
  CheckingSink sink;
  sink.fail_at = 2;
  Status s = sensor.CaptureBurst(sink);
  EXPECT_EQ(s.code(), Code::kOutOfMemory);
  EXPECT_TRUE(Contains(s, "frame 2: sink full")) << s.message();
  EXPECT_FALSE(dev.streaming);
}

TEST(V4l2SensorTest, ReconfigureAndStopReleaseEverything) {
  FakeV4l2 dev;
  {
    V4l2Sensor sensor(V4l2Options{}, &dev);
    SensorMode mode;
    for (int i = 0; i < 3; ++i) {
      ASSERT_TRUE(sensor.Configure(Burst(4), &mode).ok());
      EXPECT_EQ(dev.open_fds, 1);
      EXPECT_EQ(dev.mapped, 4);
    }
    sensor.Stop();
    EXPECT_EQ(dev.open_fds, 0);
    EXPECT_EQ(dev.mapped, 0);
    ASSERT_TRUE(sensor.Configure(Burst(4), &mode).ok());
  }
  // The destructor stops too.
  EXPECT_EQ(dev.open_fds, 0);
  EXPECT_EQ(dev.mapped, 0);
}

// Probe: what the daemon logs before "ready", and --check-config prints.
Status ProbeFake(FakeV4l2* dev, const char* device = "/dev/video7") {
  V4l2Options options;
  options.device = device;
  V4l2Sensor sensor(options, dev);
  Status s = sensor.Probe();
  EXPECT_EQ(dev->open_fds, 0) << "the probe keeps no descriptor";
  return s;
}

TEST(V4l2ProbeTest, StreamingCaptureNodePasses) {
  FakeV4l2 dev;
  Status s = ProbeFake(&dev);
  EXPECT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(dev.mapped, 0);
  EXPECT_EQ(dev.streamon_calls, 0);
}

TEST(V4l2ProbeTest, MissingNodeIsNoSuchDevice) {
  FakeV4l2 dev;
  dev.exists = false;
  Status s = ProbeFake(&dev);
  EXPECT_EQ(s.code(), Code::kNotFound);
  EXPECT_STREQ(s.message(), "camera /dev/video7: no such device");
}

TEST(V4l2ProbeTest, FileThatIsNoV4l2NodeSaysSo) {
  FakeV4l2 dev;
  dev.fail_request = VIDIOC_QUERYCAP;
  dev.fail_errno = ENOTTY;
  Status s = ProbeFake(&dev);
  EXPECT_EQ(s.code(), Code::kUnsupported);
  EXPECT_STREQ(s.message(), "camera /dev/video7: not a V4L2 device");
}

TEST(V4l2ProbeTest, NodesThatAreNoCameraSayWhatTheyAre) {
  struct Case {
    uint32_t caps;
    const char* says;
  };
  const Case cases[] = {
      {V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_STREAMING,
       "camera /dev/video7 (fake): not a capture device (a video output; caps 0x04000002)"},
      {V4L2_CAP_VIDEO_M2M_MPLANE | V4L2_CAP_STREAMING,
       "camera /dev/video7 (fake): not a capture device (a memory-to-memory device: a codec or "
       "scaler; caps 0x04004000)"},
      {V4L2_CAP_META_CAPTURE | V4L2_CAP_STREAMING,
       "camera /dev/video7 (fake): not a capture device (a metadata node: the pictures come from "
       "another node; caps 0x04800000)"},
      {V4L2_CAP_VIDEO_CAPTURE_MPLANE | V4L2_CAP_STREAMING,
       "camera /dev/video7 (fake): a multi-planar capture node; the v4l2 backend reads "
       "single-planar nodes only"},
      {V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_READWRITE,
       "camera /dev/video7 (fake): a capture node without streaming I/O (read() only); mmap "
       "streaming is needed"},
  };
  for (const Case& c : cases) {
    FakeV4l2 dev;
    dev.caps = c.caps;
    Status s = ProbeFake(&dev);
    EXPECT_EQ(s.code(), Code::kUnsupported) << c.says;
    EXPECT_STREQ(s.message(), c.says);
    // Configure refuses the same nodes with the same reason.
    V4l2Options options;
    options.device = "/dev/video7";
    V4l2Sensor sensor(options, &dev);
    SensorMode mode;
    s = sensor.Configure(Burst(), &mode);
    EXPECT_EQ(s.code(), Code::kUnsupported);
    EXPECT_EQ("camera " + std::string(s.message()), c.says) << s.message();
  }
}

// The same through the real system calls, on what a mistyped `device` names.
class V4l2SystemProbeTest : public ::testing::Test {
 protected:
  V4l2SystemProbeTest() {
    char tmpl[] = "/tmp/v4l2_probe_XXXXXX";
    dir_ = mkdtemp(tmpl) ? tmpl : "";
  }
  ~V4l2SystemProbeTest() override {
    unlink((dir_ + "/file").c_str());
    rmdir(dir_.c_str());
  }
  static std::string Probe(const std::string& device) {
    V4l2Options options;
    options.device = device.c_str();
    return V4l2Sensor(options).Probe().message();
  }
  // qemu-user answers ioctls it cannot translate, V4L2's among them, with ENOSYS (the ARM test
  // runs): the probe then rightly names that failure instead.
  static bool Emulated(const std::string& message) {
    return message.find("VIDIOC_QUERYCAP failed: Function not implemented") != std::string::npos;
  }
  std::string dir_;
};

TEST_F(V4l2SystemProbeTest, DevNullIsNotAV4l2Device) {
  const std::string m = Probe("/dev/null");
  if (Emulated(m)) GTEST_SKIP() << m;
  EXPECT_EQ(m, "camera /dev/null: not a V4L2 device");
}

TEST_F(V4l2SystemProbeTest, MissingPathIsNoSuchDevice) {
  ASSERT_FALSE(dir_.empty());
  EXPECT_EQ(Probe(dir_ + "/video7"), "camera " + dir_ + "/video7: no such device");
}

TEST_F(V4l2SystemProbeTest, RegularFileAndFolderAreNotV4l2Devices) {
  ASSERT_FALSE(dir_.empty());
  FILE* f = fopen((dir_ + "/file").c_str(), "w");
  ASSERT_NE(f, nullptr);
  fclose(f);
  EXPECT_EQ(Probe(dir_), "camera " + dir_ + ": not a V4L2 device (a folder)");
  const std::string m = Probe(dir_ + "/file");
  if (Emulated(m)) GTEST_SKIP() << m;
  EXPECT_EQ(m, "camera " + dir_ + "/file: not a V4L2 device");
}

}  // namespace
}  // namespace lb
