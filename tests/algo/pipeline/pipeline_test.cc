// The pipeline end to end on the synthetic scene: the memory discipline (nothing allocated
// between Configure and the last rendered strip), the output's independence of the CPU
// architecture, and the burst bookkeeping a sensor relies on.
#include "algo/pipeline/pipeline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "algo/core/color.h"

#include "tests/algo/pipeline/pipeline_burst.h"
#include "tests/support/alloc_counter.h"

namespace lb {
namespace {

using pipelinetest::Burst;
using pipelinetest::ExpectBoardPathAllocatesNothing;
using pipelinetest::ImageChecksum;
using pipelinetest::RenderChecksum;

TEST(Pipeline, NothingIsAllocatedBetweenConfigureAndTheLastStrip) {
  Burst b;
  b.Setup(160, 120, 5);
  RenderParams params;
  params.f_number = 2.0f;
  const size_t before = testing::AllocationCount();
  ASSERT_TRUE(b.sensor->CaptureBurst(b.pipeline).ok());
  ASSERT_TRUE(b.pipeline.ComputeDepth().ok());
  int32_t rows = 0;
  (void)RenderChecksum(b.pipeline, params, &rows);
  const size_t after = testing::AllocationCount();
  EXPECT_EQ(rows, 120);
  EXPECT_EQ(after - before, 0u) << "heap allocations during capture, depth and render";
}

TEST(Pipeline, TheBoardsDefaultPathAtQuarterSizeAllocatesNothingAfterConfigure) {
  // Small enough for the sanitizers (the full sizes: pipeline_board_test.cc, label data): the
  // board's path at 640x480, depth at 320x240, the hand moving twice as far (at this working
  // size the default motion shows under the 1 px of parallax the motion stage asks for).
  ExpectBoardPathAllocatesNothing(640, 480, 320, 240, 0.02);
}

TEST(Pipeline, TheBoardsDefaultPathAllocatesNothingWithThreeThreads) {
  ExpectBoardPathAllocatesNothing(640, 480, 320, 240, 0.02, 3);
}

// Random frames of `format` through the ingest, split over `threads` workers: a checksum of the
// full-resolution reference and the working views.
uint64_t IngestChecksum(PixelFormat format, int32_t width, int32_t height, int32_t max_working,
                        int32_t threads) {
  PipelineConfig c;
  c.width = width;
  c.height = height;
  c.frames = 2;
  c.reference = 1;
  c.labels = 8;
  c.max_working_width = c.max_working_height = max_working;
  c.workers = threads;
  size_t bytes = 0;
  EXPECT_TRUE(Pipeline::RequiredBytes(c, &bytes).ok());
  std::unique_ptr<void, decltype(&free)> arena(aligned_alloc(Arena::kAlign, Arena::RoundUp(bytes)),
                                               &free);
  Pipeline p;
  EXPECT_TRUE(p.Configure(c, arena.get(), bytes).ok());
  WorkerPool pool;
  EXPECT_TRUE(pool.Start(threads).ok());
  p.SetRunner(&pool);
  const ptrdiff_t stride = static_cast<ptrdiff_t>(width) * BytesPerPixel(format);
  std::vector<uint8_t> frame(static_cast<size_t>(stride) * height), uv(frame.size());
  uint32_t seed = 12345;
  for (int32_t f = 0; f < 2; ++f) {
    for (uint8_t& b : frame) b = static_cast<uint8_t>((seed = seed * 1664525u + 1013904223u) >> 24);
    for (uint8_t& b : uv) b = static_cast<uint8_t>((seed = seed * 1664525u + 1013904223u) >> 24);
    FrameInfo info;
    info.index = f;
    info.format = format;
    info.width = width;
    info.height = height;
    EXPECT_TRUE(p.BeginFrame(info).ok());
    for (int32_t y0 = 0; y0 < height; y0 += 16) {
      FrameRows rows;
      rows.y0 = y0;
      rows.height = std::min(16, height - y0);
      rows.planes[0] = frame.data() + y0 * stride;
      rows.strides[0] = stride;
      rows.planes[1] = uv.data() + (y0 / 2) * stride;
      rows.strides[1] = stride;
      if (format == PixelFormat::kI420) {  // U and V rows of half the luma's stride
        rows.strides[1] = rows.strides[2] = stride / 2;
        rows.planes[1] = uv.data() + (y0 / 2) * (stride / 2);
        rows.planes[2] = rows.planes[1] + uv.size() / 2;
      }
      EXPECT_TRUE(p.Rows(rows).ok());
    }
    EXPECT_TRUE(p.EndFrame().ok());
  }
  uint64_t h = 0;
  for (int32_t i = 0; i < 3; ++i) h ^= ImageChecksum(p.reference().planes[i]) * (i + 1);
  for (int32_t f = 0; f < 2; ++f) h ^= ImageChecksum(p.working_view(f)) * (f + 7);
  return h;
}

// The ingest splits every strip into bands of columns: the same reference and working views
// for any number of threads, in every sensor format, with odd and even box sizes and widths.
TEST(Pipeline, IngestGivesTheSameBytesForAnyNumberOfThreads) {
  for (PixelFormat format :
       {PixelFormat::kRgb8, PixelFormat::kYuyv, PixelFormat::kNv12, PixelFormat::kGray16,
        PixelFormat::kBgr8, PixelFormat::kI420, PixelFormat::kRgbx8, PixelFormat::kBgrx8}) {
    for (const auto& [w, h, working] :
         {std::tuple{998, 302, 334}, {640, 480, 320}, {401, 97, 100}}) {
      SCOPED_TRACE(std::string(PixelFormatName(format)) + " " + std::to_string(w) + "x" +
                   std::to_string(h));
      if ((format == PixelFormat::kYuyv || PlaneCount(format) > 1) && w % 2 != 0) continue;
      const uint64_t one = IngestChecksum(format, w, h, working, 1);
      for (int32_t threads : {2, 3, 4}) {
        EXPECT_EQ(IngestChecksum(format, w, h, working, threads), one) << threads << " threads";
      }
    }
  }
}

// The motion and depth stages, the map and the render share memory (pipeline.h): the map and its
// confidence outlive every render, a second render gives the same photo, and a second burst
// through the same pipeline, after a render, gives the first one's depth and photo again.
TEST(Pipeline, ASecondBurstAfterARenderGivesTheSameResult) {
  Burst b;
  b.config.max_working_width = 320;
  b.config.max_working_height = 240;
  b.SetupBoard(640, 480, 5, 0.02);
  RenderParams params;
  params.f_number = 2.0f;
  uint64_t disparity[2] = {}, map[2] = {}, photo[2] = {};
  for (int32_t run = 0; run < 2; ++run) {
    b.pipeline.ResetBurst();
    ASSERT_TRUE(b.sensor->CaptureBurst(b.pipeline).ok());
    ASSERT_TRUE(b.pipeline.ComputeDepth().ok());
    ASSERT_TRUE(b.pipeline.depth_warning().ok()) << b.pipeline.depth_warning().message();
    disparity[run] = ImageChecksum(b.pipeline.disparity_q8());
    map[run] = ImageChecksum(b.pipeline.map_q8()) ^ ImageChecksum(b.pipeline.map_confidence());
    int32_t rows = 0;
    photo[run] = RenderChecksum(b.pipeline, params, &rows);
    ASSERT_EQ(rows, 480);
    EXPECT_EQ(ImageChecksum(b.pipeline.map_q8()) ^ ImageChecksum(b.pipeline.map_confidence()),
              map[run])
        << "the render wrote over the map";
    EXPECT_EQ(RenderChecksum(b.pipeline, params, &rows), photo[run]) << "a second render";
  }
  EXPECT_EQ(disparity[1], disparity[0]);
  EXPECT_EQ(map[1], map[0]);
  EXPECT_EQ(photo[1], photo[0]);
}

// The board's 12 MP sensor with the defaults (motion, depth with its confidence, the map and the
// render) within the board's 48 MiB of arena.
TEST(Pipeline, TheTwelveMegapixelPhotoFitsTheBoardsArena) {
  PipelineConfig c;
  c.width = 4056;
  c.height = 3040;
  c.frames = 5;
  c.reference = 2;
  c.geometry = ViewGeometry::kAuto;
  c.labels = 32;
  c.workers = 4;
  size_t bytes = 0;
  ASSERT_TRUE(Pipeline::RequiredBytes(c, &bytes).ok());
  EXPECT_LE(bytes, size_t{48} << 20) << Pipeline::WorkingScale(c);
}

// The board's path gives the same depth and photo, bit for bit, whatever the number of threads:
// every task writes its own rows, and scratch is per worker.
TEST(Pipeline, TheOutputDoesNotDependOnTheNumberOfThreads) {
  uint64_t disparity[4] = {}, photo[4] = {};
  for (int32_t threads = 1; threads <= 4; ++threads) {
    Burst b;
    b.config.workers = threads;
    b.config.max_working_width = 320;
    b.config.max_working_height = 240;
    b.SetupBoard(640, 480, 5, 0.02);
    ASSERT_TRUE(b.sensor->CaptureBurst(b.pipeline).ok());
    ASSERT_TRUE(b.pipeline.ComputeDepth().ok());
    ASSERT_TRUE(b.pipeline.depth_warning().ok()) << b.pipeline.depth_warning().message();
    RenderParams params;
    params.f_number = 2.0f;
    int32_t rows = 0;
    disparity[threads - 1] = ImageChecksum(b.pipeline.disparity_q8());
    photo[threads - 1] = RenderChecksum(b.pipeline, params, &rows);
    ASSERT_EQ(rows, 480);
    EXPECT_EQ(disparity[threads - 1], disparity[0]) << threads << " threads";
    EXPECT_EQ(photo[threads - 1], photo[0]) << threads << " threads";
  }
}

// Bounds of the golden burst's figures, with room for a change that makes a stage a little
// worse: measured 1.14 % bad pixels, 26.0 dB in focus, 0.36 of the frame's detail energy left.
constexpr double kMaxBadPixels = 0.025;
constexpr double kMinFocusPsnr = 23.0;
constexpr double kMaxDetailRatio = 0.55;

// The burst and render of the checksum below, and the tests that say what its figures mean.
constexpr int32_t kGoldenWidth = 192, kGoldenHeight = 144;
RenderParams GoldenRender() {
  RenderParams params;
  params.f_number = 1.8f;
  params.focus = {80, 60, 32, 24};
  return params;
}

// Every working view against a float box-downscale of its frame (the scene rendered again):
// the mean of each scale x scale block, rounded.
double WorstViewError(Burst& b) {
  Scene& scene = b.sensor->scene();
  const int32_t s = b.pipeline.working_scale(), w = b.pipeline.working_width();
  const int32_t width = b.config.width;
  std::vector<uint8_t> rows(static_cast<size_t>(width) * 3 * s);
  double worst = 0;
  for (int32_t v = 0; v < b.config.frames; ++v) {
    const ConstImageU8 view = b.pipeline.working_view(v);
    for (int32_t y = 0; y < b.pipeline.working_height(); ++y) {
      EXPECT_TRUE(scene.RenderRows(v, y * s, s, rows.data(), width * 3).ok());
      for (int32_t x = 0; x < w; ++x) {
        for (int32_t c = 0; c < 3; ++c) {
          double sum = 0;
          for (int32_t j = 0; j < s; ++j) {
            for (int32_t i = 0; i < s; ++i) sum += rows[(j * width + x * s + i) * 3 + c];
          }
          worst = std::max(worst, std::fabs(view.Row(y)[3 * x + c] - sum / (s * s)));
        }
      }
    }
  }
  return worst;
}

// Share of working pixels whose disparity is off the scene's truth by more than 1 px.
double BadPixelRate(Burst& b) {
  const int32_t w = b.pipeline.working_width(), h = b.pipeline.working_height();
  std::vector<uint16_t> truth(static_cast<size_t>(w) * h);
  EXPECT_TRUE(
      b.sensor->scene().DisparityRows(b.pipeline.working_scale(), 0, h, truth.data(), w).ok());
  const ConstImageU16 disp = b.pipeline.disparity_q8();
  const int32_t bias = DepthStage::MapBiasQ8(b.pipeline.disp_min_q8());
  int64_t bad = 0;
  for (int32_t y = 0; y < h; ++y) {
    for (int32_t x = 0; x < w; ++x) bad += std::abs(disp.Row(y)[x] - bias - truth[y * w + x]) > 256;
  }
  return static_cast<double>(bad) / (int64_t{w} * h);
}

// The rendered luma, whole frame.
std::vector<uint8_t> RenderLuma(Pipeline& p, const RenderParams& params) {
  std::vector<uint8_t> luma(static_cast<size_t>(p.working_width()) * p.working_scale() *
                            p.working_height() * p.working_scale());
  EXPECT_TRUE(p.BeginRender(params).ok());
  for (;;) {
    ConstPlanarU8 strip;
    int32_t y0 = 0, rows = 0;
    EXPECT_TRUE(p.NextStrip(&strip, &y0, &rows).ok());
    if (rows == 0) break;
    const ConstImageU8& y = strip.planes[0];
    for (int32_t r = 0; r < rows; ++r) {
      std::copy(y.Row(r), y.Row(r) + y.width,
                luma.begin() + static_cast<ptrdiff_t>(y0 + r) * y.width);
    }
  }
  return luma;
}

struct LumaFigures {
  double focus_psnr = 0;    // dB, render against the sharp reference inside the focus region
  double detail_ratio = 0;  // the render's horizontal detail energy over the reference's
};

LumaFigures RenderFigures(Burst& b, const RenderParams& params) {
  const int32_t width = b.config.width, height = b.config.height;
  const std::vector<uint8_t> out = RenderLuma(b.pipeline, params);
  std::vector<uint8_t> rgb(static_cast<size_t>(width) * 3),
      ref(static_cast<size_t>(width) * height);
  for (int32_t y = 0; y < height; ++y) {
    EXPECT_TRUE(b.sensor->scene().RenderRows(b.config.reference, y, 1, rgb.data(), width * 3).ok());
    RowRgb8ToY(rgb.data(), width, ref.data() + static_cast<size_t>(y) * width);
  }
  const FocusRegion& f = params.focus;
  double se = 0, detail_out = 0, detail_ref = 0;
  for (int32_t y = 0; y < height; ++y) {
    for (int32_t x = 0; x < width; ++x) {
      const size_t p = static_cast<size_t>(y) * width + x;
      if (x >= f.x && x < f.x + f.width && y >= f.y && y < f.y + f.height) {
        se += (out[p] - ref[p]) * (out[p] - ref[p]);
      }
      if (x + 1 < width) {
        detail_out += (out[p + 1] - out[p]) * (out[p + 1] - out[p]);
        detail_ref += (ref[p + 1] - ref[p]) * (ref[p + 1] - ref[p]);
      }
    }
  }
  const double mse = se / (f.width * f.height);
  LumaFigures figures;
  figures.focus_psnr = mse > 0 ? 10 * std::log10(255.0 * 255.0 / mse) : 99;
  figures.detail_ratio = detail_out / detail_ref;
  return figures;
}

// What the checksum's three figures stand for, with stated tolerances, so that a deliberate
// change to a stage reads as better or worse instead of only "different".
TEST(Pipeline, GoldenBurstWorkingViewsAreBoxDownscalesOfTheFrames) {
  Burst b;
  b.Setup(kGoldenWidth, kGoldenHeight, 5);
  ASSERT_TRUE(b.sensor->CaptureBurst(b.pipeline).ok());
  const double worst = WorstViewError(b);
  RecordProperty("worst_view_error", std::to_string(worst));
  EXPECT_LE(worst, 1.0);
  Burst scaled;  // the same at a working scale of 3, where the downscale does something
  scaled.config.max_working_width = kGoldenWidth;
  scaled.config.max_working_height = kGoldenHeight;
  scaled.Setup(3 * kGoldenWidth, 3 * kGoldenHeight, 5);
  ASSERT_EQ(scaled.pipeline.working_scale(), 3);
  ASSERT_TRUE(scaled.sensor->CaptureBurst(scaled.pipeline).ok());
  const double worst_scaled = WorstViewError(scaled);
  RecordProperty("worst_view_error_scale_3", std::to_string(worst_scaled));
  EXPECT_LE(worst_scaled, 1.0);
}

TEST(Pipeline, GoldenBurstDisparityIsCloseToTheScenesTruth) {
  Burst b;
  b.Setup(kGoldenWidth, kGoldenHeight, 5);
  ASSERT_TRUE(b.sensor->CaptureBurst(b.pipeline).ok());
  ASSERT_TRUE(b.pipeline.ComputeDepth().ok());
  const double bad = BadPixelRate(b);
  RecordProperty("bad_pixel_percent", std::to_string(100 * bad));
  EXPECT_LT(bad, kMaxBadPixels) << "pixels off the true disparity by more than 1 px";
}

TEST(Pipeline, GoldenBurstRenderIsSharpInFocusAndBlurredElsewhere) {
  Burst b;
  b.Setup(kGoldenWidth, kGoldenHeight, 5);
  ASSERT_TRUE(b.sensor->CaptureBurst(b.pipeline).ok());
  ASSERT_TRUE(b.pipeline.ComputeDepth().ok());
  const LumaFigures figures = RenderFigures(b, GoldenRender());
  RecordProperty("focus_psnr_db", std::to_string(figures.focus_psnr));
  RecordProperty("detail_ratio", std::to_string(figures.detail_ratio));
  EXPECT_GT(figures.focus_psnr, kMinFocusPsnr) << "the focus region against the sharp frame";
  EXPECT_LT(figures.detail_ratio, kMaxDetailRatio) << "the background is not blurred";
}

// The same burst must give the same output samples on every architecture the firmware ships
// for (x86-64 here, aarch64 and armhf under qemu in CI). The expected value is the checksum of
// the current algorithms; it changes only when a stage deliberately changes its output. The
// GoldenBurst tests above say whether such a change kept each stage within its tolerance.
constexpr char kExpectedChecksum[] = "0ea153a574147db4 f5b2c4eecb1dcede 60bda03f677e06d8";

TEST(Pipeline, RenderedImageIsTheSameOnEveryArchitecture) {
  Burst b;
  b.Setup(kGoldenWidth, kGoldenHeight, 5);
  ASSERT_TRUE(b.sensor->CaptureBurst(b.pipeline).ok());
  ASSERT_TRUE(b.pipeline.ComputeDepth().ok());
  const RenderParams params = GoldenRender();
  int32_t rows = 0;
  // One checksum per stage, so a mismatch says which stage diverged.
  uint64_t views = 1469598103934665603ull;
  for (int32_t i = 0; i < b.config.frames; ++i) views ^= ImageChecksum(b.pipeline.working_view(i));
  const uint64_t depth = ImageChecksum(b.pipeline.disparity_q8());
  const uint64_t render = RenderChecksum(b.pipeline, params, &rows);
  EXPECT_EQ(rows, kGoldenHeight);
  char actual[64];
  snprintf(actual, sizeof(actual), "%016" PRIx64 " %016" PRIx64 " %016" PRIx64, views, depth,
           render);
  const char* expected = getenv("LB_EXPECT_CHECKSUM");  // lets a developer re-derive it
  EXPECT_STREQ(actual, expected ? expected : kExpectedChecksum)
      << "checksums of: the working views, the disparity, the rendered image. If the Pipeline."
         "GoldenBurst* tests pass, the change kept the views, the depth and the render within "
         "their tolerances: re-derive the value (LB_EXPECT_CHECKSUM) on x86-64 and check it "
         "matches under aarch64 and armhf; if one of them fails, that stage got worse";
}

TEST(Pipeline, MissingAndRepeatedFramesAreReported) {
  Burst b;
  b.Setup(96, 64, 3);
  Status s = b.pipeline.ComputeDepth();
  EXPECT_EQ(s.code(), Code::kNotFound);
  EXPECT_NE(std::string(s.message()).find("frame 0"), std::string::npos) << s.message();
  FrameInfo info;
  info.index = 1;
  info.width = 96;
  info.height = 64;
  ASSERT_TRUE(b.pipeline.BeginFrame(info).ok());
  EXPECT_EQ(b.pipeline.EndFrame().code(), Code::kCorruptData);  // no rows delivered
  info.width = 95;
  EXPECT_EQ(b.pipeline.BeginFrame(info).code(), Code::kInvalidArgument);  // wrong size
}

TEST(Pipeline, ABurstOfOneFrameIsRejectedBeforeAnythingIsAllocated) {
  PipelineConfig c;
  c.width = 64;
  c.height = 48;
  c.frames = 1;
  size_t bytes = 1;
  Status s = Pipeline::RequiredBytes(c, &bytes);
  EXPECT_EQ(s.code(), Code::kInvalidArgument);
  EXPECT_EQ(bytes, 0u);
  EXPECT_NE(std::string(s.message()).find("at least 2"), std::string::npos) << s.message();
}

// The working bound is a budget of pixels: a frame turned on its side, or square, is not
// shrunk further than a landscape one of the same size (a light field's 512x512 views keep
// their parallax; a portrait 12 MP burst gets the landscape one's grid).
TEST(Pipeline, TheWorkingSizeIsAPixelBudgetWhicheverWayTheFrameIsTurned) {
  auto scale = [](int32_t w, int32_t h) {
    PipelineConfig c;
    c.width = w;
    c.height = h;
    return Pipeline::WorkingScale(c);
  };
  EXPECT_EQ(scale(1280, 960), 2);
  EXPECT_EQ(scale(4056, 3040), 6);  // the board's 12 MP sensor: 676x506
  EXPECT_EQ(scale(3040, 4056), 6);
  EXPECT_EQ(scale(960, 1280), 2);
  EXPECT_EQ(scale(512, 512), 1);
  EXPECT_EQ(scale(1920, 1080), 3);
  EXPECT_EQ(scale(1080, 1920), 3);
  // Within the budget but longer than its longer side: still shrunk.
  EXPECT_EQ(scale(1000, 100), 2);
  const PipelineConfig defaults;
  const int32_t budget = defaults.max_working_width * defaults.max_working_height;
  const int32_t longest = std::max(defaults.max_working_width, defaults.max_working_height);
  for (const auto& [w, h] : {std::pair{4056, 3040}, {3040, 4056}, {700, 700}, {6000, 4000}}) {
    const int32_t s = scale(w, h);
    EXPECT_LE((w / s) * (h / s), budget) << w << "x" << h;
    EXPECT_LE(std::max(w / s, h / s), longest) << w << "x" << h;
    EXPECT_TRUE(s == 1 || (w / (s - 1)) * (h / (s - 1)) > budget ||
                std::max(w / (s - 1), h / (s - 1)) > longest)
        << w << "x" << h << ": " << s - 1 << " would fit";
  }
}

TEST(Pipeline, TakesRectifiedOrAutoGeometryOnly) {
  PipelineConfig c;
  c.width = 64;
  c.height = 48;
  size_t bytes = 0;
  for (const ViewGeometry g : {ViewGeometry::kRectified, ViewGeometry::kAuto}) {
    c.geometry = g;
    EXPECT_TRUE(Pipeline::RequiredBytes(c, &bytes).ok()) << static_cast<int>(g);
  }
  for (const ViewGeometry g : {ViewGeometry::kHandheld, ViewGeometry::kKnownPoses}) {
    c.geometry = g;
    EXPECT_EQ(Pipeline::RequiredBytes(c, &bytes).code(), Code::kInvalidArgument)
        << static_cast<int>(g);
  }
}

// `refocus depth`'s road: a depth-only pipeline carves nothing for the render, refuses one, takes
// frames as small as the depth stage does, and computes the map a rendering pipeline does.
TEST(Pipeline, ADepthOnlyRunGivesTheSameMapAndNoRender) {
  Burst full;
  full.Setup(160, 120, 5);
  ASSERT_TRUE(full.sensor->CaptureBurst(full.pipeline).ok());
  ASSERT_TRUE(full.pipeline.ComputeDepth().ok());

  Burst depth;
  SceneParams scene;
  scene.seed = 7;
  ASSERT_NO_FATAL_FAILURE(depth.Open(scene, 160, 120, 5));
  depth.config = full.config;
  depth.config.render = false;
  ASSERT_NO_FATAL_FAILURE(depth.ConfigurePipeline());
  ASSERT_TRUE(depth.sensor->CaptureBurst(depth.pipeline).ok());
  ASSERT_TRUE(depth.pipeline.ComputeDepth().ok());
  EXPECT_EQ(ImageChecksum(depth.pipeline.disparity_q8()),
            ImageChecksum(full.pipeline.disparity_q8()));
  EXPECT_EQ(depth.pipeline.disp_max_q8(), full.pipeline.disp_max_q8());
  EXPECT_EQ(depth.pipeline.BeginRender(RenderParams()).code(), Code::kInvalidArgument);
  size_t with = 0, without = 0;
  ASSERT_TRUE(Pipeline::RequiredBytes(full.config, &with).ok());
  ASSERT_TRUE(Pipeline::RequiredBytes(depth.config, &without).ok());
  EXPECT_LE(without, with);

  PipelineConfig tiny;
  tiny.width = tiny.height = DepthConfig::kMinSize;
  tiny.render = false;
  EXPECT_TRUE(Pipeline::RequiredBytes(tiny, &without).ok());
  tiny.render = true;
  EXPECT_EQ(Pipeline::RequiredBytes(tiny, &with).code(), Code::kInvalidArgument);
}

}  // namespace
}  // namespace lb
