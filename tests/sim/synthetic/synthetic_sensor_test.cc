#include "sim/synthetic/synthetic_sensor.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/support/alloc_counter.h"

namespace lb {
namespace {

// Stitches the strips into preallocated frames and checks the sink protocol.
class RecordingSink : public FrameSink {
 public:
  RecordingSink(int32_t w, int32_t h, int32_t frames)
      : w_(w), h_(h), frames_(size_t(frames), std::vector<uint8_t>(size_t(w) * h * 3)) {
    infos_.reserve(size_t(frames));
    infos_.resize(size_t(frames));
  }
  Status BeginFrame(const FrameInfo& info) override {
    if (in_frame_) return Status(Code::kInternal, "BeginFrame inside a frame");
    if (info.index != begun_ || info.width != w_ || info.height != h_)
      return Status(Code::kInternal, "unexpected frame %d %dx%d", info.index, info.width,
                    info.height);
    infos_[size_t(begun_++)] = info;
    in_frame_ = true;
    next_row_ = 0;
    return Status::Ok();
  }
  Status Rows(const FrameRows& rows) override {
    if (!in_frame_ || rows.y0 != next_row_ || rows.height <= 0 || rows.height > 16 ||
        rows.strides[0] < w_ * 3)
      return Status(Code::kInternal, "bad strip at row %d", rows.y0);
    if (rows.height != 16) short_strips_++;
    std::vector<uint8_t>& frame = frames_[size_t(begun_ - 1)];
    for (int32_t r = 0; r < rows.height; ++r)
      for (int32_t i = 0; i < w_ * 3; ++i)
        frame[size_t(rows.y0 + r) * w_ * 3 + i] = rows.planes[0][r * rows.strides[0] + i];
    next_row_ += rows.height;
    return Status::Ok();
  }
  Status EndFrame() override {
    if (!in_frame_ || next_row_ != h_) return Status(Code::kInternal, "short frame");
    in_frame_ = false;
    if (begun_ - 1 == fail_frame_) return Status(Code::kIoError, "sink full");
    return Status::Ok();
  }

  int32_t w_, h_;
  std::vector<std::vector<uint8_t>> frames_;
  std::vector<FrameInfo> infos_;
  int32_t begun_ = 0, next_row_ = 0, short_strips_ = 0, fail_frame_ = -1;
  bool in_frame_ = false;
};

TEST(SyntheticSensorTest, DefaultsTo1280x960FiveFrames) {
  SyntheticSensor sensor;
  SensorMode mode;
  ASSERT_TRUE(sensor.Configure(SensorConfig{0, 0, 0, 2000}, &mode).ok());
  EXPECT_EQ(mode.width, 1280);
  EXPECT_EQ(mode.height, 960);
  EXPECT_EQ(mode.frames, 5);
  EXPECT_EQ(mode.format, PixelFormat::kRgb8);
  EXPECT_EQ(sensor.scene().reference(), 2);
  EXPECT_STREQ(sensor.name(), "synthetic");
}

TEST(SyntheticSensorTest, DeliversTheSceneInStripsWithoutAllocating) {
  SyntheticSensor sensor;
  SensorMode mode;
  ASSERT_TRUE(sensor.Configure(SensorConfig{200, 150, 4, 2000}, &mode).ok());
  RecordingSink sink(200, 150, 4);
  const size_t before = testing::AllocationCount();
  const Status s = sensor.CaptureBurst(sink);
  const size_t during = testing::AllocationCount() - before;
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(during, 0u) << "allocations inside CaptureBurst";
  EXPECT_EQ(sink.begun_, 4);
  EXPECT_EQ(sink.short_strips_, 4);  // 150 = 9 x 16 + 6
  for (int32_t i = 0; i < 4; ++i) {
    EXPECT_EQ(sink.infos_[size_t(i)].timestamp_ns, i * int64_t{33'000'000});
    EXPECT_EQ(sink.infos_[size_t(i)].sequence, uint32_t(i));
    EXPECT_EQ(sink.infos_[size_t(i)].format, PixelFormat::kRgb8);
    std::vector<uint8_t> direct(size_t(200) * 150 * 3);
    ASSERT_TRUE(sensor.scene().RenderRows(i, 0, 150, direct.data(), 600).ok());
    EXPECT_EQ(sink.frames_[size_t(i)], direct) << "frame " << i;
  }
  EXPECT_NE(sink.frames_[0], sink.frames_[3]);
  // A second burst continues the sequence numbers and repeats the pixels.
  RecordingSink again(200, 150, 4);
  ASSERT_TRUE(sensor.CaptureBurst(again).ok());
  EXPECT_EQ(again.infos_[0].sequence, 4u);
  EXPECT_EQ(again.frames_, sink.frames_);
}

TEST(SyntheticSensorTest, HandheldParamsReachTheScene) {
  SceneParams params;
  params.geometry = ViewGeometry::kHandheld;
  SyntheticSensor sensor(params);
  ASSERT_TRUE(sensor.Configure(SensorConfig{64, 48, 3, 2000}, nullptr).ok());
  EXPECT_EQ(sensor.scene().params().geometry, ViewGeometry::kHandheld);
  EXPECT_NE(sensor.scene().pose(0).rotation[0][1], 0);
}

TEST(SyntheticSensorTest, ReportsSinkErrorsAndBadConfigs) {
  SyntheticSensor sensor;
  RecordingSink sink(64, 48, 3);
  Status s = sensor.CaptureBurst(sink);
  EXPECT_EQ(s.code(), Code::kInvalidArgument);
  EXPECT_NE(std::string(s.message()).find("before Configure"), std::string::npos);

  s = sensor.Configure(SensorConfig{64, 48, 17, 2000}, nullptr);
  EXPECT_EQ(s.code(), Code::kInvalidArgument);
  EXPECT_NE(std::string(s.message()).find("sensor synthetic"), std::string::npos) << s.message();
  s = sensor.Configure(SensorConfig{10, 48, 3, 2000}, nullptr);
  EXPECT_EQ(s.code(), Code::kInvalidArgument);

  ASSERT_TRUE(sensor.Configure(SensorConfig{64, 48, 3, 2000}, nullptr).ok());
  sink.fail_frame_ = 1;
  s = sensor.CaptureBurst(sink);
  EXPECT_EQ(s.code(), Code::kIoError);
  EXPECT_NE(std::string(s.message()).find("frame 1"), std::string::npos) << s.message();
  EXPECT_EQ(sink.begun_, 2);
}

}  // namespace
}  // namespace lb
