// The libcamera sensor's pieces that need no camera: format choice, the exposure hold, and the
// errors of a machine without cameras (the build host). Where libcamera's versions differ, the
// expectations follow the version its headers declare (libcamera_version.h).
#include <gtest/gtest.h>
#include <libcamera/control_ids.h>
#include <libcamera/formats.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "hal/libcamera/exposure_hold.h"
#include "hal/libcamera/libcamera_format.h"
#include "hal/libcamera/libcamera_sensor.h"
#include "hal/libcamera/libcamera_version.h"

namespace lb {
namespace {

namespace f = libcamera::formats;
namespace c = libcamera::controls;

TEST(LibcameraVersionTest, TheMacroReadsTheHeadersVersion) {
  printf("libcamera headers: %d.%d.%d\n", LIBCAMERA_VERSION_MAJOR, LIBCAMERA_VERSION_MINOR,
         LIBCAMERA_VERSION_PATCH);
  EXPECT_TRUE(LB_LIBCAMERA_AT_LEAST(0, 0, 3));
  EXPECT_TRUE(LB_LIBCAMERA_AT_LEAST(LIBCAMERA_VERSION_MAJOR, LIBCAMERA_VERSION_MINOR,
                                    LIBCAMERA_VERSION_PATCH));
  EXPECT_FALSE(LB_LIBCAMERA_AT_LEAST(LIBCAMERA_VERSION_MAJOR, LIBCAMERA_VERSION_MINOR,
                                     LIBCAMERA_VERSION_PATCH + 1));
  EXPECT_FALSE(LB_LIBCAMERA_AT_LEAST(LIBCAMERA_VERSION_MAJOR, LIBCAMERA_VERSION_MINOR + 1, 0));
}

TEST(LibcameraFormatTest, DrmNamedRgbMapsByMemoryOrder) {
  PixelFormat out;
  ASSERT_TRUE(LibcameraToPixelFormat(f::BGR888, &out));
  EXPECT_EQ(out, PixelFormat::kRgb8);  // R, G, B in memory
  ASSERT_TRUE(LibcameraToPixelFormat(f::RGB888, &out));
  EXPECT_EQ(out, PixelFormat::kBgr8);
  ASSERT_TRUE(LibcameraToPixelFormat(f::XBGR8888, &out));
  EXPECT_EQ(out, PixelFormat::kRgbx8);  // R, G, B, X in memory
  ASSERT_TRUE(LibcameraToPixelFormat(f::XRGB8888, &out));
  EXPECT_EQ(out, PixelFormat::kBgrx8);  // B, G, R, X
  ASSERT_TRUE(LibcameraToPixelFormat(f::YUYV, &out));
  EXPECT_EQ(out, PixelFormat::kYuyv);
  ASSERT_TRUE(LibcameraToPixelFormat(f::NV12, &out));
  EXPECT_EQ(out, PixelFormat::kNv12);
  ASSERT_TRUE(LibcameraToPixelFormat(f::YUV420, &out));
  EXPECT_EQ(out, PixelFormat::kI420);
  EXPECT_FALSE(LibcameraToPixelFormat(f::YVU420, &out));  // V before U
  EXPECT_FALSE(LibcameraToPixelFormat(f::NV21, &out));
  EXPECT_FALSE(LibcameraToPixelFormat(f::SBGGR10, &out));
  EXPECT_FALSE(LibcameraToPixelFormat(f::MJPEG, &out));
}

TEST(LibcameraFormatTest, KeepsAReadableDefaultElsePrefersFewerBytes) {
  EXPECT_EQ(ChooseLibcameraFormat(f::BGR888, {f::YUYV, f::BGR888}), f::BGR888);
  EXPECT_EQ(ChooseLibcameraFormat(f::YUV420, {f::NV12, f::YUV420}), f::YUV420);
  EXPECT_EQ(ChooseLibcameraFormat(f::XRGB8888, {f::YUV420, f::XRGB8888}), f::XRGB8888);
  EXPECT_EQ(ChooseLibcameraFormat(f::SBGGR10, {f::RGB888, f::NV12, f::SBGGR10}), f::NV12);
  EXPECT_EQ(ChooseLibcameraFormat(f::SBGGR10, {f::XRGB8888, f::RGB888, f::YUV420}), f::YUV420);
  EXPECT_EQ(ChooseLibcameraFormat(f::MJPEG, {f::XRGB8888, f::RGB888, f::MJPEG}), f::RGB888);
  EXPECT_EQ(ChooseLibcameraFormat(f::MJPEG, {f::XRGB8888, f::XBGR8888}), f::XBGR8888);
  EXPECT_EQ(ChooseLibcameraFormat(f::MJPEG, {f::XRGB8888, f::MJPEG}), f::XRGB8888);
  EXPECT_FALSE(ChooseLibcameraFormat(f::MJPEG, {f::SBGGR10, f::MJPEG}).isValid());
}

TEST(LibcameraFormatTest, FullRangeOnlyWhereTheColourSpaceSaysSo) {
  using libcamera::ColorSpace;
  EXPECT_EQ(LibcameraYuvRange(ColorSpace::Sycc), YuvRange::kFull);  // Raspberry Pi's stills
  EXPECT_EQ(LibcameraYuvRange(ColorSpace::Smpte170m), YuvRange::kLimited);
  EXPECT_EQ(LibcameraYuvRange(ColorSpace::Rec709), YuvRange::kLimited);
  EXPECT_EQ(LibcameraYuvRange(std::nullopt), YuvRange::kLimited);
}

// Controls a test camera lists.
enum Listed : unsigned {
  kAeEnable = 1,
  kExposureTime = 2,
  kAnalogueGain = 4,
  kAwbEnable = 8,
  kColourGains = 16,
  kModes = 32,  // ExposureTimeMode and AnalogueGainMode (libcamera 0.5 on)
  kExposureTimeMode = 64,
};

libcamera::ControlInfoMap Available(unsigned listed) {
  libcamera::ControlInfoMap::Map map;
  if (listed & kAeEnable) map.emplace(&c::AeEnable, libcamera::ControlInfo(false, true));
  if (listed & kExposureTime) map.emplace(&c::ExposureTime, libcamera::ControlInfo(100, 100000));
  if (listed & kAnalogueGain) map.emplace(&c::AnalogueGain, libcamera::ControlInfo(1.0f, 16.0f));
  if (listed & kAwbEnable) map.emplace(&c::AwbEnable, libcamera::ControlInfo(false, true));
  if (listed & kColourGains) map.emplace(&c::ColourGains, libcamera::ControlInfo(0.0f, 32.0f));
#if LB_LIBCAMERA_AT_LEAST(0, 5, 0)
  if (listed & (kModes | kExposureTimeMode)) {
    map.emplace(&c::ExposureTimeMode, libcamera::ControlInfo(0, 1));
  }
  if (listed & kModes) map.emplace(&c::AnalogueGainMode, libcamera::ControlInfo(0, 1));
#endif
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

// The ids a request's ControlList carries, sorted.
std::vector<unsigned> Ids(const libcamera::ControlList& list) {
  std::vector<unsigned> ids;
  for (const auto& entry : list) ids.push_back(entry.first);
  std::sort(ids.begin(), ids.end());
  return ids;
}

std::vector<unsigned> Ids(std::vector<const libcamera::ControlId*> controls) {
  std::vector<unsigned> ids;
  for (const libcamera::ControlId* id : controls) ids.push_back(id->id());
  std::sort(ids.begin(), ids.end());
  return ids;
}

// The metered values, fixed in `out`.
void ExpectMeteredValues(const libcamera::ControlList& out, bool white_balance) {
  EXPECT_EQ(out.get(c::ExposureTime), std::optional<int32_t>(12345));
  EXPECT_EQ(out.get(c::AnalogueGain), std::optional<float>(2.5f));
  if (!white_balance) return;
  EXPECT_EQ(out.get(c::AwbEnable), std::optional<bool>(false));
  auto gains = out.get(c::ColourGains);
  ASSERT_TRUE(gains);
  EXPECT_FLOAT_EQ((*gains)[0], 1.8f);
  EXPECT_FLOAT_EQ((*gains)[1], 1.4f);
}

// A camera whose automatic exposure stops with AeEnable (every pipeline before 0.5, and a
// 0.5 pipeline that lists AeEnable without the modes): one list holds all three.
TEST(ExposureHoldTest, AeEnableCameraHoldsAllThreeInOneList) {
  libcamera::ControlList out(c::controls);
  HeldControls held =
      HoldExposure(Available(kAeEnable | kExposureTime | kAnalogueGain | kAwbEnable | kColourGains),
                   Metered(), &out);
  EXPECT_TRUE(held.exposure);
  EXPECT_TRUE(held.gain);
  EXPECT_TRUE(held.white_balance);
  EXPECT_STREQ(held.note, "");
  EXPECT_EQ(Ids(out), Ids({&c::AeEnable, &c::ExposureTime, &c::AnalogueGain, &c::AwbEnable,
                           &c::ColourGains}));
  EXPECT_EQ(out.get(c::AeEnable), std::optional<bool>(false));
  ExpectMeteredValues(out, true);
}

#if LB_LIBCAMERA_AT_LEAST(0, 5, 0)
// Raspberry Pi and rkisp1 from 0.5: the two modes and AeEnable, every one set.
TEST(ExposureHoldTest, ModeCameraHoldsWithBothModesManual) {
  libcamera::ControlList out(c::controls);
  HeldControls held = HoldExposure(
      Available(kModes | kAeEnable | kExposureTime | kAnalogueGain | kAwbEnable | kColourGains),
      Metered(), &out);
  EXPECT_TRUE(held.exposure && held.gain && held.white_balance);
  EXPECT_STREQ(held.note, "");
  EXPECT_EQ(Ids(out), Ids({&c::ExposureTimeMode, &c::AnalogueGainMode, &c::AeEnable,
                           &c::ExposureTime, &c::AnalogueGain, &c::AwbEnable, &c::ColourGains}));
  EXPECT_EQ(out.get(c::ExposureTimeMode), std::optional<int32_t>(c::ExposureTimeModeManual));
  EXPECT_EQ(out.get(c::AnalogueGainMode), std::optional<int32_t>(c::AnalogueGainModeManual));
  EXPECT_EQ(out.get(c::AeEnable), std::optional<bool>(false));
  ExpectMeteredValues(out, true);
}
#endif

// A UVC camera: from 0.5 it lists ExposureTimeMode and not AeEnable, before it AeEnable; it has
// no colour gains. Exposure and gain are held all the same, and the missing white balance is
// said.
TEST(ExposureHoldTest, UvcCameraHoldsExposureAndGainAndSaysWhiteBalanceDrifts) {
#if LB_LIBCAMERA_AT_LEAST(0, 5, 0)
  const libcamera::ControlInfoMap available =
      Available(kExposureTimeMode | kExposureTime | kAnalogueGain);
  const std::vector<unsigned> want =
      Ids({&c::ExposureTimeMode, &c::ExposureTime, &c::AnalogueGain});
#else
  const libcamera::ControlInfoMap available = Available(kAeEnable | kExposureTime | kAnalogueGain);
  const std::vector<unsigned> want = Ids({&c::AeEnable, &c::ExposureTime, &c::AnalogueGain});
#endif
  EXPECT_TRUE(CanHoldAny(available));  // so the sensor meters it
  libcamera::ControlList out(c::controls);
  HeldControls held = HoldExposure(available, Metered(), &out);
  EXPECT_TRUE(held.exposure);
  EXPECT_TRUE(held.gain);
  EXPECT_FALSE(held.white_balance);
  EXPECT_EQ(Ids(out), want);
#if LB_LIBCAMERA_AT_LEAST(0, 5, 0)
  EXPECT_EQ(out.get(c::ExposureTimeMode), std::optional<int32_t>(c::ExposureTimeModeManual));
#else
  EXPECT_EQ(out.get(c::AeEnable), std::optional<bool>(false));
#endif
  ExpectMeteredValues(out, false);
  EXPECT_STREQ(held.note,
               "cannot hold white balance (no AwbEnable or ColourGains control) across the "
               "burst: it may drift from frame to frame");
}

// A camera offering none of the controls: nothing set, nothing metered, and one log line.
TEST(ExposureHoldTest, ACameraHoldingNothingIsLoggedOnce) {
  const libcamera::ControlInfoMap available = Available(0);
  EXPECT_FALSE(CanHoldAny(available));
  libcamera::ControlList out(c::controls);
  HeldControls held = HoldExposure(available, Metered(), &out);
  EXPECT_FALSE(held.exposure || held.gain || held.white_balance);
  EXPECT_TRUE(out.empty());

  std::vector<std::string> lines;
  HoldReporter reporter(
      [](void* context, const char* line) {
        static_cast<std::vector<std::string>*>(context)->push_back(line);
      },
      &lines);
  reporter.Note("/base/cam0", held);
  reporter.Note("/base/cam0", held);  // the next burst: said already
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0],
            "libcamera /base/cam0: cannot hold exposure (no ExposureTime control), gain (no "
            "AnalogueGain control) and white balance (no AwbEnable or ColourGains control) "
            "across the burst: they may drift from frame to frame");
  reporter.Reset();  // configured again
  reporter.Note("/base/cam0", held);
  EXPECT_EQ(lines.size(), 2u);
  reporter.Note("/base/cam0", HeldControls());  // everything held: nothing to say
  EXPECT_EQ(lines.size(), 2u);
}

// Some controls listed, others not, or not reported by the metered frame: what is there is
// held, the rest is named.
TEST(ExposureHoldTest, SetsNothingTheCameraLacksAndNamesIt) {
  libcamera::ControlList out(c::controls);
  HeldControls held =
      HoldExposure(Available(kAeEnable | kExposureTime | kAwbEnable), Metered(), &out);
  EXPECT_TRUE(held.exposure);
  EXPECT_FALSE(held.gain);
  EXPECT_FALSE(held.white_balance);
  EXPECT_EQ(Ids(out), Ids({&c::AeEnable, &c::ExposureTime}));
  EXPECT_STREQ(held.note,
               "cannot hold gain (no AnalogueGain control) and white balance (no ColourGains "
               "control) across the burst: they may drift from frame to frame");
}

TEST(ExposureHoldTest, NoMeteredValueNoHold) {
  libcamera::ControlList out(c::controls);
  libcamera::ControlList empty(c::controls);
  HeldControls held =
      HoldExposure(Available(kAeEnable | kExposureTime | kAnalogueGain | kAwbEnable | kColourGains),
                   empty, &out);
  EXPECT_FALSE(held.exposure || held.gain || held.white_balance);
  EXPECT_TRUE(out.empty());  // the algorithms keep running rather than freeze on unread values
  EXPECT_NE(std::string(held.note).find("exposure (the metered frame reports no ExposureTime)"),
            std::string::npos)
      << held.note;
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
