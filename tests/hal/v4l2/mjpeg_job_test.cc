// A photo from an MJPEG camera: the V4L2 sensor on the scripted device, through the pipeline, to
// a JPEG on storage, with a corrupt frame in the stream skipped on the way.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "firmware/app/job.h"
#include "hal/v4l2/v4l2_sensor.h"
#include "tests/firmware/codecs/jpeg_test_util.h"
#include "tests/hal/v4l2/fake_v4l2.h"
#include "tests/hal/v4l2/jpeg_frames.h"

namespace lb {
namespace {

struct Lines {
  std::vector<std::string> lines;
  static void Write(void* context, const char* line) {
    static_cast<Lines*>(context)->lines.push_back(line);
  }
};

TEST(MjpegJobTest, AnMjpegCameraGivesAPhoto) {
  constexpr int32_t kW = 320, kH = 240;
  const jpegtest::Rgb picture = jpegtest::TestPicture(kW, kH, 7);
  const std::vector<uint8_t> frame = jpegtest::WithoutHuffmanTables(jpegtest::Encode(picture, {}));
  ASSERT_FALSE(frame.empty());
  std::vector<uint8_t> cut(frame.begin(), frame.begin() + static_cast<ptrdiff_t>(frame.size() / 2));

  FakeV4l2 dev;
  dev.width = kW;
  dev.height = kH;
  dev.formats = {V4L2_PIX_FMT_MJPEG};
  dev.sizes = {{V4L2_PIX_FMT_MJPEG, kW, kH}};
  // The third frame of every stream is cut short in transfer.
  dev.jpeg_frames = {frame, frame, cut, frame, frame, frame, frame};
  Lines log;
  V4l2Options options;
  options.log = Lines::Write;
  options.log_context = &log;
  V4l2Sensor sensor(options, &dev);

  JobOptions job_options;
  job_options.sensor.width = kW;
  job_options.sensor.height = kH;
  job_options.sensor.frames = 5;
  job_options.sensor.timeout_ms = 500;
  job_options.pipeline.max_working_width = 160;
  job_options.pipeline.max_working_height = 120;
  job_options.pipeline.labels = 12;
  job_options.threads = 1;
  job_options.model = "MJPEG camera";
  Job job;
  Status s = job.Configure(&sensor, job_options);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(sensor.fourcc(), V4L2_PIX_FMT_MJPEG);

  test::ScratchDir dir;
  const std::string out = dir.Path("photo.jpg");
  JobReport report;
  s = job.Run(out.c_str(), &report);
  ASSERT_TRUE(s.ok()) << s.message();
  ASSERT_EQ(log.lines.size(), 1u) << "one log line for the skipped frame";
  EXPECT_NE(log.lines[0].find("frame"), std::string::npos) << log.lines[0];

  // Every view is the same picture: the photo is that picture, unblurred, through two JPEG
  // generations (the camera's and the photo's).
  int32_t w = 0, h = 0;
  std::vector<uint8_t> ycc;
  std::string error;
  ASSERT_TRUE(test::DecodeYcc(test::ReadFile(out), &w, &h, &ycc, &error)) << error;
  ASSERT_EQ(w, kW);
  ASSERT_EQ(h, kH);
  double sum = 0;
  for (int32_t y = 0; y < kH; ++y) {
    for (int32_t x = 0; x < kW; ++x) {
      const uint8_t* p = picture.at(x, y);
      const double luma = 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
      sum += std::fabs(luma - ycc[(size_t(y) * kW + x) * 3]);
    }
  }
  EXPECT_LT(sum / (kW * kH), 3.0) << "mean luma difference from the camera's picture";
}

}  // namespace
}  // namespace lb
