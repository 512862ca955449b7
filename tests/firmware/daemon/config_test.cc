// refocusd's configuration file: what an installer or a user editing /etc/refocusd.conf sees.
#include "firmware/daemon/config.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "firmware/app/focus.h"
#include "firmware/app/settings.h"
#include "tests/firmware/codecs/jpeg_test_util.h"

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
  EXPECT_EQ(parsed.job.sensor.width, d.job.sensor.width);
  EXPECT_EQ(parsed.job.sensor.height, d.job.sensor.height);
  EXPECT_EQ(parsed.job.sensor.frames, d.job.sensor.frames);
  EXPECT_EQ(parsed.frame_timeout_ms, d.frame_timeout_ms);
  EXPECT_EQ(parsed.button, d.button);
  EXPECT_EQ(parsed.busy, d.busy);
  EXPECT_EQ(parsed.capture_retries, d.capture_retries);
  EXPECT_EQ(parsed.output_dir, d.output_dir);
  EXPECT_EQ(parsed.job.quality, d.job.quality);
  EXPECT_EQ(parsed.job.pipeline.labels, d.job.pipeline.labels);
  EXPECT_EQ(parsed.job.render.f_number, d.job.render.f_number);
  EXPECT_EQ(parsed.job.render.aperture.blades, d.job.render.aperture.blades);
  EXPECT_EQ(parsed.job.render.focus.width, 0);
  EXPECT_EQ(parsed.log_level, d.log_level);
}

TEST(ConfigTest, EveryKeyIsDocumentedInTheShippedFile) {
  const std::vector<uint8_t> bytes = test::ReadFile(DefaultConfigPath());
  const std::string text(bytes.begin(), bytes.end());
  int keys = 0;
  for (int i = 0; ConfigKeyName(i) != nullptr; ++i, ++keys) {
    // The web keys are shown commented out (the web side stays off until a token is chosen).
    const std::string line = std::string("\n") + ConfigKeyName(i) + " = ";
    const std::string commented = std::string("\n# ") + ConfigKeyName(i) + " = ";
    EXPECT_TRUE(text.find(line) != std::string::npos || text.find(commented) != std::string::npos)
        << ConfigKeyName(i) << " is not in the file";
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
  EXPECT_EQ(c.job.sensor.width, 640);
  EXPECT_EQ(c.job.sensor.height, 480);
  EXPECT_EQ(c.job.sensor.frames, 7);
  EXPECT_EQ(c.frame_timeout_ms, 500);
  EXPECT_EQ(c.busy, BusyPolicy::kRefuse);
  EXPECT_EQ(c.output_dir, "/media/card/DCIM");
  EXPECT_EQ(c.job.render.focus.x, 10);
  EXPECT_EQ(c.job.render.focus.height, 40);
  EXPECT_FLOAT_EQ(c.job.render.f_number, 1.4f);
  EXPECT_EQ(c.job.render.aperture.blades, 6);
  EXPECT_EQ(c.log_level, LogLevel::kDebug);

  const JobOptions o = MakeJobOptions(c);
  EXPECT_EQ(o.sensor.width, 640);
  EXPECT_EQ(o.sensor.frames, 7);
  EXPECT_EQ(o.sensor.timeout_ms, 500);
  EXPECT_EQ(o.render.aperture.blades, 6);
  EXPECT_EQ(o.replace, AtomicFile::Replace::kNever) << "a camera's photo never goes over another";
  EXPECT_EQ(JobOptions{}.replace, AtomicFile::Replace::kRegularFile) << "refocus run --out";
}

TEST(ConfigTest, GeometryAndLensReachTheJob) {
  DaemonConfig c;
  EXPECT_EQ(MakeJobOptions(c).pipeline.geometry, ViewGeometry::kAuto) << "a camera is handheld";
  ASSERT_TRUE(Parse("geometry = rectified\nfocal_35mm = 28\n", &c).ok());
  const JobOptions o = MakeJobOptions(c);
  EXPECT_EQ(o.pipeline.geometry, ViewGeometry::kRectified);
  EXPECT_EQ(o.focal_35mm, 28);
  EXPECT_EQ(Error("geometry = tripod\n"),
            "test.conf:1: geometry: 'tripod' is neither auto nor rectified");
  EXPECT_EQ(Error("focal_35mm = 4\n"),
            "test.conf:1: focal_35mm: '4' is neither 0 (unknown) nor a focal length from 8 to "
            "2000 mm");
  EXPECT_EQ(Error("focal_35mm = 9000\n"),
            "test.conf:1: focal_35mm: '9000' is neither 0 (unknown) nor a focal length from 8 to "
            "2000 mm");
}

TEST(ConfigTest, NativeResolutionAutoDeviceAndPointFocus) {
  DaemonConfig c;
  c.device = "/dev/video9";
  ASSERT_TRUE(Parse("resolution = native\ndevice = auto\nfocus = point 50,60\n", &c).ok());
  EXPECT_EQ(c.job.sensor.width, 0);
  EXPECT_EQ(c.job.sensor.height, 0);
  EXPECT_EQ(c.device, "");
  // A point means what it means on the command line (firmware/app/focus.h).
  const FocusRegion cli = FocusAtPoint(50, 60);
  EXPECT_EQ(c.job.render.focus.x, cli.x);
  EXPECT_EQ(c.job.render.focus.y, cli.y);
  EXPECT_EQ(c.job.render.focus.width, cli.width);
  EXPECT_EQ(c.job.render.focus.height, cli.height);
  EXPECT_EQ(cli.width, 2 * kFocusPointHalfSide);
}

TEST(ConfigTest, ErrorsNameTheFileTheLineAndTheProblem) {
  EXPECT_EQ(Error("frames = 5\n\nburst = 3\n"), "test.conf:3: unknown key 'burst'");
  // No integer overflow turns a size into another one.
  EXPECT_EQ(Error("resolution = 4294967616x240\n"),
            "test.conf:1: resolution: '4294967616x240' is neither native nor WxH between 16x16 "
            "and 8192x8192");
  EXPECT_EQ(Error("frames 5\n"), "test.conf:1: 'frames 5' is not 'key = value'");
  EXPECT_EQ(Error("frames = 5\nframes = 6\n"), "test.conf:2: frames is already set on line 1");
  EXPECT_EQ(Error("quality =\n"), "test.conf:1: quality has no value");
  EXPECT_EQ(Error("frames = 40\n"), "test.conf:1: frames: '40' is not a whole number from 2 to 16");
  EXPECT_EQ(Error("frames = 5x\n"), "test.conf:1: frames: '5x' is not a whole number from 2 to 16");
  EXPECT_EQ(Error("backend = usb\n"),
            "test.conf:1: backend: 'usb' is none of: v4l2, libcamera, synthetic");
  EXPECT_EQ(Error("resolution = 640*480\n"),
            "test.conf:1: resolution: '640*480' is neither native nor WxH between 16x16 and "
            "8192x8192");
  EXPECT_EQ(Error("aperture = 2-blade\n"),
            "test.conf:1: aperture: '2-blade' is none of: disc, N-blade, polygon:N with N from 3 "
            "to 12");
  EXPECT_EQ(Error("f_number = nan\n"), "test.conf:1: f_number: 'nan' is not a number from 1 to 22");
  EXPECT_EQ(Error("busy_press = drop\n"),
            "test.conf:1: busy_press: 'drop' is neither queue nor refuse");
  EXPECT_EQ(Error("focus = middle\n"),
            "test.conf:1: focus: 'middle' is none of: center, X,Y (a point), X,Y,W,H (a "
            "rectangle), in pixels of the photo");
  EXPECT_EQ(Error("log_level = loud\n"),
            "test.conf:1: log_level: 'loud' is none of: debug, info, warning, error");
  EXPECT_EQ(Error("resolution = 320x240\n# x\nfocus = region 330,10,40,40\n"),
            "test.conf:3: focus: the focus region 330,10,40,40 lies outside the 320x240 photo");
  EXPECT_EQ(Error("f-number = 2\n"), "test.conf:1: unknown key 'f-number'");
  EXPECT_EQ(Error("size = 320x240\n"), "test.conf:1: unknown key 'size'");
}

// One parser for the command line and the file: every shared setting, given the same text under
// its two spellings, sets the same job.
TEST(ConfigTest, EverySharedSettingMeansWhatTheCommandLineMeans) {
  const char* const value_of[][2] = {
      {"focus", "100,80"},
      {"f-number", "1.8"},
      {"aperture", "polygon:7"},
      {"aperture-rotation", "15"},
      {"blade-curvature", "0.5"},
      {"highlight-threshold", "200"},
      {"highlight-gain", "3"},
      {"max-blur-radius", "40"},
      {"quality", "80"},
      {"resolution", "640x480"},
      {"frames", "7"},
      {"geometry", "rectified"},
      {"focal-35mm", "28"},
      {"labels", "48"},
      {"working-size", "320x240"},
      {"threads", "3"},
  };
  int covered = 0;
  for (const auto& [name, value] : value_of) {
    SCOPED_TRACE(name);
    const Setting* s = FindSetting(name);
    ASSERT_NE(s, nullptr);
    JobOptions cli = DaemonConfig().job;
    std::string why;
    ASSERT_TRUE(s->parse(value, &cli, &why)) << why;
    std::string key = name;
    for (char& ch : key) ch = ch == '-' ? '_' : ch;
    DaemonConfig c;
    const Status st = Parse((key + " = " + value + "\n").c_str(), &c);
    ASSERT_TRUE(st.ok()) << st.message();
    const JobOptions& conf = c.job;
    EXPECT_EQ(conf.render.focus.x, cli.render.focus.x);
    EXPECT_EQ(conf.render.focus.width, cli.render.focus.width);
    EXPECT_EQ(conf.render.f_number, cli.render.f_number);
    EXPECT_EQ(conf.render.aperture.blades, cli.render.aperture.blades);
    EXPECT_EQ(conf.render.aperture.rotation_deg, cli.render.aperture.rotation_deg);
    EXPECT_EQ(conf.render.aperture.curvature, cli.render.aperture.curvature);
    EXPECT_EQ(conf.render.highlight_threshold, cli.render.highlight_threshold);
    EXPECT_EQ(conf.render.highlight_gain, cli.render.highlight_gain);
    EXPECT_EQ(conf.pipeline.max_blur_radius, cli.pipeline.max_blur_radius);
    EXPECT_EQ(conf.quality, cli.quality);
    EXPECT_EQ(conf.sensor.width, cli.sensor.width);
    EXPECT_EQ(conf.sensor.frames, cli.sensor.frames);
    EXPECT_EQ(conf.pipeline.geometry, cli.pipeline.geometry);
    EXPECT_EQ(conf.focal_35mm, cli.focal_35mm);
    EXPECT_EQ(conf.pipeline.labels, cli.pipeline.labels);
    EXPECT_EQ(conf.pipeline.max_working_width, cli.pipeline.max_working_width);
    EXPECT_EQ(conf.threads, cli.threads);
    ++covered;
  }
  int settings = 0;
  while (SettingAt(settings) != nullptr) ++settings;
  EXPECT_EQ(covered, settings) << "a setting without a case here";
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

TEST(ConfigTest, WebIsOffUntilAnAddressAndATokenAreSet) {
  DaemonConfig c;
  EXPECT_FALSE(c.web_on());
  EXPECT_EQ(c.web_root, "/usr/share/refocusd/www");
  ASSERT_TRUE(Parse("web = 0.0.0.0:8080\nweb_token = 0123456789abcdef\n", &c).ok());
  EXPECT_TRUE(c.web_on());
  EXPECT_EQ(c.web_address, "0.0.0.0");
  EXPECT_EQ(c.web_port, 8080);
  EXPECT_EQ(c.web_token, "0123456789abcdef");
  DaemonConfig v6;
  ASSERT_TRUE(
      Parse("web = [::1]:8081\nweb_token = 0123456789abcdef\nweb_root = /srv/www\n", &v6).ok());
  EXPECT_EQ(v6.web_address, "::1");
  EXPECT_EQ(v6.web_port, 8081);
  EXPECT_EQ(v6.web_root, "/srv/www");
  DaemonConfig off;
  ASSERT_TRUE(Parse("web = off\n", &off).ok());
  EXPECT_FALSE(off.web_on());
}

TEST(ConfigTest, WebWithoutAGoodTokenIsRefusedAtLoad) {
  EXPECT_EQ(Error("frames = 5\nweb = 0.0.0.0:8080\n"),
            "test.conf:2: web is on but web_token is not set (16 to 128 characters; the page asks "
            "for it)");
  // Loopback too: another user of the board could reach it.
  EXPECT_EQ(Error("web = 127.0.0.1:8080\n"),
            "test.conf:1: web is on but web_token is not set (16 to 128 characters; the page asks "
            "for it)");
  EXPECT_EQ(Error("web_token = short\n"),
            "test.conf:1: web_token: 5 characters; it needs 16 to 128");
  EXPECT_EQ(Error("web_token = has a space in it ok\n"),
            "test.conf:1: web_token: only printable ASCII characters without spaces are allowed");
  EXPECT_EQ(Error("web = camera.local:80\n"),
            "test.conf:1: web: 'camera.local' is not a numeric IPv4 address (e.g. 0.0.0.0:8080 or "
            "[::]:8080)");
  EXPECT_EQ(Error("web = 0.0.0.0\n"),
            "test.conf:1: web: '0.0.0.0' is neither off nor ADDRESS:PORT");
  EXPECT_NE(Error("web = 0.0.0.0:70000\n").find("test.conf:1: web: port: "), std::string::npos);
  EXPECT_EQ(Error("web_root = www\n"), "test.conf:1: web_root: 'www' is not an absolute path");
  // A port the kernel picks anew at each start is one no browser can find.
  EXPECT_EQ(Error("frames = 5\nweb = [::]:0\n"),
            "test.conf:2: web: port 0 is not a port a browser can find; name one (e.g. 8080)");
}

TEST(ConfigTest, AByteOrderMarkIsNoPartOfTheFirstKey) {
  DaemonConfig c;
  Status s = Parse(
      "\xEF\xBB\xBF"
      "frames = 5\n",
      &c);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(c.job.sensor.frames, 5);
  // Only at the start: elsewhere it is part of a key, and the key is unknown.
  EXPECT_EQ(Error("frames = 5\n\xEF\xBB\xBF"
                  "labels = 8\n"),
            "test.conf:2: unknown key '\xEF\xBB\xBFlabels'");
}

}  // namespace
}  // namespace lb
