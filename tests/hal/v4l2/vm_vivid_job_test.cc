// Runs inside the throw-away VM (tests/vm): a whole refocus job on vivid frames, from the V4L2
// sensor through the pipeline into a JPEG on storage, and the job surviving a sensor that stops
// delivering (nothing left under the final name, the next job works).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "firmware/app/job.h"
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

bool SetDropPercent(const std::string& device, int32_t value) {
  int fd = open(device.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0) return false;
  v4l2_query_ext_ctrl q;
  memset(&q, 0, sizeof(q));
  q.id = V4L2_CTRL_FLAG_NEXT_CTRL;
  bool done = false;
  while (ioctl(fd, VIDIOC_QUERY_EXT_CTRL, &q) == 0) {
    if (strcmp(q.name, "Percentage of Dropped Buffers") == 0) {
      v4l2_control c = {q.id, value};
      done = ioctl(fd, VIDIOC_S_CTRL, &c) == 0;
      break;
    }
    q.id |= V4L2_CTRL_FLAG_NEXT_CTRL;
  }
  close(fd);
  return done;
}

std::vector<uint8_t> ReadFile(const char* path) {
  std::vector<uint8_t> bytes;
  FILE* f = fopen(path, "rb");
  if (!f) return bytes;
  uint8_t buffer[65536];
  size_t n;
  while ((n = fread(buffer, 1, sizeof(buffer), f)) > 0)
    bytes.insert(bytes.end(), buffer, buffer + n);
  fclose(f);
  return bytes;
}

TEST(VividJobTest, BurstFromVividBecomesARefocusedJpeg) {
  std::string device = FindVivid();
  if (device.empty()) {
    if (getenv("LB_REQUIRE_DEVICES")) FAIL() << "no vivid capture node";
    GTEST_SKIP() << "no vivid capture node";
  }
  ASSERT_TRUE(SetDropPercent(device, 0));
  V4l2Options options;
  options.device = device.c_str();
  options.fps = 5;
  V4l2Sensor sensor(options);
  JobOptions job_options;
  job_options.sensor.width = 320;  // a vivid webcam size small enough for emulated depth
  job_options.sensor.height = 180;
  job_options.sensor.frames = 5;
  job_options.sensor.timeout_ms = 1500;
  // Depth at 160x90 with 12 labels: the VM emulates the CPU, and this test is about the path
  // from driver to file, not about depth quality.
  job_options.pipeline.max_working_width = 160;
  job_options.pipeline.max_working_height = 120;
  job_options.pipeline.labels = 12;
  job_options.model = "vivid";
  Job job;
  Status s = job.Configure(&sensor, job_options);
  ASSERT_TRUE(s.ok()) << s.message();

  const char* out = "/tmp/vivid.jpg";
  JobReport report;
  s = job.Run(out, &report);
  ASSERT_TRUE(s.ok()) << s.message();
  std::vector<uint8_t> jpeg = ReadFile(out);
  ASSERT_GT(jpeg.size(), 1000u);
  EXPECT_EQ(jpeg[0], 0xFF);
  EXPECT_EQ(jpeg[1], 0xD8);  // SOI
  EXPECT_EQ(jpeg[jpeg.size() - 2], 0xFF);
  EXPECT_EQ(jpeg[jpeg.size() - 1], 0xD9);  // EOI
  printf("vivid job: %dx%d -> %s, %zu bytes; capture %.2f s, depth %.2f s, render %.2f s\n",
         report.width, report.height, out, jpeg.size(), report.capture_s, report.depth_s,
         report.render_s);

  // The sensor stops delivering: the job fails with a timeout and leaves nothing behind.
  const char* lost = "/tmp/stalled.jpg";
  ASSERT_TRUE(SetDropPercent(device, 100));
  s = job.Run(lost, &report);
  EXPECT_EQ(s.code(), Code::kTimeout) << s.message();
  printf("stalled job: %s\n", s.message());
  struct stat st;
  EXPECT_NE(stat(lost, &st), 0) << "a failed job left " << lost;
  ASSERT_TRUE(SetDropPercent(device, 0));
  s = job.Run(lost, &report);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(stat(lost, &st), 0);
}

}  // namespace
}  // namespace lb
