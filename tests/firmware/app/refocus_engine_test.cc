// The web page's engine: photos from the synthetic camera, loaded, previewed, rendered and saved
// with no allocation after Configure (Save's metadata apart), the focus really moving to the
// tapped region, files it cannot take refused, and the camera pausing it between strips.
#include "firmware/app/refocus_engine.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "firmware/app/focus.h"
#include "firmware/app/job.h"
#include "sim/synthetic/synthetic_sensor.h"
#include "tests/firmware/codecs/jpeg_test_util.h"
#include "tests/support/alloc_counter.h"

namespace lb {
namespace {

using test::DecodeYcc;
using test::ReadFile;
using test::ScratchDir;

struct Luma {
  int32_t width = 0, height = 0;
  std::vector<uint8_t> y;
};

Luma Decode(const std::vector<uint8_t>& jpeg) {
  Luma l;
  std::vector<uint8_t> ycc;
  std::string error;
  EXPECT_TRUE(DecodeYcc(jpeg, &l.width, &l.height, &ycc, &error)) << error;
  l.y.resize(static_cast<size_t>(l.width) * l.height);
  for (size_t i = 0; i < l.y.size(); ++i) l.y[i] = ycc[3 * i];
  return l;
}

// What a user sees as "sharp here": the variance of the Laplacian in a window around (cx, cy),
// given as fractions of the image.
double Sharpness(const Luma& l, double fx, double fy, int32_t half) {
  const int32_t cx = static_cast<int32_t>(fx * l.width), cy = static_cast<int32_t>(fy * l.height);
  double sum = 0, sum2 = 0;
  int n = 0;
  for (int32_t y = std::max(1, cy - half); y < std::min(l.height - 1, cy + half); ++y) {
    for (int32_t x = std::max(1, cx - half); x < std::min(l.width - 1, cx + half); ++x) {
      auto at = [&](int32_t xx, int32_t yy) {
        return static_cast<double>(l.y[static_cast<size_t>(yy) * l.width + xx]);
      };
      const double lap = 4 * at(x, y) - at(x - 1, y) - at(x + 1, y) - at(x, y - 1) - at(x, y + 1);
      sum += lap;
      sum2 += lap * lap;
      ++n;
    }
  }
  return n ? sum2 / n - (sum / n) * (sum / n) : 0;
}

// A photo from the synthetic camera, focused at the central ninth (the default), and from its
// depth map a point at another depth with a uniform neighbourhood: where a user would tap.
struct Photo {
  std::string path;
  int32_t width = 0, height = 0;
  double old_x = 0.5, old_y = 0.5;  // the focus it was rendered with
  double new_x = 0, new_y = 0;      // the tap
};

Photo MakePhoto(const ScratchDir& dir, const char* name, int32_t width, int32_t height) {
  Photo photo;
  photo.path = dir.Path(name);
  photo.width = width;
  photo.height = height;
  SyntheticSensor sensor;
  Job job;
  JobOptions o;
  o.sensor.width = width;
  o.sensor.height = height;
  o.pipeline.labels = 32;
  o.pipeline.disp_max_q8 = 16 << 8;
  o.render.f_number = 2.0f;
  o.threads = 1;
  Status s = job.Configure(&sensor, o);
  EXPECT_TRUE(s.ok()) << s.message();
  JobReport report;
  s = job.Run(photo.path.c_str(), &report);
  EXPECT_TRUE(s.ok()) << s.message();
  ConstImageU16 d = job.pipeline().map_q8();
  // The most different depth from the focus whose 7x7 map px are within 1/4 px of each other.
  int32_t best = -1;
  for (int32_t y = 4; y + 4 < d.height; ++y) {
    for (int32_t x = 4; x + 4 < d.width; ++x) {
      int32_t lo = 1 << 30, hi = 0;
      for (int32_t j = -3; j <= 3; ++j) {
        for (int32_t i = -3; i <= 3; ++i) {
          lo = std::min<int32_t>(lo, d.Row(y + j)[x + i]);
          hi = std::max<int32_t>(hi, d.Row(y + j)[x + i]);
        }
      }
      if (hi - lo > 64) continue;
      const int32_t diff = std::abs(d.Row(y)[x] - report.focus_disp_q8);
      if (diff > best) {
        best = diff;
        photo.new_x = (x + 0.5) / d.width;
        photo.new_y = (y + 0.5) / d.height;
      }
    }
  }
  EXPECT_GT(best, 2 << 8) << "the scene has no region at another depth";
  return photo;
}

RenderParams TapAt(const Photo& p, double fx, double fy) {
  RenderParams r;
  r.focus = FocusAtPoint(static_cast<int32_t>(fx * p.width), static_cast<int32_t>(fy * p.height));
  r.f_number = 2.0f;
  return r;
}

std::vector<uint8_t> Output(const RefocusEngine& e) {
  return std::vector<uint8_t>(e.output(), e.output() + e.output_size());
}

class RefocusEngineTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new ScratchDir();
    photos_ = new std::vector<Photo>{MakePhoto(*dir_, "IMG_a.jpg", 320, 240),
                                     MakePhoto(*dir_, "IMG_b.jpg", 256, 192),
                                     MakePhoto(*dir_, "IMG_c.jpg", 400, 288)};
  }
  static void TearDownTestSuite() {
    delete photos_;
    delete dir_;
  }
  static RefocusEngineConfig Config() {
    RefocusEngineConfig c;
    c.max_width = 400;
    c.max_height = 300;
    c.threads = 2;
    c.max_blur_radius = 16;
    return c;
  }
  static ScratchDir* dir_;
  static std::vector<Photo>* photos_;
};
ScratchDir* RefocusEngineTest::dir_ = nullptr;
std::vector<Photo>* RefocusEngineTest::photos_ = nullptr;

TEST_F(RefocusEngineTest, NoAllocationAfterConfigure) {
  RefocusEngine engine;
  RefocusEngineConfig c = Config();
  c.preview_side = 160;  // the photos are small: make the preview a real downscale
  ASSERT_TRUE(engine.Configure(c).ok());
  size_t allocations = 0;
  for (int round = 0; round < 2; ++round) {
    for (const Photo& p : *photos_) {
      const size_t before = testing::AllocationCount();
      Status s = engine.Load(p.path.c_str());
      if (s.ok()) s = engine.RenderPreview(TapAt(p, p.new_x, p.new_y));
      if (s.ok()) s = engine.RenderFull(TapAt(p, p.new_x, p.new_y));
      allocations += testing::AllocationCount() - before;
      ASSERT_TRUE(s.ok()) << s.message();
      EXPECT_LE(std::max(engine.photo().preview_width, engine.photo().preview_height), 160);
      // Save writes the metadata through `refocus rerender`'s code (on the heap, freed after).
      const std::string out = p.path + ".saved" + std::to_string(round) + ".jpg";
      s = engine.Save(TapAt(p, p.old_x, p.old_y), out.c_str());
      ASSERT_TRUE(s.ok()) << s.message();
    }
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_GT(engine.reserved_bytes(), 0u);
}

TEST_F(RefocusEngineTest, FocusMovesToTheTap) {
  RefocusEngine engine;
  ASSERT_TRUE(engine.Configure(Config()).ok());
  for (const Photo& p : *photos_) {
    SCOPED_TRACE(p.path);
    ASSERT_TRUE(engine.Load(p.path.c_str()).ok());
    EXPECT_EQ(engine.photo().width, p.width);
    EXPECT_NEAR(engine.photo().current.f_number, 2.0f, 0.05f);  // from GFocus
    const Luma original = Decode(ReadFile(p.path));
    ASSERT_TRUE(engine.RenderFull(TapAt(p, p.new_x, p.new_y)).ok());
    const Luma full = Decode(Output(engine));
    ASSERT_EQ(full.width, p.width);
    EXPECT_GT(Sharpness(full, p.new_x, p.new_y, 6), 1.5 * Sharpness(original, p.new_x, p.new_y, 6));
    EXPECT_LT(Sharpness(full, p.old_x, p.old_y, 12),
              0.8 * Sharpness(original, p.old_x, p.old_y, 12));
    // The saved photo is refocusable again, focused at the tap.
    const std::string out = p.path + ".tap.jpg";
    ASSERT_TRUE(engine.Save(TapAt(p, p.new_x, p.new_y), out.c_str()).ok());
    // A second save under the same name is refused at the commit: the first stays.
    const std::vector<uint8_t> first = ReadFile(out);
    EXPECT_EQ(engine.Save(TapAt(p, p.old_x, p.old_y), out.c_str()).code(), Code::kInvalidArgument);
    EXPECT_EQ(ReadFile(out), first);
    const Luma saved = Decode(ReadFile(out));
    EXPECT_GT(Sharpness(saved, p.new_x, p.new_y, 6),
              1.5 * Sharpness(original, p.new_x, p.new_y, 6));
    RefocusEngine again;
    ASSERT_TRUE(again.Configure(Config()).ok());
    ASSERT_TRUE(again.Load(out.c_str()).ok());
    EXPECT_NEAR(again.photo().current.focus.x + 8, p.new_x * p.width, 2.0);
  }
}

// At preview size, against the same engine's preview at the photo's own focus: a photo whose
// depth scale the preview step does not divide (the depth map resampled), and one where it does
// (the render stage upsamples the stored map, as at full size).
void CheckPreview(const Photo& p, int32_t side, bool divides) {
  SCOPED_TRACE(p.path);
  RefocusEngine engine;
  RefocusEngineConfig c;
  c.max_width = 800;
  c.max_height = 600;
  c.max_blur_radius = 16;
  c.preview_side = side;
  ASSERT_TRUE(engine.Configure(c).ok());
  ASSERT_TRUE(engine.Load(p.path.c_str()).ok());
  const EnginePhoto& e = engine.photo();
  const int32_t step = (std::max(e.width, e.height) + side - 1) / side;
  ASSERT_GT(step, 1);
  EXPECT_EQ(e.working_scale % step == 0, divides);
  ASSERT_TRUE(engine.RenderPreview(e.current).ok());
  const Luma before = Decode(Output(engine));
  ASSERT_TRUE(engine.RenderPreview(TapAt(p, p.new_x, p.new_y)).ok());
  const Luma after = Decode(Output(engine));
  EXPECT_EQ(after.width, e.preview_width);
  EXPECT_LE(std::max(after.width, after.height), side);
  EXPECT_GE(after.width, e.width / step - 16);
  EXPECT_GT(Sharpness(after, p.new_x, p.new_y, 4), 1.5 * Sharpness(before, p.new_x, p.new_y, 4));
  EXPECT_LT(Sharpness(after, p.old_x, p.old_y, 8), 0.8 * Sharpness(before, p.old_x, p.old_y, 8));
}

TEST_F(RefocusEngineTest, PreviewFocusMovesFromAResampledDepthMap) {
  CheckPreview(photos_->front(), 200, false);
}

TEST_F(RefocusEngineTest, PreviewFocusMovesFromTheStoredDepthMap) {
  // 704 px wide: the pipeline works at half size (at most 640 px), and a 400 px preview is too.
  CheckPreview(MakePhoto(*dir_, "IMG_d.jpg", 704, 528), 400, true);
}

TEST_F(RefocusEngineTest, DamagedFilesNeverCrashIt) {
  RefocusEngine engine;
  ASSERT_TRUE(engine.Configure(Config()).ok());
  const std::vector<uint8_t> good = ReadFile(photos_->front().path);
  const std::string bad = dir_->Path("damaged.jpg");
  uint32_t seed = 12345;
  int refused = 0;
  for (int i = 0; i < 60; ++i) {
    std::vector<uint8_t> bytes = good;
    for (int k = 0; k < 1 + i % 4; ++k) {
      seed = seed * 1664525u + 1013904223u;
      // Most of the file is the XMP (depth and original): damage lands there and in the image.
      bytes[seed % bytes.size()] ^= static_cast<uint8_t>(1 + (seed >> 24) % 255);
    }
    FILE* f = fopen(bad.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    fwrite(bytes.data(), 1, bytes.size(), f);
    fclose(f);
    const Status s = engine.Load(bad.c_str());
    if (!s.ok()) {
      ++refused;
      EXPECT_FALSE(engine.loaded());
    } else {
      EXPECT_TRUE(engine.RenderPreview(engine.photo().current).ok());
    }
  }
  EXPECT_GT(refused, 0);
  EXPECT_TRUE(engine.Load(photos_->front().path.c_str()).ok());
}

TEST_F(RefocusEngineTest, RefusesWhatItCannotTake) {
  RefocusEngine small;
  RefocusEngineConfig c = Config();
  c.max_width = 128;
  c.max_height = 96;
  ASSERT_TRUE(small.Configure(c).ok());
  Status s = small.Load(photos_->front().path.c_str());
  EXPECT_EQ(s.code(), Code::kOutOfMemory) << s.message();
  EXPECT_FALSE(small.loaded());
  EXPECT_FALSE(small.RenderPreview(RenderParams()).ok());

  RefocusEngine engine;
  ASSERT_TRUE(engine.Configure(Config()).ok());
  // A plain JPEG (no depth map), a truncated photo and a missing file.
  const std::string plain = dir_->Path("plain.jpg");
  {
    SyntheticSensor sensor;
    Job job;
    JobOptions o;
    o.sensor.width = 128;
    o.sensor.height = 96;
    o.refocusable = false;
    ASSERT_TRUE(job.Configure(&sensor, o).ok());
    ASSERT_TRUE(job.Run(plain.c_str(), nullptr).ok());
  }
  EXPECT_EQ(engine.Load(plain.c_str()).code(), Code::kUnsupported);
  std::vector<uint8_t> bytes = ReadFile(photos_->front().path);
  const std::string cut = dir_->Path("cut.jpg");
  for (size_t keep : {size_t{3}, bytes.size() / 3, bytes.size() / 2}) {
    FILE* f = fopen(cut.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    fwrite(bytes.data(), 1, keep, f);
    fclose(f);
    EXPECT_FALSE(engine.Load(cut.c_str()).ok()) << keep;
  }
  EXPECT_EQ(engine.Load(dir_->Path("absent.jpg").c_str()).code(), Code::kNotFound);
  // A link put where a photo was checked is not followed (the page names files, not links).
  const std::string link = dir_->Path("link.jpg");
  ASSERT_EQ(symlink(photos_->front().path.c_str(), link.c_str()), 0);
  EXPECT_FALSE(engine.Load(link.c_str()).ok());
  // After all that, a good photo still loads.
  EXPECT_TRUE(engine.Load(photos_->front().path.c_str()).ok());
}

TEST_F(RefocusEngineTest, WaitsWhileTheCameraIsBusy) {
  std::atomic<bool> busy{true};
  RefocusEngine engine;
  ASSERT_TRUE(engine.Configure(Config()).ok());
  const Photo& p = photos_->front();
  ASSERT_TRUE(engine.Load(p.path.c_str()).ok());
  engine.set_camera_busy(&busy);
  std::atomic<bool> done{false};
  std::thread render([&] {
    // Loading waits for the camera too; then the render, between strips.
    EXPECT_TRUE(engine.Load(p.path.c_str()).ok());
    EXPECT_TRUE(engine.RenderFull(TapAt(p, p.new_x, p.new_y)).ok());
    done = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_FALSE(done.load());
  busy = false;
  render.join();
  EXPECT_TRUE(done.load());
  EXPECT_GE(engine.paused_strips(), 1);
  EXPECT_GT(engine.output_size(), 0u);
}

// The page opens what `refocus rerender` opens: phones' Lens Blur files, their depth an 8-bit
// RGBA PNG at the photo's full size in the phone's own units (../shared/data/phone-depth;
// skipped when absent).
TEST(RefocusEnginePhoneFiles, OpensAndRendersAPhonesLensBlurFile) {
  const char* root = std::getenv("LB_SOURCE_DIR");
  const std::string dir = std::string(root ? root : ".") + "/../shared/data/phone-depth";
  struct stat st;
  if (stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    GTEST_SKIP() << dir << " is absent: no phone files to open";
  }
  // A landscape camera's engine, otherwise as configured by default: the phones' photos are
  // portrait, and their depth maps as large as they are.
  RefocusEngine engine;
  RefocusEngineConfig c;
  c.max_width = 1024;
  c.max_height = 768;
  c.threads = 2;
  c.max_blur_radius = 16;
  ASSERT_TRUE(engine.Configure(c).ok());
  struct PhoneFile {
    const char* name;
    int32_t width, height;
  };
  for (const PhoneFile& f :
       {PhoneFile{"lensblur_table.jpg", 768, 1024}, PhoneFile{"lensblur_depthy1.jpg", 580, 1024}}) {
    SCOPED_TRACE(f.name);
    const Status s = engine.Load((dir + "/" + f.name).c_str());
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_EQ(engine.photo().width, f.width);
    EXPECT_EQ(engine.photo().height, f.height);
    ASSERT_TRUE(engine.RenderPreview(engine.photo().current).ok());
    EXPECT_GT(engine.output_size(), 0u);
    ASSERT_TRUE(engine.RenderFull(engine.photo().current).ok());
    EXPECT_EQ(Decode(Output(engine)).width, f.width);
  }
}

}  // namespace
}  // namespace lb
