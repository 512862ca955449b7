// What a Job reports of a photo's stages, which refocusd logs and `refocus run` prints.
#include <gtest/gtest.h>
#include <unistd.h>

#include <string>

#include "firmware/app/job.h"
#include "sim/synthetic/synthetic_sensor.h"

namespace lb {
namespace {

JobReport RunOnce(ViewGeometry scene, ViewGeometry depth) {
  SceneParams params;
  params.geometry = scene;
  SyntheticSensor sensor(params);
  JobOptions o;
  o.sensor.width = 640;  // a handheld burst's parallax needs some pixels
  o.sensor.height = 480;
  o.pipeline.labels = 16;
  o.pipeline.geometry = depth;
  Job job;
  JobReport report;
  EXPECT_TRUE(job.Configure(&sensor, o).ok());
  const std::string out = "/tmp/job_report_test_" + std::to_string(getpid()) + ".jpg";
  const Status s = job.Run(out.c_str(), &report);
  EXPECT_TRUE(s.ok()) << s.message();
  EXPECT_TRUE(report.warning.ok()) << report.warning.message();
  unlink(out.c_str());
  return report;
}

// A handheld burst's depth stage begins with the camera's motion: a part of it, not all.
TEST(JobReport, TheMotionEstimateIsPartOfTheDepthStage) {
  const JobReport r = RunOnce(ViewGeometry::kHandheld, ViewGeometry::kAuto);
  EXPECT_GT(r.capture_s, 0.0);
  EXPECT_GT(r.render_s, 0.0);
  EXPECT_GT(r.motion_s, 0.0);
  EXPECT_LT(r.motion_s, r.depth_s);
}

// Equally spaced views need no motion estimate: the labeling starts at once.
TEST(JobReport, RectifiedViewsSpendNextToNothingOnMotion) {
  const JobReport r = RunOnce(ViewGeometry::kRectified, ViewGeometry::kRectified);
  EXPECT_GE(r.motion_s, 0.0);
  EXPECT_LT(r.motion_s, 0.5 * r.depth_s);
}

}  // namespace
}  // namespace lb
