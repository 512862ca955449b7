// The refocusable JPEG that `refocus run` writes carries everything a later re-render needs:
// the depth map comes back exactly, and re-rendering from the file alone gives the same pixels as
// rendering the same focus from the burst's own depth (with the stored original as reference).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "firmware/app/job.h"
#include "firmware/app/rerender.h"
#include "sim/synthetic/synthetic_sensor.h"
#include "tests/support/remove_tree.h"

namespace lb {
namespace {

// Keeps every rendered luma row (the test images are small).
class LumaRecorder : public StripObserver {
 public:
  void OnStrip(const ConstPlanarU8& strip, int32_t y0, int32_t rows) override {
    const ConstImageU8& y = strip.planes[0];
    if (luma.empty()) width = y.width;
    luma.resize(static_cast<size_t>(y0 + rows) * width);
    for (int32_t r = 0; r < rows; ++r) {
      for (int32_t x = 0; x < width; ++x)
        luma[static_cast<size_t>(y0 + r) * width + x] = y.Row(r)[x];
    }
  }
  int32_t width = 0;
  std::vector<uint8_t> luma;
};

double Psnr(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  double se = 0;
  for (size_t i = 0; i < a.size(); ++i) se += (a[i] - b[i]) * (a[i] - b[i]);
  return se == 0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 * a.size() / se);
}

class Refocusable : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/refocusable-XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
    sensor_ = std::make_unique<SyntheticSensor>();
    JobOptions o;
    o.sensor.width = 256;
    o.sensor.height = 192;
    o.pipeline.labels = 32;
    o.pipeline.disp_max_q8 = 16 << 8;
    o.pipeline.max_blur_radius = 16;
    o.render.f_number = 2.0f;
    o.render.focus = {40, 60, 24, 24};
    params_ = o.render;
    ASSERT_TRUE(job_.Configure(sensor_.get(), o).ok());
    Status s = job_.Run(Path("run.jpg").c_str(), nullptr, &run_);
    ASSERT_TRUE(s.ok()) << s.message();
  }
  void TearDown() override { (void)lb::test::RemoveTree(dir_); }
  std::string Path(const char* name) const { return dir_ + "/" + name; }

  std::string dir_;
  std::unique_ptr<SyntheticSensor> sensor_;
  Job job_;
  RenderParams params_;
  LumaRecorder run_;
};

TEST_F(Refocusable, DepthMapComesBackExactly) {
  Rerenderer r;
  Status s = r.Load(Path("run.jpg").c_str());
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(r.width(), 256);
  EXPECT_EQ(r.height(), 192);
  ConstImageU16 want = job_.pipeline().map_q8(), got = r.disparity_q8();
  ASSERT_EQ(got.width, want.width);
  ASSERT_EQ(got.height, want.height);
  EXPECT_EQ(r.working_scale(), job_.pipeline().map_scale());
  int32_t differ = 0;
  for (int32_t y = 0; y < want.height; ++y)
    for (int32_t x = 0; x < want.width; ++x) differ += got.Row(y)[x] != want.Row(y)[x];
  EXPECT_EQ(differ, 0);
}

TEST_F(Refocusable, RerenderEqualsRenderingFromTheBurstDepth) {
  Rerenderer r;
  ASSERT_TRUE(r.Load(Path("run.jpg").c_str()).ok());
  RerenderOptions o;
  o.render = params_;
  o.render.focus = {180, 30, 30, 30};  // a new focus
  o.render.f_number = 1.6f;
  o.max_blur_radius = 16;
  LumaRecorder rerendered;
  Status s = r.Render(o, Path("new.jpg").c_str(), &rerendered);
  ASSERT_TRUE(s.ok()) << s.message();

  // Straight from the burst: the pipeline's own map, the stored original as reference.
  RenderConfig rc;
  rc.width = 256;
  rc.height = 192;
  rc.working_scale = job_.pipeline().map_scale();
  rc.working_width = job_.pipeline().map_q8().width;
  rc.working_height = job_.pipeline().map_q8().height;
  rc.max_radius = 16;
  std::vector<uint8_t> block(RenderStage::RequiredBytes(rc) + Arena::kAlign);
  void* base =
      block.data() + (Arena::kAlign - reinterpret_cast<uintptr_t>(block.data()) % Arena::kAlign);
  Arena arena(base, block.size() - Arena::kAlign);
  RenderStage direct;
  ASSERT_TRUE(direct.Configure(rc, arena).ok());
  ASSERT_TRUE(direct.Begin(r.reference(), job_.pipeline().map_q8(), o.render).ok());
  LumaRecorder straight;
  for (;;) {
    ConstPlanarU8 strip;
    int32_t y0 = 0, rows = 0;
    ASSERT_TRUE(direct.NextStrip(&strip, &y0, &rows).ok());
    if (rows == 0) break;
    straight.OnStrip(strip, y0, rows);
  }
  ASSERT_EQ(rerendered.luma.size(), straight.luma.size());
  EXPECT_TRUE(rerendered.luma == straight.luma);
}

TEST_F(Refocusable, RerenderWithTheSameFocusIsCloseToTheOriginalRender) {
  // Only the JPEG coding of the stored original separates the two.
  Rerenderer r;
  ASSERT_TRUE(r.Load(Path("run.jpg").c_str()).ok());
  RerenderOptions o;
  o.render = params_;
  o.max_blur_radius = 16;
  LumaRecorder again;
  ASSERT_TRUE(r.Render(o, Path("same.jpg").c_str(), &again).ok());
  ASSERT_EQ(again.luma.size(), run_.luma.size());
  EXPECT_GT(Psnr(again.luma, run_.luma), 36.0);
}

TEST_F(Refocusable, NotARefocusableFileIsAClearError) {
  JobOptions o;
  o.sensor.width = 64;
  o.sensor.height = 48;
  o.refocusable = false;
  o.pipeline.labels = 8;
  SyntheticSensor plain_sensor;
  Job plain;
  ASSERT_TRUE(plain.Configure(&plain_sensor, o).ok());
  ASSERT_TRUE(plain.Run(Path("plain.jpg").c_str(), nullptr).ok());
  Rerenderer r;
  Status s = r.Load(Path("plain.jpg").c_str());
  EXPECT_FALSE(s.ok());
  EXPECT_NE(std::string(s.message()).find("plain.jpg"), std::string::npos) << s.message();
}

// With threads the XMP is built beside the render and spliced in when it is ready; the file must
// be the one a single thread writes (the EXIF time of taking aside).
TEST_F(Refocusable, TheFileIsTheSameWithOneToFourThreads) {
  auto read = [](const std::string& path) {
    std::vector<uint8_t> bytes;
    FILE* f = fopen(path.c_str(), "rb");
    if (f == nullptr) return bytes;
    for (int c; (c = fgetc(f)) != EOF;) bytes.push_back(static_cast<uint8_t>(c));
    fclose(f);
    return bytes;
  };
  // Blanks the DateTimeOriginal value ("YYYY:MM:DD HH:MM:SS"), the one field that may differ.
  auto without_time = [](std::vector<uint8_t> b) {
    for (size_t i = 0; i + 19 <= b.size(); ++i) {
      const char* p = reinterpret_cast<const char*>(&b[i]);
      if (p[4] == ':' && p[7] == ':' && p[10] == ' ' && p[13] == ':' && p[16] == ':' &&
          isdigit(p[0]) && isdigit(p[18])) {
        memset(&b[i], '0', 19);
        break;
      }
    }
    return b;
  };
  std::vector<uint8_t> one;
  for (int32_t threads = 1; threads <= 4; ++threads) {
    SCOPED_TRACE(threads);
    JobOptions o;
    o.sensor.width = 320;
    o.sensor.height = 240;
    o.pipeline.labels = 16;
    o.threads = threads;
    SyntheticSensor sensor;
    Job job;
    ASSERT_TRUE(job.Configure(&sensor, o).ok());
    const std::string path = Path("threads.jpg");
    JobReport report;
    Status s = job.Run(path.c_str(), &report);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_GT(report.metadata_s, 0.0);
    const std::vector<uint8_t> bytes = without_time(read(path));
    ASSERT_GT(bytes.size(), 1000u);
    if (threads == 1) {
      one = bytes;
    } else {
      EXPECT_TRUE(bytes == one);
    }
  }
}

}  // namespace
}  // namespace lb
