// The libcamera sensor's pieces that need no camera: format choice, the exposure hold, and the
// errors of a machine without cameras (the build host).
#include <gtest/gtest.h>
#include <libcamera/control_ids.h>
#include <libcamera/formats.h>

#include <string>

#include "hal/libcamera/exposure_hold.h"
#include "hal/libcamera/libcamera_format.h"
#include "hal/libcamera/libcamera_sensor.h"

namespace lb {
namespace {

namespace f = libcamera::formats;
namespace c = libcamera::controls;

TEST(LibcameraFormatTest, DrmNamedRgbMapsByMemoryOrder) {
  PixelFormat out;
  ASSERT_TRUE(LibcameraToPixelFormat(f::BGR888, &out));
  EXPECT_EQ(out, PixelFormat::kRgb8);  // R, G, B in memory
  ASSERT_TRUE(LibcameraToPixelFormat(f::RGB888, &out));
  EXPECT_EQ(out, PixelFormat::kBgr8);
  ASSERT_TRUE(LibcameraToPixelFormat(f::YUYV, &out));
  EXPECT_EQ(out, PixelFormat::kYuyv);
  ASSERT_TRUE(LibcameraToPixelFormat(f::NV12, &out));
  EXPECT_EQ(out, PixelFormat::kNv12);
  EXPECT_FALSE(LibcameraToPixelFormat(f::SBGGR10, &out));
  EXPECT_FALSE(LibcameraToPixelFormat(f::MJPEG, &out));
}

TEST(LibcameraFormatTest, KeepsAReadableDefaultElsePrefersYuvThenRgb) {
  EXPECT_EQ(ChooseLibcameraFormat(f::BGR888, {f::YUYV, f::BGR888}), f::BGR888);
  EXPECT_EQ(ChooseLibcameraFormat(f::SBGGR10, {f::RGB888, f::NV12, f::SBGGR10}), f::NV12);
  EXPECT_EQ(ChooseLibcameraFormat(f::MJPEG, {f::RGB888, f::MJPEG}), f::RGB888);
  EXPECT_FALSE(ChooseLibcameraFormat(f::MJPEG, {f::SBGGR10, f::MJPEG}).isValid());
}

libcamera::ControlInfoMap Available(bool ae, bool awb) {
  libcamera::ControlInfoMap::Map map;
  if (ae) {
    map.emplace(&c::AeEnable, libcamera::ControlInfo(false, true));
    map.emplace(&c::ExposureTime, libcamera::ControlInfo(100, 100000));
    map.emplace(&c::AnalogueGain, libcamera::ControlInfo(1.0f, 16.0f));
  }
  if (awb) {
    map.emplace(&c::AwbEnable, libcamera::ControlInfo(false, true));
    map.emplace(&c::ColourGains, libcamera::ControlInfo(0.0f, 32.0f));
  }
  return libcamera::ControlInfoMap(std::move(map), c::controls);
}

libcamera::ControlList Metered() {
  libcamera::ControlList md(c::controls);
  md.set(c::ExposureTime, 12345);
  md.set(c::AnalogueGain, 2.5f);
  const float gains[2] = {1.8f, 1.4f};
  md.set(c::ColourGains, libcamera::Span<const float, 2>(gains));
  return md;
}

TEST(ExposureHoldTest, FixesWhatTheCameraExposesToTheMeteredValues) {
  libcamera::ControlList out(c::controls);
  HeldControls held = HoldExposure(Available(true, true), Metered(), &out);
  EXPECT_TRUE(held.exposure);
  EXPECT_TRUE(held.white_balance);
  EXPECT_EQ(out.get(c::AeEnable), std::optional<bool>(false));
  EXPECT_EQ(out.get(c::ExposureTime), std::optional<int32_t>(12345));
  EXPECT_EQ(out.get(c::AnalogueGain), std::optional<float>(2.5f));
  EXPECT_EQ(out.get(c::AwbEnable), std::optional<bool>(false));
  auto gains = out.get(c::ColourGains);
  ASSERT_TRUE(gains);
  EXPECT_FLOAT_EQ((*gains)[0], 1.8f);
  EXPECT_FLOAT_EQ((*gains)[1], 1.4f);
}

TEST(ExposureHoldTest, SetsNothingTheCameraLacks) {
  libcamera::ControlList out(c::controls);
  HeldControls held = HoldExposure(Available(true, false), Metered(), &out);
  EXPECT_TRUE(held.exposure);
  EXPECT_FALSE(held.white_balance);
  EXPECT_FALSE(out.contains(c::AwbEnable.id()));
  libcamera::ControlList none(c::controls);
  held = HoldExposure(Available(false, false), Metered(), &none);
  EXPECT_FALSE(held.exposure);
  EXPECT_TRUE(none.empty());
}

TEST(ExposureHoldTest, NoMeteredValueNoHold) {
  libcamera::ControlList out(c::controls);
  libcamera::ControlList empty(c::controls);
  HeldControls held = HoldExposure(Available(true, true), empty, &out);
  EXPECT_FALSE(held.exposure);
  EXPECT_FALSE(held.white_balance);
  EXPECT_TRUE(out.empty());
}

// One test owns the process's CameraManager at a time (libcamera allows one per process).
TEST(LibcameraSensorTest, ErrorsWithoutACamera) {
  SensorConfig config;
  SensorMode mode;
  {
    LibcameraSensor sensor(LibcameraOptions{});
    config.frames = 0;
    EXPECT_EQ(sensor.Configure(config, &mode).code(), Code::kInvalidArgument);
    config.frames = 5;
    class NullSink : public FrameSink {
      Status BeginFrame(const FrameInfo&) override { return Status::Ok(); }
      Status Rows(const FrameRows&) override { return Status::Ok(); }
      Status EndFrame() override { return Status::Ok(); }
    } sink;
    EXPECT_EQ(sensor.CaptureBurst(sink).code(), Code::kInvalidArgument);
  }
  LibcameraOptions options;
  options.camera_id = "/base/no/such/camera";
  LibcameraSensor sensor(options);
  Status s = sensor.Configure(config, &mode);
  if (s.ok()) GTEST_SKIP() << "this machine has a camera named like that";
  EXPECT_EQ(s.code(), Code::kNotFound) << s.message();
  EXPECT_NE(std::string(s.message()).find("/base/no/such/camera"), std::string::npos)
      << s.message();
  sensor.Stop();
  EXPECT_EQ(sensor.Configure(config, &mode).code(), Code::kNotFound);  // still answers
}

// What the daemon logs before "ready" when libcamera lacks the camera.
TEST(LibcameraSensorTest, ProbeNamesTheMissingCamera) {
  {
    LibcameraOptions options;
    options.camera_id = "/base/no/such/camera";
    LibcameraSensor sensor(options);
    Status s = sensor.Probe();
    EXPECT_EQ(s.code(), Code::kNotFound) << s.message();
    const std::string m = s.message();
    EXPECT_EQ(m.rfind("libcamera: no camera '/base/no/such/camera' (found: ", 0), 0u) << m;
    EXPECT_EQ(sensor.Probe().code(), Code::kNotFound);  // asked again, the same answer
  }
  LibcameraSensor any(LibcameraOptions{});
  Status s = any.Probe();
  if (s.ok()) GTEST_SKIP() << "this machine has a camera";
  EXPECT_EQ(s.code(), Code::kNotFound);
  EXPECT_STREQ(s.message(), "libcamera: no camera found");
}

}  // namespace
}  // namespace lb
