// Runs inside the throw-away VM (tests/vm) with vimc: a whole refocus job from frames captured
// through libcamera, written as a JPEG.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <vector>

#include "firmware/app/job.h"
#include "hal/libcamera/libcamera_sensor.h"

namespace lb {
namespace {

TEST(VimcJobTest, BurstThroughLibcameraBecomesAJpeg) {
  LibcameraOptions sensor_options;
  sensor_options.log = [](void*, const char* line) { printf("%s\n", line); };
  LibcameraSensor sensor(sensor_options);
  JobOptions options;
  options.sensor.width = 640;
  options.sensor.height = 480;
  options.sensor.frames = 5;
  options.sensor.timeout_ms = 5000;
  // Small depth problem: the VM emulates the CPU; this test is about the path to the file.
  options.pipeline.max_working_width = 160;
  options.pipeline.max_working_height = 120;
  options.pipeline.labels = 12;
  options.model = "vimc";
  Job job;
  Status s = job.Configure(&sensor, options);
  if (s.code() == Code::kNotFound && !getenv("LB_REQUIRE_DEVICES")) GTEST_SKIP() << s.message();
  ASSERT_TRUE(s.ok()) << s.message();
  const char* out = "/tmp/vimc.jpg";
  JobReport report;
  s = job.Run(out, &report);
  ASSERT_TRUE(s.ok()) << s.message();
  FILE* f = fopen(out, "rb");
  ASSERT_NE(f, nullptr);
  std::vector<uint8_t> jpeg(1 << 20);
  jpeg.resize(fread(jpeg.data(), 1, jpeg.size(), f));
  fclose(f);
  ASSERT_GT(jpeg.size(), 1000u);
  EXPECT_EQ(jpeg[0], 0xFF);
  EXPECT_EQ(jpeg[1], 0xD8);
  EXPECT_EQ(jpeg[jpeg.size() - 2], 0xFF);
  EXPECT_EQ(jpeg[jpeg.size() - 1], 0xD9);
  printf("vimc job: %dx%d -> %s, %zu bytes; capture %.2f s, depth %.2f s, render %.2f s\n",
         report.width, report.height, out, jpeg.size(), report.capture_s, report.depth_s,
         report.render_s);
}

}  // namespace
}  // namespace lb
