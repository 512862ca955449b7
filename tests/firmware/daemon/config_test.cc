// refocusd's configuration file: what an installer or a user editing /etc/refocusd.conf sees.
#include "firmware/daemon/config.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "firmware/app/focus.h"
#include "tests/firmware/jpeg/jpeg_test_util.h"

namespace lb {
namespace {

std::string DefaultConfigPath() {
  const char* root = getenv("LB_SOURCE_DIR");
  return std::string(root ? root : ".") + "/firmware/daemon/refocusd.conf";
}

Status Parse(const char* text, DaemonConfig* config) {
  return ParseConfig("test.conf", text, config);
}

std::string Error(const char* text) {
  DaemonConfig config;
  Status s = Parse(text, &config);
  EXPECT_FALSE(s.ok()) << text;
  EXPECT_EQ(s.code(), Code::kInvalidArgument);
  return s.message();
}

TEST(ConfigTest, ShippedFileParsesToTheDefaults) {
  DaemonConfig parsed;
  Status s = LoadConfig(DefaultConfigPath().c_str(), &parsed);
  ASSERT_TRUE(s.ok()) << s.message();
  const DaemonConfig d;
  EXPECT_EQ(parsed.backend, d.backend);
  EXPECT_EQ(parsed.device, d.device);
  EXPECT_EQ(parsed.width, d.width);
  EXPECT_EQ(parsed.height, d.height);
  EXPECT_EQ(parsed.frames, d.frames);
  EXPECT_EQ(parsed.frame_timeout_ms, d.frame_timeout_ms);
  EXPECT_EQ(parsed.button, d.button);
  EXPECT_EQ(parsed.busy, d.busy);
  EXPECT_EQ(parsed.capture_retries, d.capture_retries);
  EXPECT_EQ(parsed.output_dir, d.output_dir);
  EXPECT_EQ(parsed.quality, d.quality);
  EXPECT_EQ(parsed.labels, d.labels);
  EXPECT_EQ(parsed.render.f_number, d.render.f_number);
  EXPECT_EQ(parsed.render.aperture.blades, d.render.aperture.blades);
  EXPECT_EQ(parsed.render.focus.width, 0);
  EXPECT_EQ(parsed.log_level, d.log_level);
}

TEST(ConfigTest, EveryKeyIsDocumentedInTheShippedFile) {
  const std::vector<uint8_t> bytes = test::ReadFile(DefaultConfigPath());
  const std::string text(bytes.begin(), bytes.end());
  int keys = 0;
  for (int i = 0; ConfigKeyName(i) != nullptr; ++i, ++keys) {
    const std::string line = std::string("\n") + ConfigKeyName(i) + " = ";
    EXPECT_NE(text.find(line), std::string::npos) << ConfigKeyName(i) << " is not in the file";
  }
  EXPECT_GE(keys, 20);
}

TEST(ConfigTest, ValuesReachTheSettings) {
  DaemonConfig c;
  Status s = Parse(
      "# a comment\n"
      "\n"
      "  backend   =  synthetic  \n"
      "device = /dev/video4\n"
      "resolution = 640x480\n"
      "frames = 7\n"
      "frame_timeout_ms = 500\n"
      "busy_press = refuse\n"
      "output_dir = /media/card/DCIM\n"
      "focus = region 10,20,30,40\n"
      "f_number = 1.4\n"
      "aperture = 6-blade\n"
      "log_level = debug\n",
      &c);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(c.backend, Backend::kSynthetic);
  EXPECT_EQ(c.device, "/dev/video4");
  EXPECT_EQ(c.width, 640);
  EXPECT_EQ(c.height, 480);
  EXPECT_EQ(c.frames, 7);
  EXPECT_EQ(c.frame_timeout_ms, 500);
  EXPECT_EQ(c.busy, BusyPolicy::kRefuse);
  EXPECT_EQ(c.output_dir, "/media/card/DCIM");
  EXPECT_EQ(c.render.focus.x, 10);
  EXPECT_EQ(c.render.focus.height, 40);
  EXPECT_FLOAT_EQ(c.render.f_number, 1.4f);
  EXPECT_EQ(c.render.aperture.blades, 6);
  EXPECT_EQ(c.log_level, LogLevel::kDebug);

  const JobOptions o = MakeJobOptions(c);
  EXPECT_EQ(o.sensor.width, 640);
  EXPECT_EQ(o.sensor.frames, 7);
  EXPECT_EQ(o.sensor.timeout_ms, 500);
  EXPECT_EQ(o.render.aperture.blades, 6);
}

TEST(ConfigTest, GeometryAndLensReachTheJob) {
  DaemonConfig c;
  EXPECT_EQ(MakeJobOptions(c).pipeline.geometry, Geometry::kAuto) << "a camera is handheld";
  ASSERT_TRUE(Parse("geometry = rectified\nfocal_35mm = 28\n", &c).ok());
  const JobOptions o = MakeJobOptions(c);
  EXPECT_EQ(o.pipeline.geometry, Geometry::kRectified);
  EXPECT_EQ(o.focal_35mm, 28);
  EXPECT_EQ(Error("geometry = tripod\n"),
            "test.conf:1: geometry: 'tripod' is neither auto nor rectified");
  EXPECT_EQ(Error("focal_35mm = 4\n"), "test.conf:1: focal_35mm: 4 mm is no lens");
  EXPECT_EQ(Error("focal_35mm = 9000\n"),
            "test.conf:1: focal_35mm: '9000' is not a whole number from 0 to 2000");
}

TEST(ConfigTest, NativeResolutionAutoDeviceAndPointFocus) {
  DaemonConfig c;
  c.device = "/dev/video9";
  ASSERT_TRUE(Parse("resolution = native\ndevice = auto\nfocus = point 5,6\n", &c).ok());
  EXPECT_EQ(c.width, 0);
  EXPECT_EQ(c.height, 0);
  EXPECT_EQ(c.device, "");
  // Issue 13, defect 6: a point means what it means on the command line (firmware/app/focus.h).
  const FocusRegion cli = FocusAtPoint(5, 6);
  EXPECT_EQ(c.render.focus.x, cli.x);
  EXPECT_EQ(c.render.focus.y, cli.y);
  EXPECT_EQ(c.render.focus.width, cli.width);
  EXPECT_EQ(c.render.focus.height, cli.height);
  EXPECT_EQ(cli.width, 2 * kFocusPointHalfSide);
}

TEST(ConfigTest, ErrorsNameTheFileTheLineAndTheProblem) {
  EXPECT_EQ(Error("frames = 5\n\nburst = 3\n"), "test.conf:3: unknown key 'burst'");
  // Issue 13, defect 6: no integer overflow turns a size into another one.
  EXPECT_EQ(Error("resolution = 4294967616x240\n"),
            "test.conf:1: resolution: '4294967616x240' is not WxH between 16x16 and 8192x8192");
  EXPECT_EQ(Error("frames 5\n"), "test.conf:1: 'frames 5' is not 'key = value'");
  EXPECT_EQ(Error("frames = 5\nframes = 6\n"), "test.conf:2: frames is already set on line 1");
  EXPECT_EQ(Error("quality =\n"), "test.conf:1: quality has no value");
  EXPECT_EQ(Error("frames = 40\n"), "test.conf:1: frames: '40' is not a whole number from 2 to 16");
  EXPECT_EQ(Error("frames = 5x\n"), "test.conf:1: frames: '5x' is not a whole number from 2 to 16");
  EXPECT_EQ(Error("backend = usb\n"),
            "test.conf:1: backend: 'usb' is none of: v4l2, libcamera, synthetic");
  EXPECT_EQ(Error("resolution = 640*480\n"),
            "test.conf:1: resolution: '640*480' is not WxH between 16x16 and 8192x8192");
  EXPECT_EQ(Error("aperture = 2-blade\n"),
            "test.conf:1: aperture: '2-blade' is neither disc nor N-blade with N from 3 to 12");
  EXPECT_EQ(Error("f_number = nan\n"), "test.conf:1: f_number: 'nan' is not a number from 1 to 22");
  EXPECT_EQ(Error("busy_press = drop\n"),
            "test.conf:1: busy_press: 'drop' is neither queue nor refuse");
  EXPECT_EQ(Error("focus = middle\n"),
            "test.conf:1: focus: 'middle' is none of: center, point X,Y, region X,Y,W,H");
  EXPECT_EQ(Error("log_level = loud\n"),
            "test.conf:1: log_level: 'loud' is none of: debug, info, warning, error");
  EXPECT_EQ(Error("resolution = 320x240\n# x\nfocus = region 300,10,40,40\n"),
            "test.conf:3: focus lies outside the 320x240 picture");
}

TEST(ConfigTest, UnreadableFilesAreClearErrors) {
  DaemonConfig c;
  Status s = LoadConfig("/nonexistent/refocusd.conf", &c);
  EXPECT_EQ(s.code(), Code::kNotFound);
  EXPECT_STREQ(s.message(), "/nonexistent/refocusd.conf: cannot open: No such file or directory");

  test::ScratchDir dir;
  const std::string path = dir.Path("binary.conf");
  FILE* f = fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  fwrite("frames = 5\n\0\1\2", 1, 14, f);
  fclose(f);
  s = LoadConfig(path.c_str(), &c);
  EXPECT_EQ(s.code(), Code::kInvalidArgument);
  EXPECT_NE(std::string(s.message()).find("NUL byte"), std::string::npos) << s.message();
}

}  // namespace
}  // namespace lb
