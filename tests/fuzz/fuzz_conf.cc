// libFuzzer target: refocusd.conf text through ParseConfig, over the defaults, as LoadConfig
// hands it over (at most 64 KiB, no NUL byte: LoadConfig refuses other files before parsing).
// A failure names the file and a line; a success holds only values the file documents and gives
// job options that point into the configuration.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "firmware/daemon/config.h"

namespace {

#define CONF_REQUIRE(cond, ...)                                     \
  do {                                                              \
    if (!(cond)) {                                                  \
      fprintf(stderr, "broken invariant: " #cond ": " __VA_ARGS__); \
      fprintf(stderr, "\n");                                        \
      abort();                                                      \
    }                                                               \
  } while (0)

constexpr size_t kMaxFileBytes = 64 * 1024;  // LoadConfig's limit
constexpr char kName[] = "fuzz.conf";

bool Within(int64_t v, int64_t lo, int64_t hi) { return v >= lo && v <= hi; }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > kMaxFileBytes || memchr(data, '\0', size) != nullptr) return 0;
  const std::string text(reinterpret_cast<const char*>(data), size);
  lb::DaemonConfig config;
  const lb::Status status = lb::ParseConfig(kName, text.c_str(), &config);
  if (!status.ok()) {
    // "fuzz.conf:LINE: ..." (every error is on a line: an empty file is valid).
    const char* m = status.message();
    CONF_REQUIRE(strncmp(m, kName, sizeof(kName) - 1) == 0 && m[sizeof(kName) - 1] == ':',
                 "message '%s'", m);
    CONF_REQUIRE(status.code() == lb::Code::kInvalidArgument, "code of '%s'", m);
    return 0;
  }
  const lb::DaemonConfig& c = config;
  CONF_REQUIRE((c.job.sensor.width == 0 && c.job.sensor.height == 0) ||
                   (Within(c.job.sensor.width, 16, 8192) && Within(c.job.sensor.height, 16, 8192)),
               "resolution %dx%d", c.job.sensor.width, c.job.sensor.height);
  CONF_REQUIRE(Within(c.job.sensor.frames, 2, lb::PipelineConfig::kMaxFrames), "frames %d",
               c.job.sensor.frames);
  CONF_REQUIRE(Within(c.fps, 0, 240), "fps %d", c.fps);
  CONF_REQUIRE(Within(c.frame_timeout_ms, 100, 60000), "frame_timeout_ms %d", c.frame_timeout_ms);
  CONF_REQUIRE(c.seed <= INT32_MAX, "seed %llu", static_cast<unsigned long long>(c.seed));
  CONF_REQUIRE(Within(c.debounce_ms, 0, 500), "debounce_ms %d", c.debounce_ms);
  CONF_REQUIRE(Within(c.capture_retries, 0, 5), "capture_retries %d", c.capture_retries);
  CONF_REQUIRE(Within(c.job.quality, 1, 100), "quality %d", c.job.quality);
  CONF_REQUIRE(c.make.size() <= 63 && c.model.size() <= 63, "make %zu, model %zu bytes",
               c.make.size(), c.model.size());
  CONF_REQUIRE(c.output_dir.size() <= 900, "output_dir %zu bytes", c.output_dir.size());
  CONF_REQUIRE(Within(c.job.pipeline.labels, 2, 256), "labels %d", c.job.pipeline.labels);
  CONF_REQUIRE(c.job.focal_35mm == 0 || Within(c.job.focal_35mm, 8, 2000), "focal_35mm %d",
               c.job.focal_35mm);
  CONF_REQUIRE(Within(c.job.pipeline.max_working_width, 16, 8192) &&
                   Within(c.job.pipeline.max_working_height, 16, 8192),
               "working_size %dx%d", c.job.pipeline.max_working_width,
               c.job.pipeline.max_working_height);
  CONF_REQUIRE(Within(c.job.pipeline.max_blur_radius, 0, 128), "max_blur_radius %d",
               c.job.pipeline.max_blur_radius);
  const lb::RenderParams& r = c.job.render;
  CONF_REQUIRE(r.f_number >= 1.0f && r.f_number <= 22.0f, "f_number %g",
               static_cast<double>(r.f_number));
  CONF_REQUIRE(r.aperture.blades == 0 || Within(r.aperture.blades, 3, 12), "blades %d",
               static_cast<int>(r.aperture.blades));
  CONF_REQUIRE(r.aperture.rotation_deg >= -360.0f && r.aperture.rotation_deg <= 360.0f,
               "aperture_rotation %g", static_cast<double>(r.aperture.rotation_deg));
  CONF_REQUIRE(r.aperture.curvature >= 0.0f && r.aperture.curvature <= 1.0f, "blade_curvature %g",
               static_cast<double>(r.aperture.curvature));
  CONF_REQUIRE(r.highlight_gain >= 1.0f && r.highlight_gain <= 8.0f, "highlight_gain %g",
               static_cast<double>(r.highlight_gain));
  // A chosen focus region is not wholly outside a picture of the configured size.
  const lb::FocusRegion& f = r.focus;
  if (c.job.sensor.width > 0 && f.width > 0) {
    CONF_REQUIRE(f.x < c.job.sensor.width && f.y < c.job.sensor.height,
                 "focus %d,%d,%d,%d in %dx%d", f.x, f.y, f.width, f.height, c.job.sensor.width,
                 c.job.sensor.height);
  }
  const lb::JobOptions job = lb::MakeJobOptions(c);
  CONF_REQUIRE(job.make == c.make.c_str() && job.model == c.model.c_str(), "make/model copied");
  CONF_REQUIRE(job.sensor.frames == c.job.sensor.frames && job.quality == c.job.quality,
               "job options");
  // The same text over the same defaults parses to the same settings.
  lb::DaemonConfig again;
  CONF_REQUIRE(lb::ParseConfig(kName, text.c_str(), &again).ok(), "second parse failed");
  CONF_REQUIRE(again.job.sensor.width == c.job.sensor.width &&
                   again.job.sensor.height == c.job.sensor.height && again.device == c.device &&
                   again.button == c.button && again.output_dir == c.output_dir,
               "second parse differs");
  return 0;
}
