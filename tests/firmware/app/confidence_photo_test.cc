// Every photo the job writes carries its depth map's confidence (GDepth:Confidence and Dynamic
// Depth's confidence item): an independent reader (exiftool) lists both, and the product's reader
// gives back the pipeline's map, byte for byte, at the map's size. A burst whose depth is mostly
// a guess (a textureless scene) gives the retake hint.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "firmware/app/job.h"
#include "firmware/app/refocus_engine.h"
#include "firmware/codecs/codec_decoder.h"
#include "firmware/refocusable/refocusable_reader.h"
#include "sim/files/file_sensor.h"
#include "sim/synthetic/synthetic_sensor.h"
#include "tests/algo/motion/burst.h"
#include "tests/firmware/codecs/jpeg_test_util.h"
#include "tests/firmware/codecs/test_images.h"
#include "tests/support/remove_tree.h"

namespace lb {
namespace {

class ConfidencePhoto : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/confidence-photo-XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override { (void)lb::test::RemoveTree(dir_); }

  // Runs `sensor`'s burst through a job into dir_/photo.jpg.
  void Run(Sensor* sensor, ViewGeometry geometry, Job* job, JobReport* report) {
    JobOptions o;
    o.pipeline.labels = 16;
    o.pipeline.geometry = geometry;
    o.pipeline.reference = -1;
    o.render.f_number = 2.0f;
    Status s = job->Configure(sensor, o);
    ASSERT_TRUE(s.ok()) << s.message();
    s = job->Run(Photo().c_str(), report);
    ASSERT_TRUE(s.ok()) << s.message();
  }
  std::string Photo() const { return dir_ + "/photo.jpg"; }

  // What the camera's page reads of the photo: the share of its depth its confidence map calls
  // a guess (-1: no map).
  static void PageGuessPermille(const std::string& path, int32_t* permille) {
    RefocusEngineConfig c;
    c.max_width = 1280;  // the synthetic sensor's photos and the files' below
    c.max_height = 960;
    c.threads = 1;
    c.max_blur_radius = 16;
    RefocusEngine engine;
    ASSERT_TRUE(engine.Configure(c).ok());
    const Status s = engine.Load(path.c_str());
    ASSERT_TRUE(s.ok()) << s.message();
    *permille = engine.photo().guess_permille;
  }

  // The frames of `b` as PPM files.
  std::vector<std::string> Write(const motiontest::Burst& b) {
    std::vector<std::string> paths;
    for (size_t v = 0; v < b.pixels.size(); ++v) {
      const std::vector<uint16_t> samples(b.pixels[v].begin(), b.pixels[v].end());
      paths.push_back(dir_ + "/f" + std::to_string(v) + ".ppm");
      EXPECT_TRUE(
          test::WriteFile(paths.back(), test::EncodePnm("P6", b.width, b.height, 255, samples)));
    }
    return paths;
  }

  std::string dir_;
};

// Whether exiftool's `-G1 -s` listing has a line "<group> <name> : ...".
bool HasTag(const std::string& tags, const std::string& group, const std::string& name) {
  for (size_t at = tags.find(group); at != std::string::npos; at = tags.find(group, at + 1)) {
    size_t from = at + group.size();
    while (from < tags.size() && tags[from] == ' ') ++from;
    if (tags.compare(from, name.size(), name) == 0 && from + name.size() < tags.size() &&
        (tags[from + name.size()] == ' ' || tags[from + name.size()] == ':')) {
      return true;
    }
  }
  return false;
}

TEST_F(ConfidencePhoto, TheFileCarriesThePipelinesMapInBothFormats) {
  SyntheticSensor sensor;
  Job job;
  JobReport report;
  ASSERT_NO_FATAL_FAILURE(Run(&sensor, ViewGeometry::kRectified, &job, &report));
  const Pipeline& p = job.pipeline();
  const ConstImageU8 map = p.map_confidence();
  ASSERT_FALSE(map.empty());
  ASSERT_EQ(map.width, p.map_q8().width);
  ASSERT_EQ(map.height, p.map_q8().height);
  // The hint follows the pipeline's share, whatever the scene.
  RecordProperty("low_confidence_permille", std::to_string(report.low_confidence_permille));
  EXPECT_EQ(report.hint != nullptr, report.low_confidence_permille > Pipeline::kRetakePermille);
  // The page reads the same share back from the file, and gives the same verdict.
  int32_t page = -1;
  ASSERT_NO_FATAL_FAILURE(PageGuessPermille(Photo(), &page));
  EXPECT_NEAR(page, report.low_confidence_permille, 30);
  EXPECT_EQ(page > Pipeline::kRetakePermille, report.hint != nullptr);

  RefocusableImage back;
  Status s = ReadRefocusableFile(Photo().c_str(), &back);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_TRUE(back.confidence_ignored.ok()) << back.confidence_ignored.message();
  ASSERT_EQ(back.confidence.width, map.width);
  ASSERT_EQ(back.confidence.height, map.height);
  EXPECT_EQ(back.depth.width, map.width);
  EXPECT_EQ(back.confidence.bits, 8);
  int64_t differing = 0;
  for (int32_t y = 0; y < map.height; ++y) {
    for (int32_t x = 0; x < map.width; ++x) {
      differing += back.confidence.values[static_cast<size_t>(y) * map.width + x] != map.Row(y)[x];
    }
  }
  EXPECT_EQ(differing, 0);

  if (!test::HaveTool("exiftool")) {
    GTEST_SKIP() << "exiftool is not installed: the independent reader's half is skipped";
  }
  int code = 0;
  const std::string tags = test::RunTool("exiftool -a -G1 -s '" + Photo() + "' 2>&1", &code);
  EXPECT_EQ(code, 0) << tags;
  for (const char* name : {"Confidence", "ConfidenceMime"}) {
    EXPECT_TRUE(HasTag(tags, "[XMP-GDepth]", name)) << name << "\n" << tags;
  }
  EXPECT_TRUE(HasTag(tags, "[XMP-Device]", "CameraDepthMapConfidenceURI")) << tags;
  for (const char* want :
       {"android/confidencemap", "image/jpeg, image/png, image/png, image/jpeg"}) {
    EXPECT_NE(tags.find(want), std::string::npos) << want << "\n" << tags;
  }
  // exiftool's copy of GDepth:Confidence is a PNG of the map's size (IHDR's width and height,
  // big-endian, are its bytes 16..23).
  const std::string png = test::RunTool("exiftool -b -XMP-GDepth:Confidence '" + Photo() +
                                            "' | head -c 24 | od -An -v -tx1 | tr -d '\\n'",
                                        &code);
  EXPECT_NE(png.find("89 50 4e 47"), std::string::npos) << png;
  char size[64];
  snprintf(size, sizeof(size), "%02x %02x %02x %02x %02x %02x %02x %02x", map.width >> 24,
           (map.width >> 16) & 0xFF, (map.width >> 8) & 0xFF, map.width & 0xFF, map.height >> 24,
           (map.height >> 16) & 0xFF, (map.height >> 8) & 0xFF, map.height & 0xFF);
  EXPECT_NE(png.find(size), std::string::npos)
      << png << " is not " << map.width << "x" << map.height;
}

// A flat, textureless scene: every label fits every pixel equally, so the depth is a guess.
TEST_F(ConfidencePhoto, ATexturelessBurstGivesTheRetakeHint) {
  motiontest::Burst b;
  b.width = 320;
  b.height = 240;
  b.pixels.assign(5, std::vector<uint8_t>(static_cast<size_t>(b.width) * b.height * 3, 180));
  std::unique_ptr<FileSensor> sensor;
  ASSERT_TRUE(FileSensor::FromFiles(Write(b), CodecImageDecoder(), &sensor).ok());
  Job job;
  JobReport report;
  ASSERT_NO_FATAL_FAILURE(Run(sensor.get(), ViewGeometry::kRectified, &job, &report));
  EXPECT_TRUE(report.warning.ok()) << report.warning.message();
  EXPECT_GT(report.low_confidence_permille, Pipeline::kRetakePermille);
  ASSERT_NE(report.hint, nullptr);
  EXPECT_STREQ(report.hint, kRetakeHint);
  EXPECT_EQ(std::string(report.hint).find('\n'), std::string::npos);
  // The camera's page says so too, from the file alone.
  int32_t page = -1;
  ASSERT_NO_FATAL_FAILURE(PageGuessPermille(Photo(), &page));
  EXPECT_GT(page, Pipeline::kRetakePermille);
}

// A handheld burst whose middle is a blank wall: the camera's motion is found from the border,
// but most of the picture's depth is a guess.
TEST_F(ConfidencePhoto, AHandheldBurstOfABlankWallGivesTheRetakeHint) {
  SceneParams params;
  params.seed = 11;
  params.geometry = ViewGeometry::kHandheld;
  params.max_translation = 0.02;
  motiontest::Burst b;
  ASSERT_TRUE(motiontest::MakeBurst(params, 320, 240, 5, &b));
  const int32_t border = 40;
  for (std::vector<uint8_t>& frame : b.pixels) {
    for (int32_t y = border; y < b.height - border; ++y) {
      for (int32_t x = border; x < b.width - border; ++x) {
        for (int32_t c = 0; c < 3; ++c) frame[(static_cast<size_t>(y) * b.width + x) * 3 + c] = 200;
      }
    }
  }
  std::unique_ptr<FileSensor> sensor;
  ASSERT_TRUE(FileSensor::FromFiles(Write(b), CodecImageDecoder(), &sensor).ok());
  Job job;
  JobReport report;
  ASSERT_NO_FATAL_FAILURE(Run(sensor.get(), ViewGeometry::kAuto, &job, &report));
  RecordProperty("low_confidence_permille", std::to_string(report.low_confidence_permille));
  if (!report.warning.ok()) {
    // No depth at all: the warning says what to do, and the hint does not repeat it.
    EXPECT_EQ(report.hint, nullptr);
    GTEST_SKIP() << "the border gave no motion: " << report.warning.message();
  }
  EXPECT_GT(report.low_confidence_permille, Pipeline::kRetakePermille);
  EXPECT_STREQ(report.hint, kRetakeHint);
}

}  // namespace
}  // namespace lb
