// Handheld bursts that cannot give depth, read from files as a user's would be: each one makes a
// photo all the same, unblurred (every rendered pixel is the reference frame's), with a warning
// that says what to do - never a garbage depth map.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "firmware/app/job.h"
#include "firmware/codecs/codec_decoder.h"
#include "sim/files/file_sensor.h"
#include "tests/algo/motion/burst.h"
#include "tests/firmware/codecs/test_images.h"
#include "tests/support/remove_tree.h"

namespace lb {
namespace {

constexpr int32_t kW = 320, kH = 240, kFrames = 5;

// Compares every rendered sample with the pipeline's full-resolution reference.
class SameAsReference : public StripObserver {
 public:
  explicit SameAsReference(const Job& job) : job_(job) {}
  void OnStrip(const ConstPlanarU8& strip, int32_t y0, int32_t rows) override {
    const ConstPlanarU8 ref = const_cast<Job&>(job_).pipeline().reference();
    for (int32_t p = 0; p < strip.count; ++p) {
      const int32_t shift = p == 0 ? 0 : 1;  // 4:2:0 chroma rows
      const ConstImageU8& s = strip.planes[p];
      for (int32_t r = 0; r < (p == 0 ? rows : s.height); ++r) {
        const int32_t y = (y0 >> shift) + r;
        if (y >= ref.planes[p].height) break;
        for (int32_t x = 0; x < s.width; ++x) {
          differing += s.Row(r)[x] != ref.planes[p].Row(y)[x];
          ++samples;
        }
      }
    }
  }
  int64_t differing = 0, samples = 0;

 private:
  const Job& job_;
};

class DegenerateBurst : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/degenerate-XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override { (void)lb::test::RemoveTree(dir_); }

  // Writes the burst's frames as PPM files.
  std::vector<std::string> Write(const motiontest::Burst& b) {
    std::vector<std::string> paths;
    for (int32_t v = 0; v < kFrames; ++v) {
      const std::vector<uint16_t> samples(b.pixels[v].begin(), b.pixels[v].end());
      paths.push_back(dir_ + "/f" + std::to_string(v) + ".ppm");
      EXPECT_TRUE(test::WriteFile(paths.back(), test::EncodePnm("P6", kW, kH, 255, samples)));
    }
    return paths;
  }

  // Runs the burst's files through a Job; expects a saved, unblurred photo of `pixels` pixels
  // and a warning holding `advice`.
  void ExpectUnblurredWithWarning(const std::vector<std::string>& paths, const char* advice,
                                  ViewGeometry geometry = ViewGeometry::kAuto,
                                  int64_t pixels = int64_t{kW} * kH) {
    std::unique_ptr<FileSensor> sensor;
    ASSERT_TRUE(FileSensor::FromFiles(paths, CodecImageDecoder(), &sensor).ok());
    JobOptions o;
    o.pipeline.geometry = geometry;
    o.pipeline.labels = 16;
    o.pipeline.reference = 2;
    o.render.f_number = 1.4f;
    Job job;
    Status s = job.Configure(sensor.get(), o);
    ASSERT_TRUE(s.ok()) << s.message();
    SameAsReference check(job);
    JobReport report;
    const std::string out = dir_ + "/photo.jpg";
    s = job.Run(out.c_str(), &report, &check);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_EQ(report.warning.code(), Code::kDegenerate);
    EXPECT_NE(strstr(report.warning.message(), advice), nullptr) << report.warning.message();
    EXPECT_GT(check.samples, pixels);
    EXPECT_EQ(check.differing, 0) << "the photo is blurred somewhere";
    EXPECT_EQ(access(out.c_str(), R_OK), 0) << "no photo saved";
  }

  std::string dir_;
};

TEST_F(DegenerateBurst, NoMotion) {
  motiontest::Burst b;
  ASSERT_TRUE(motiontest::MakeBurst(motiontest::Handheld(6), kW, kH, kFrames, &b));
  for (int32_t v = 0; v < kFrames; ++v) b.pixels[v] = b.pixels[b.scene.reference()];
  ExpectUnblurredWithWarning(Write(b), "sideways");
}

TEST_F(DegenerateBurst, PureRotation) {
  SceneParams p = motiontest::Handheld(7);
  p.max_translation = 0;
  motiontest::Burst b;
  ASSERT_TRUE(motiontest::MakeBurst(p, kW, kH, kFrames, &b));
  ExpectUnblurredWithWarning(Write(b), "sideways");
}

TEST_F(DegenerateBurst, TooFewFeatures) {
  motiontest::Burst b;
  ASSERT_TRUE(motiontest::MakeBurst(motiontest::Handheld(8), kW, kH, kFrames, &b));
  for (int32_t v = 0; v < kFrames; ++v) {
    for (int32_t i = 0; i < kW * kH * 3; ++i) {
      b.pixels[v][i] = static_cast<uint8_t>(100 + (i / 3 % kW) / 16 + v);
    }
  }
  ExpectUnblurredWithWarning(Write(b), "texture");
}

TEST_F(DegenerateBurst, BlurredFrame) {
  motiontest::Burst b;
  ASSERT_TRUE(motiontest::MakeBurst(motiontest::Handheld(9), kW, kH, kFrames, &b));
  motiontest::Blur(&b.pixels[3], kW, kH);
  ExpectUnblurredWithWarning(Write(b), "frame 3 is blurred");
}

// 16x8192 into the 640x480 working bound is under a pixel wide: no depth, but still a photo.
TEST_F(DegenerateBurst, FramesTooThinForDepth) {
  for (const bool tall : {true, false}) {
    const int32_t w = tall ? 16 : 8192, h = tall ? 8192 : 16;
    std::vector<uint16_t> samples(static_cast<size_t>(w) * h * 3);
    for (size_t i = 0; i < samples.size(); ++i) samples[i] = static_cast<uint16_t>(i * 7 % 251);
    std::vector<std::string> paths;
    for (int32_t v = 0; v < 3; ++v) {
      paths.push_back(dir_ + "/thin" + std::to_string(v) + ".ppm");
      ASSERT_TRUE(test::WriteFile(paths.back(), test::EncodePnm("P6", w, h, 255, samples)));
    }
    for (const ViewGeometry g : {ViewGeometry::kAuto, ViewGeometry::kRectified}) {
      SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h));
      ExpectUnblurredWithWarning(paths, "too thin for depth", g, int64_t{w} * h);
    }
  }
}

}  // namespace
}  // namespace lb
