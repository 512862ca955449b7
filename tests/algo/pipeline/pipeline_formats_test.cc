// The formats Raspberry Pi's libcamera delivers, through the ingest: an I420 burst (three
// planes, padded rows, full range) and 32-bit RGB bursts give the same working views and
// full-resolution reference as the RGB8 burst they encode.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <vector>

#include "algo/core/color.h"
#include "algo/pipeline/pipeline.h"
#include "tests/algo/pipeline/pipeline_burst.h"

namespace lb {
namespace {

using pipelinetest::ImageChecksum;

constexpr int32_t kW = 160, kH = 120, kFrames = 3;

// One frame in memory as a camera lays it out: up to three planes, rows padded.
struct Frame {
  std::vector<uint8_t> plane[3];
  ptrdiff_t stride[3] = {0, 0, 0};
};

// What the ingest keeps of a burst: the reference's three planes and every working view.
struct Ingested {
  uint64_t sums[3 + kFrames] = {};
  bool operator==(const Ingested& o) const { return std::equal(sums, sums + 3 + kFrames, o.sums); }
};

Ingested Ingest(PixelFormat format, YuvRange range, const std::vector<Frame>& frames) {
  PipelineConfig c;
  c.width = kW;
  c.height = kH;
  c.frames = kFrames;
  c.reference = 1;
  c.labels = 8;
  c.max_working_width = c.max_working_height = 60;  // scale 3: odd boxes, bands of 2 columns
  c.workers = 3;
  size_t bytes = 0;
  EXPECT_TRUE(Pipeline::RequiredBytes(c, &bytes).ok());
  std::unique_ptr<void, decltype(&free)> arena(aligned_alloc(Arena::kAlign, Arena::RoundUp(bytes)),
                                               &free);
  Pipeline p;
  EXPECT_TRUE(p.Configure(c, arena.get(), bytes).ok());
  WorkerPool pool;
  EXPECT_TRUE(pool.Start(c.workers).ok());
  p.SetRunner(&pool);
  const int32_t strip_rows[] = {16, 6, 10, 2, 24};  // even: 4:2:0 strips start on even rows
  for (int32_t f = 0; f < kFrames; ++f) {
    FrameInfo info;
    info.index = f;
    info.format = format;
    info.width = kW;
    info.height = kH;
    info.range = range;
    EXPECT_TRUE(p.BeginFrame(info).ok());
    for (int32_t y0 = 0, s = 0; y0 < kH; ++s) {
      FrameRows rows;
      rows.y0 = y0;
      rows.height = std::min(strip_rows[s % 5], kH - y0);
      for (int32_t k = 0; k < PlaneCount(format); ++k) {
        const int32_t first = k == 0 ? y0 : y0 / 2;
        rows.planes[k] = frames[f].plane[k].data() + frames[f].stride[k] * first;
        rows.strides[k] = frames[f].stride[k];
      }
      const Status st = p.Rows(rows);
      EXPECT_TRUE(st.ok()) << st.message();
      y0 += rows.height;
    }
    EXPECT_TRUE(p.EndFrame().ok());
  }
  Ingested out;
  for (int32_t i = 0; i < 3; ++i) out.sums[i] = ImageChecksum(p.reference().planes[i]);
  for (int32_t f = 0; f < kFrames; ++f) out.sums[3 + f] = ImageChecksum(p.working_view(f));
  return out;
}

uint8_t Random(uint32_t* seed) {
  *seed = *seed * 1664525u + 1013904223u;
  return static_cast<uint8_t>(*seed >> 24);
}

Frame Rgb8Frame(const std::vector<uint8_t>& rgb) {
  Frame f;
  f.stride[0] = kW * 3;
  f.plane[0] = rgb;
  return f;
}

// Full-range I420 frames of random samples with padded rows, and the RGB8 frames they encode,
// converted pixel by pixel (each pixel's chroma at (x / 2, y / 2)).
void I420Burst(std::vector<Frame>* i420, std::vector<Frame>* rgb8) {
  uint32_t seed = 99;
  for (int32_t f = 0; f < kFrames; ++f) {
    Frame yuv;
    yuv.stride[0] = kW + 32;
    yuv.stride[1] = yuv.stride[2] = kW / 2 + 16;
    yuv.plane[0].resize(static_cast<size_t>(yuv.stride[0]) * kH);
    for (int k = 1; k < 3; ++k) yuv.plane[k].resize(static_cast<size_t>(yuv.stride[k]) * kH / 2);
    for (auto& plane : yuv.plane) {
      for (uint8_t& b : plane) b = Random(&seed);
    }
    std::vector<uint8_t> rgb(static_cast<size_t>(kW) * kH * 3);
    for (int32_t y = 0; y < kH; ++y) {
      for (int32_t x = 0; x < kW; ++x) {
        const ptrdiff_t c = yuv.stride[1] * (y / 2) + x / 2;
        YCbCrToRgb8(yuv.plane[0][yuv.stride[0] * y + x], yuv.plane[1][c], yuv.plane[2][c],
                    &rgb[(static_cast<size_t>(y) * kW + x) * 3]);
      }
    }
    i420->push_back(std::move(yuv));
    rgb8->push_back(Rgb8Frame(rgb));
  }
}

TEST(PipelineFormats, FullRangeI420IngestsLikeTheRgbItEncodes) {
  std::vector<Frame> i420, rgb8;
  I420Burst(&i420, &rgb8);
  const Ingested want = Ingest(PixelFormat::kRgb8, YuvRange::kLimited, rgb8);
  EXPECT_TRUE(Ingest(PixelFormat::kI420, YuvRange::kFull, i420) == want);
  // The range is the frame's: the same bytes read as limited range are another picture.
  EXPECT_FALSE(Ingest(PixelFormat::kI420, YuvRange::kLimited, i420) == want);
}

// XRGB8888 (B, G, R, X in memory) and XBGR8888 (R, G, B, X), the unused byte set to junk.
TEST(PipelineFormats, ThirtyTwoBitRgbIngestsLikeRgb8) {
  uint32_t seed = 7;
  std::vector<Frame> rgb8, bgrx, rgbx;
  for (int32_t f = 0; f < kFrames; ++f) {
    std::vector<uint8_t> rgb(static_cast<size_t>(kW) * kH * 3);
    for (uint8_t& b : rgb) b = Random(&seed);
    Frame a, b;
    a.stride[0] = b.stride[0] = kW * 4 + 64;
    a.plane[0].resize(static_cast<size_t>(a.stride[0]) * kH);
    b.plane[0].resize(a.plane[0].size());
    for (int32_t y = 0; y < kH; ++y) {
      for (int32_t x = 0; x < kW; ++x) {
        const uint8_t* px = &rgb[(static_cast<size_t>(y) * kW + x) * 3];
        uint8_t* pa = &a.plane[0][a.stride[0] * y + 4 * x];
        uint8_t* pb = &b.plane[0][b.stride[0] * y + 4 * x];
        pa[0] = px[2], pa[1] = px[1], pa[2] = px[0], pa[3] = Random(&seed);
        pb[0] = px[0], pb[1] = px[1], pb[2] = px[2], pb[3] = Random(&seed);
      }
    }
    bgrx.push_back(std::move(a));
    rgbx.push_back(std::move(b));
    rgb8.push_back(Rgb8Frame(rgb));
  }
  const Ingested want = Ingest(PixelFormat::kRgb8, YuvRange::kLimited, rgb8);
  EXPECT_TRUE(Ingest(PixelFormat::kBgrx8, YuvRange::kLimited, bgrx) == want);
  EXPECT_TRUE(Ingest(PixelFormat::kRgbx8, YuvRange::kLimited, rgbx) == want);
}

// A 4:2:0 strip needs its chroma planes and an even first row.
TEST(PipelineFormats, I420RowsWithoutTheirPlanesAreRefused) {
  PipelineConfig c;
  c.width = 32;
  c.height = 32;
  c.frames = 2;
  c.reference = 1;
  c.labels = 8;
  size_t bytes = 0;
  ASSERT_TRUE(Pipeline::RequiredBytes(c, &bytes).ok());
  std::unique_ptr<void, decltype(&free)> arena(aligned_alloc(Arena::kAlign, Arena::RoundUp(bytes)),
                                               &free);
  Pipeline p;
  ASSERT_TRUE(p.Configure(c, arena.get(), bytes).ok());
  FrameInfo info;
  info.format = PixelFormat::kI420;
  info.width = info.height = 32;
  ASSERT_TRUE(p.BeginFrame(info).ok());
  std::vector<uint8_t> y(32 * 32), u(16 * 16), v(16 * 16);
  FrameRows rows;
  rows.height = 2;
  rows.planes[0] = y.data();
  rows.strides[0] = 32;
  rows.planes[1] = u.data();
  rows.strides[1] = 16;
  EXPECT_EQ(p.Rows(rows).code(), Code::kInvalidArgument);  // no V plane
  rows.planes[2] = v.data();
  rows.strides[2] = 16;
  rows.height = 1;
  EXPECT_TRUE(p.Rows(rows).ok());
  rows.y0 = 1;
  rows.planes[0] += 32;
  EXPECT_EQ(p.Rows(rows).code(), Code::kInvalidArgument);  // odd first row
}

}  // namespace
}  // namespace lb
