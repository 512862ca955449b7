// A re-rendered photo keeps its depth's confidence: `refocus rerender` (Rerenderer) and the
// camera page's saves (RefocusEngine) write the file's confidence map back, byte for byte, as
// GDepth:Confidence and as Dynamic Depth's confidence item, whichever of the two the file was
// read from. A depth map of another size than the working grid takes its confidence with it,
// nearest pixel; a file without confidence (a phone's, or one written without) still re-renders,
// and the new file has none.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include "algo/render/depth_refine.h"
#include "firmware/app/focus.h"
#include "firmware/app/job.h"
#include "firmware/app/refocus_engine.h"
#include "firmware/app/refocusable.h"
#include "firmware/app/refocusable_photo.h"
#include "firmware/app/rerender.h"
#include "firmware/codecs/jpeg_writer.h"
#include "firmware/refocusable/refocusable_reader.h"
#include "sim/synthetic/synthetic_sensor.h"
#include "tests/firmware/codecs/jpeg_test_util.h"
#include "tests/firmware/codecs/test_images.h"
#include "tests/firmware/refocusable/refocusable_test_util.h"

namespace lb {
namespace {

constexpr int32_t kWidth = 320, kHeight = 240;

// What a reader finds of a file's confidence, through GDepth or (`dd_only`: the file with its
// GDepth part removed) through Dynamic Depth's item.
struct Confidence {
  int32_t width = 0, height = 0, bits = 0;
  std::vector<uint16_t> values;  // empty when the file has none
};

Confidence ConfidenceOf(const std::vector<uint8_t>& file, bool dd_only) {
  const std::vector<uint8_t> bytes = dd_only ? test::WithoutGDepth(file) : file;
  EXPECT_FALSE(bytes.empty());
  RefocusableImage image;
  const Status s = ReadRefocusable(bytes.data(), bytes.size(), "photo.jpg", &image);
  EXPECT_TRUE(s.ok()) << s.message();
  EXPECT_TRUE(image.confidence_ignored.ok()) << image.confidence_ignored.message();
  EXPECT_EQ(image.confidence.values.empty(), image.xmp.depth.confidence.empty());
  return {image.confidence.width, image.confidence.height, image.confidence.bits,
          image.confidence.values};
}

void ExpectSame(const Confidence& got, const Confidence& want, const char* what) {
  SCOPED_TRACE(what);
  ASSERT_FALSE(want.values.empty());
  EXPECT_EQ(got.width, want.width);
  EXPECT_EQ(got.height, want.height);
  EXPECT_EQ(got.bits, 8);
  EXPECT_TRUE(got.values == want.values) << "the confidence changed";
}

// In both formats, a file's confidence is `want`.
void ExpectCarries(const std::string& path, const Confidence& want) {
  const std::vector<uint8_t> bytes = test::ReadFile(path);
  ExpectSame(ConfidenceOf(bytes, false), want, "GDepth:Confidence");
  ExpectSame(ConfidenceOf(bytes, true), want, "Dynamic Depth's item");
}

void ExpectNone(const std::string& path) {
  const std::vector<uint8_t> bytes = test::ReadFile(path);
  EXPECT_TRUE(ConfidenceOf(bytes, false).values.empty());
  const std::vector<uint8_t> dd = test::WithoutGDepth(bytes);
  if (!dd.empty()) {
    EXPECT_TRUE(ConfidenceOf(bytes, true).values.empty());
  }
}

// A focus away from the one the photo was rendered with (the centre).
RenderParams NewFocus() {
  RenderParams r;
  r.focus = FocusAtPoint(kWidth / 5, kHeight / 4);
  r.f_number = 4.0f;
  return r;
}

class RerenderConfidence : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::ScratchDir();
    SyntheticSensor sensor;
    JobOptions o;
    o.sensor.width = kWidth;
    o.sensor.height = kHeight;
    o.pipeline.labels = 16;
    o.render.f_number = 2.0f;
    o.threads = 1;
    Job job;
    Status s = job.Configure(&sensor, o);
    ASSERT_TRUE(s.ok()) << s.message();
    s = job.Run(Photo().c_str(), nullptr);
    ASSERT_TRUE(s.ok()) << s.message();
  }
  static void TearDownTestSuite() { delete dir_; }
  static std::string Photo() { return dir_->Path("photo.jpg"); }
  static test::ScratchDir* dir_;
};
test::ScratchDir* RerenderConfidence::dir_ = nullptr;

TEST_F(RerenderConfidence, ThePhotoDecodesItOnTheWorkingGrid) {
  const std::vector<uint8_t> bytes = test::ReadFile(Photo());
  const Confidence file = ConfidenceOf(bytes, false);
  ASSERT_FALSE(file.values.empty());
  RefocusablePhoto photo;
  const Status s = photo.Decode(bytes.data(), bytes.size(), "photo.jpg");
  ASSERT_TRUE(s.ok()) << s.message();
  const ConstImageU8 c = photo.confidence();
  ASSERT_EQ(c.width, photo.disparity_q8().width);
  ASSERT_EQ(c.height, photo.disparity_q8().height);
  ASSERT_EQ(c.width, file.width);
  ASSERT_EQ(c.height, file.height);
  for (int32_t y = 0; y < c.height; ++y) {
    for (int32_t x = 0; x < c.width; ++x) {
      ASSERT_EQ(c.Row(y)[x], file.values[static_cast<size_t>(y) * c.width + x]) << x << "," << y;
    }
  }
}

TEST_F(RerenderConfidence, ARerenderKeepsItInBothFormats) {
  const std::vector<uint8_t> bytes = test::ReadFile(Photo());
  const Confidence original = ConfidenceOf(bytes, false);
  ExpectSame(ConfidenceOf(bytes, true), original, "the job's Dynamic Depth item");

  // From the job's photo, and from the same photo with only its Dynamic Depth part.
  const std::string dd_only = dir_->Path("dd_only.jpg");
  ASSERT_TRUE(test::WriteFile(dd_only, test::WithoutGDepth(bytes)));
  for (const std::string& in : {Photo(), dd_only}) {
    SCOPED_TRACE(in);
    Rerenderer rerenderer;
    Status s = rerenderer.Load(in.c_str());
    ASSERT_TRUE(s.ok()) << s.message();
    RerenderOptions ro;
    ro.render = NewFocus();
    ro.threads = 1;
    const std::string out = in + ".again.jpg";
    s = rerenderer.Render(ro, out.c_str());
    ASSERT_TRUE(s.ok()) << s.message();
    ExpectCarries(out, original);
    // Re-rendered with the new focus, not the old one.
    RefocusableImage again;
    ASSERT_TRUE(ReadRefocusableFile(out.c_str(), &again).ok());
    EXPECT_LT(again.xmp.focus.focal_point_x, 0.4);
  }
}

TEST_F(RerenderConfidence, ThePagesSaveKeepsIt) {
  const Confidence original = ConfidenceOf(test::ReadFile(Photo()), false);
  RefocusEngine engine;
  RefocusEngineConfig c;
  c.max_width = kWidth;
  c.max_height = kHeight;
  c.threads = 2;
  c.max_blur_radius = 16;
  ASSERT_TRUE(engine.Configure(c).ok());
  Status s = engine.Load(Photo().c_str());
  ASSERT_TRUE(s.ok()) << s.message();
  const std::string out = dir_->Path("saved.jpg");
  s = engine.Save(NewFocus(), out.c_str());
  ASSERT_TRUE(s.ok()) << s.message();
  ExpectCarries(out, original);
}

// A refocusable file written here, GDepth only: a `width` x `height` original, a depth map of
// `dw` x `dh` (two depths, left and right), and `confidence` (that size, or empty for none).
std::vector<uint8_t> BuiltFile(int32_t width, int32_t height, int32_t dw, int32_t dh,
                               const std::vector<uint8_t>& confidence) {
  test::RefocusSample sample = test::MakeRefocusSample(false);
  sample.picture = test::MakeTexture(width, height);
  std::vector<uint8_t> original;
  EXPECT_TRUE(EncodeYCbCr420(sample.picture.View(), 90, &original).ok());
  std::vector<uint16_t> disp(static_cast<size_t>(dw) * dh);
  for (int32_t y = 0; y < dh; ++y) {
    for (int32_t x = 0; x < dw; ++x) {
      disp[static_cast<size_t>(y) * dw + x] = static_cast<uint16_t>(256 + (x < dw / 2 ? 0 : 2048));
    }
  }
  const ConstImageU8 conf =
      confidence.empty() ? ConstImageU8() : MakeView<const uint8_t>(confidence.data(), dw, dh);
  std::vector<JpegSegment> segments;
  const Status s =
      BuildRefocusableSegments(MakeView<const uint16_t>(disp.data(), dw, dh), sample.range,
                               original, FocusUsed(), width, &segments, nullptr, conf);
  EXPECT_TRUE(s.ok()) << s.message();
  return test::WriteRefocusJpeg(sample, segments);
}

// A map not a whole-number fraction of the photo is resampled onto the working grid, its
// confidence by the nearest pixel, centres aligned.
TEST(RerenderConfidenceResampled, TheNearestPixelsConfidence) {
  const int32_t dw = 200, dh = 133;
  std::vector<uint8_t> confidence(static_cast<size_t>(dw) * dh);
  for (size_t i = 0; i < confidence.size(); ++i) confidence[i] = static_cast<uint8_t>(i * 37 % 251);
  test::ScratchDir dir;
  const std::string in = dir.Path("built.jpg"), out = dir.Path("again.jpg");
  ASSERT_TRUE(test::WriteFile(in, BuiltFile(480, 320, dw, dh, confidence)));
  Rerenderer rerenderer;
  Status s = rerenderer.Load(in.c_str());
  ASSERT_TRUE(s.ok()) << s.message();
  const int32_t gw = rerenderer.disparity_q8().width, gh = rerenderer.disparity_q8().height;
  ASSERT_EQ(gw, 240);
  ASSERT_EQ(gh, 160);
  RerenderOptions ro;
  ro.threads = 1;
  s = rerenderer.Render(ro, out.c_str());
  ASSERT_TRUE(s.ok()) << s.message();
  Confidence want{gw, gh, 8, std::vector<uint16_t>(static_cast<size_t>(gw) * gh)};
  for (int32_t y = 0; y < gh; ++y) {
    for (int32_t x = 0; x < gw; ++x) {
      const int32_t sx = static_cast<int32_t>((x + 0.5) * dw / gw);
      const int32_t sy = static_cast<int32_t>((y + 0.5) * dh / gh);
      want.values[static_cast<size_t>(y) * gw + x] = confidence[static_cast<size_t>(sy) * dw + sx];
    }
  }
  ExpectCarries(out, want);
}

// The page, configured for a camera's photos, opens the map the job gives them (at least half
// the photo's side or 1 MP: over 1 MP for some sizes) and saves its confidence.
class RerenderConfidenceOnThePage : public ::testing::TestWithParam<std::pair<int32_t, int32_t>> {};

TEST_P(RerenderConfidenceOnThePage, ACameraSizedMap) {
  const int32_t width = GetParam().first, height = GetParam().second;
  const int32_t s = DepthRefiner::MapScale(width, height, 4);
  const int32_t dw = width / s, dh = height / s;
  RecordProperty("map", std::to_string(dw) + "x" + std::to_string(dh));
  std::vector<uint8_t> confidence(static_cast<size_t>(dw) * dh);
  for (size_t i = 0; i < confidence.size(); ++i) confidence[i] = static_cast<uint8_t>(i * 37 % 251);
  test::ScratchDir dir;
  const std::string in = dir.Path("built.jpg"), out = dir.Path("saved.jpg");
  ASSERT_TRUE(test::WriteFile(in, BuiltFile(width, height, dw, dh, confidence)));
  RefocusEngine engine;
  RefocusEngineConfig c;
  c.max_width = width;
  c.max_height = height;
  c.threads = 2;
  ASSERT_TRUE(engine.Configure(c).ok());
  RecordProperty("reserved_bytes", std::to_string(engine.reserved_bytes()));
  Status st = engine.Load(in.c_str());
  ASSERT_TRUE(st.ok()) << st.message();
  st = engine.Save(engine.photo().current, out.c_str());
  ASSERT_TRUE(st.ok()) << st.message();
  ExpectCarries(out, {dw, dh, 8, std::vector<uint16_t>(confidence.begin(), confidence.end())});
}

// 1200x900 and 1352x1013 maps.
INSTANTIATE_TEST_SUITE_P(Sizes, RerenderConfidenceOnThePage,
                         ::testing::Values(std::make_pair(2400, 1800), std::make_pair(4056, 3040)));

TEST(RerenderWithoutConfidence, AFileWrittenWithoutOneGivesOneWithout) {
  test::ScratchDir dir;
  const std::string in = dir.Path("built.jpg"), out = dir.Path("again.jpg");
  ASSERT_TRUE(test::WriteFile(in, BuiltFile(480, 320, 240, 160, {})));
  ExpectNone(in);
  Rerenderer rerenderer;
  Status s = rerenderer.Load(in.c_str());
  ASSERT_TRUE(s.ok()) << s.message();
  RerenderOptions ro;
  ro.threads = 1;
  s = rerenderer.Render(ro, out.c_str());
  ASSERT_TRUE(s.ok()) << s.message();
  ExpectNone(out);
}

// A phone's Lens Blur file (../shared/data/phone-depth; skipped when absent) carries none.
TEST(RerenderWithoutConfidence, APhonesFileGivesOneWithout) {
  const char* root = std::getenv("LB_SOURCE_DIR");
  const std::string dir = std::string(root ? root : ".") + "/../shared/data/phone-depth";
  struct stat st;
  if (stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    GTEST_SKIP() << dir << " is absent: no phone files to open";
  }
  test::ScratchDir scratch;
  const std::string in = dir + "/lensblur_depthy1.jpg", out = scratch.Path("again.jpg");
  Rerenderer rerenderer;
  Status s = rerenderer.Load(in.c_str());
  ASSERT_TRUE(s.ok()) << s.message();
  RerenderOptions ro;
  ro.threads = 2;
  s = rerenderer.Render(ro, out.c_str());
  ASSERT_TRUE(s.ok()) << s.message();
  ExpectNone(out);
}

}  // namespace
}  // namespace lb
