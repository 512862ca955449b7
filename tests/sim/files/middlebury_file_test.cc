// Real files from ../shared/data (label `data`): the Middlebury Tsukuba views.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "firmware/codecs/codec_decoder.h"
#include "firmware/codecs/image_file.h"
#include "sim/files/file_sensor.h"
#include "tests/firmware/codecs/recording_sink.h"

namespace lb {
namespace {

std::string TsukubaDir() {
  const char* source = getenv("LB_SOURCE_DIR");
  const std::string root = source != nullptr ? std::string(source) + "/.." : "/work";
  return root + "/shared/data/middlebury/tsukuba";
}

bool Exists(const std::string& path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0;
}

TEST(MiddleburyFiles, ReadsTsukubaReferenceView) {
  const std::string path = TsukubaDir() + "/scene1.row3.col3.ppm";
  if (!Exists(path)) GTEST_SKIP() << path << " is absent (the shared data set is not installed)";
  ImageFileInfo info;
  std::vector<uint8_t> pixels;
  const Status s = ReadImageFile(path.c_str(), &info, &pixels);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(info.format, PixelFormat::kRgb8);
  EXPECT_EQ(info.width, 384);
  EXPECT_EQ(info.height, 288);
  EXPECT_EQ(pixels.size(), 384u * 288u * 3u);
}

TEST(MiddleburyFiles, FiveTsukubaViewsMakeABurst) {
  std::vector<std::string> paths;
  for (int col = 1; col <= 5; ++col) {
    paths.push_back(TsukubaDir() + "/scene1.row3.col" + std::to_string(col) + ".ppm");
  }
  if (!Exists(paths[0])) GTEST_SKIP() << paths[0] << " is absent (shared data not installed)";
  std::unique_ptr<FileSensor> sensor;
  ASSERT_TRUE(FileSensor::FromFiles(paths, CodecImageDecoder(), &sensor).ok());
  SensorMode mode;
  const Status s = sensor->Configure(SensorConfig{}, &mode);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(mode.frames, 5);
  EXPECT_EQ(mode.width, 384);
  EXPECT_EQ(mode.height, 288);
  test::RecordingSink sink;
  ASSERT_TRUE(sensor->CaptureBurst(sink).ok()) << sink.error;
  ASSERT_EQ(sink.frames.size(), 5u);
  // Neighbouring views differ (parallax) but are not unrelated images.
  EXPECT_NE(sink.frames[1].pixels, sink.frames[2].pixels);
}

}  // namespace
}  // namespace lb
