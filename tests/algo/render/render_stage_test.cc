#include "algo/render/render_stage.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <vector>

#include "tests/algo/render/render_util.h"
#include "tests/support/alloc_counter.h"
#include "tests/support/backwards_runner.h"

namespace lb {
namespace {

// A synthetic image described per full-resolution pixel: luma, chroma and disparity (working
// px), rendered through the stage at `scale`.
struct Image {
  int32_t w = 0, h = 0, scale = 1;
  std::vector<uint8_t> y, cb, cr;
  std::vector<uint16_t> disp;
  Image(int32_t width, int32_t height, int32_t s) : w(width), h(height), scale(s) {
    y.assign(w * h, 0);
    cb.assign(((w + 1) / 2) * ((h + 1) / 2), 128);
    cr.assign(cb.size(), 128);
    disp.assign((w / s) * (h / s), 0);
  }
  ConstPlanarU8 Planar() const {
    ConstPlanarU8 p;
    p.count = 3;
    p.planes[0] = MakeView(y.data(), w, h);
    p.planes[1] = MakeView(cb.data(), (w + 1) / 2, (h + 1) / 2);
    p.planes[2] = MakeView(cr.data(), (w + 1) / 2, (h + 1) / 2);
    return p;
  }
  ConstImageU16 Disp() const { return MakeView(disp.data(), w / scale, h / scale); }
  uint8_t& Y(int32_t x, int32_t yy) { return y[yy * w + x]; }
  uint16_t& D(int32_t wx, int32_t wy) { return disp[wy * (w / scale) + wx]; }
};

test::Rendered Render(const Image& im, const test::RenderSetup& setup) {
  test::Rendered out;
  const Status s = test::RenderAll(im.Planar(), im.Disp(), im.scale, setup, &out);
  EXPECT_TRUE(s.ok()) << s.message();
  return out;
}

TEST(RenderStage, AllInFocusIsTheIdentity) {
  Image im(97, 75, 3);  // odd sizes: a lone chroma column and row, a short last strip
  for (size_t i = 0; i < im.y.size(); ++i) im.y[i] = static_cast<uint8_t>(i * 37 % 251);
  for (size_t i = 0; i < im.cb.size(); ++i) im.cb[i] = static_cast<uint8_t>(i * 11 % 256);
  for (size_t i = 0; i < im.cr.size(); ++i) im.cr[i] = static_cast<uint8_t>(i * 5 % 256);
  for (uint16_t& d : im.disp) d = 3 << 8;
  const test::Rendered out = Render(im, {});
  EXPECT_EQ(out.y, im.y);
  EXPECT_EQ(out.cb, im.cb);
  EXPECT_EQ(out.cr, im.cr);
  EXPECT_EQ(out.strip_rows, (std::vector<int32_t>{16, 16, 16, 16, 11}));
}

TEST(RenderStage, FlatColourStaysFlatWhateverTheDepth) {
  Image im(64, 48, 4);
  for (uint8_t& v : im.y) v = 140;
  for (uint8_t& v : im.cb) v = 90;
  for (uint8_t& v : im.cr) v = 170;
  for (size_t i = 0; i < im.disp.size(); ++i) im.disp[i] = static_cast<uint16_t>(i * 997 % 3000);
  test::RenderSetup setup;
  setup.params.f_number = 1.4f;
  const test::Rendered out = Render(im, setup);
  for (uint8_t v : out.y) ASSERT_NEAR(v, 140, 1);
  for (uint8_t v : out.cb) ASSERT_NEAR(v, 90, 1);
  for (uint8_t v : out.cr) ASSERT_NEAR(v, 170, 1);
}

// Left half at disparity `left_disp` with luma `left_y`, right half likewise; focus on one side.
Image TwoHalves(int32_t left_y, uint16_t left_disp, int32_t right_y, uint16_t right_disp) {
  Image im(96, 64, 4);
  for (int32_t y = 0; y < im.h; ++y) {
    for (int32_t x = 0; x < im.w; ++x) im.Y(x, y) = static_cast<uint8_t>(x < 48 ? left_y : right_y);
  }
  for (int32_t wy = 0; wy < 16; ++wy) {
    for (int32_t wx = 0; wx < 24; ++wx) im.D(wx, wy) = wx < 12 ? left_disp : right_disp;
  }
  return im;
}

// Every size, scale and largest radius (kernels larger than the image, odd sizes, reduced
// levels down to 1/16): a flat colour stays flat under any depth and iris, so borders, tiles and
// levels neither lose nor invent light.
TEST(RenderStage, FlatColourStaysFlatForExtremeConfigurations) {
  struct Size {
    int32_t w, h, scale;
  };
  uint32_t seed = 7;
  auto next = [&seed] { return seed = seed * 1664525u + 1013904223u; };
  for (const Size& size : {Size{16, 16, 1}, Size{33, 17, 2}, Size{97, 75, 3}, Size{200, 40, 8}}) {
    for (int32_t radius : {0, 1, 7, 33, 128}) {
      Image im(size.w, size.h, size.scale);
      for (uint8_t& v : im.y) v = 77;
      for (uint8_t& v : im.cb) v = 200;
      for (uint8_t& v : im.cr) v = 30;
      for (uint16_t& d : im.disp) d = static_cast<uint16_t>(next() >> 16);
      test::RenderSetup setup;
      setup.max_radius = radius;
      setup.params.f_number = 1.4f;
      setup.params.aperture = {static_cast<int32_t>(next() % 2 ? 0 : 3 + next() % 10), 33.0f, 0.2f};
      const test::Rendered out = Render(im, setup);
      for (uint8_t v : out.y) ASSERT_NEAR(v, 77, 1) << size.w << "x" << size.h << " r" << radius;
      for (uint8_t v : out.cb) ASSERT_NEAR(v, 200, 1) << size.w << "x" << size.h << " r" << radius;
      for (uint8_t v : out.cr) ASSERT_NEAR(v, 30, 1) << size.w << "x" << size.h << " r" << radius;
    }
  }
}

// An image that repeats every 64 rows renders to one that repeats too, away from the top and
// bottom: the ring of rows (far shorter than the image) never hands a strip a wrong row.
TEST(RenderStage, StreamingIsShiftInvariant) {
  Image im(72, 640, 2);
  uint32_t seed = 11;
  auto next = [&seed] { return seed = seed * 1664525u + 1013904223u; };
  std::vector<uint8_t> tile_y(72 * 64), tile_c(36 * 32 * 2);
  std::vector<uint16_t> tile_d(36 * 32);
  for (uint8_t& v : tile_y) v = static_cast<uint8_t>(next() >> 24);
  for (uint8_t& v : tile_c) v = static_cast<uint8_t>(next() >> 24);
  for (uint16_t& d : tile_d) d = static_cast<uint16_t>((next() >> 24) * 6);  // 0 .. 6 px
  for (int32_t y = 0; y < im.h; ++y) {
    for (int32_t x = 0; x < im.w; ++x) im.Y(x, y) = tile_y[(y % 64) * 72 + x];
  }
  for (int32_t y = 0; y < im.h / 2; ++y) {
    for (int32_t x = 0; x < 36; ++x) {
      im.cb[y * 36 + x] = tile_c[(y % 32) * 36 + x];
      im.cr[y * 36 + x] = tile_c[36 * 32 + (y % 32) * 36 + x];
      im.D(x, y) = tile_d[(y % 32) * 36 + x];
    }
  }
  test::RenderSetup setup;
  setup.max_radius = 32;
  setup.params.f_number = 1.4f;
  setup.params.focus = {10, 10, 4, 4};
  setup.params.aperture = {5, 12.0f, 0.3f};
  const test::Rendered out = Render(im, setup);
  for (int32_t y = 128; y < im.h - 128 - 64; ++y) {
    for (int32_t x = 0; x < im.w; ++x) {
      ASSERT_EQ(out.y[y * im.w + x], out.y[(y + 64) * im.w + x]) << x << "," << y;
    }
  }
  for (int32_t y = 64; y < im.h / 2 - 64 - 32; ++y) {
    for (int32_t x = 0; x < 36; ++x) {
      ASSERT_EQ(out.cb[y * 36 + x], out.cb[(y + 32) * 36 + x]) << x << "," << y;
      ASSERT_EQ(out.cr[y * 36 + x], out.cr[(y + 32) * 36 + x]) << x << "," << y;
    }
  }
}

TEST(RenderStage, SharpForegroundDoesNotBleedIntoBlurredBackground) {
  // Left: far background (disparity 1), dark. Right: near foreground (disparity 3), bright, in
  // focus. At f/2.8 and scale 4 the background blurs by 16 px.
  const Image im = TwoHalves(40, 1 << 8, 200, 3 << 8);
  test::RenderSetup setup;
  setup.params.focus = {60, 10, 30, 40};
  const test::Rendered out = Render(im, setup);
  for (int32_t y = 0; y < im.h; ++y) {
    for (int32_t x = 0; x < im.w; ++x) {
      const int32_t v = out.y[y * im.w + x];
      if (x >= 48) {
        ASSERT_EQ(v, 200) << x << "," << y;  // the foreground stays sharp
      }
      if (x < 48) {
        ASSERT_NEAR(v, 40, 1) << x << "," << y;  // no glow of the foreground
      }
    }
  }
}

TEST(RenderStage, BlurredForegroundSpreadsOverSharpBackground) {
  // Left: near foreground (disparity 3), bright, blurred by 16 px. Right: far background
  // (disparity 1), dark, in focus.
  const Image im = TwoHalves(200, 3 << 8, 40, 1 << 8);
  test::RenderSetup setup;
  setup.params.focus = {60, 10, 30, 40};
  const test::Rendered out = Render(im, setup);
  const int32_t row = 32 * im.w;
  EXPECT_GT(out.y[row + 49], 100);  // just behind the foreground's edge: covered by its blur
  EXPECT_GT(out.y[row + 58], 45);   // 10 px in: still partly covered
  EXPECT_LT(out.y[row + 58], out.y[row + 49]);
  EXPECT_EQ(out.y[row + 66], 40);        // beyond the 16 px radius: untouched
  EXPECT_NEAR(out.y[row + 20], 200, 1);  // the foreground's inside keeps its colour
}

// A dark plane at disparity 1 with a bright 3x3 spot; the focus is elsewhere (disparity 3 in
// the bottom-right corner), so the point blurs by radius 8 * 2 / (f/2.8 -> 1) = 16 px.
Image PointLight(int32_t px, int32_t py) {
  Image im(96, 96, 4);
  for (uint8_t& v : im.y) v = 20;
  for (int32_t dy = -1; dy <= 1; ++dy) {
    for (int32_t dx = -1; dx <= 1; ++dx) im.Y(px + dx, py + dy) = 255;
  }
  for (int32_t wy = 0; wy < 24; ++wy) {
    for (int32_t wx = 0; wx < 24; ++wx) im.D(wx, wy) = (wx >= 20 && wy >= 20) ? 3 << 8 : 1 << 8;
  }
  return im;
}

TEST(RenderStage, PointSpreadsOverTheApertureOfTheLensModelRadius) {
  const Image im = PointLight(40, 40);
  test::RenderSetup setup;
  setup.max_radius = 32;
  setup.params.focus = {84, 84, 8, 8};
  const test::Rendered disc = Render(im, setup);
  EXPECT_FLOAT_EQ(disc.radius_per_disp, 8.0f);
  EXPECT_FLOAT_EQ(disc.focus_disp, 3.0f);
  auto at = [&](const test::Rendered& r, int32_t dx, int32_t dy) {
    return static_cast<int32_t>(r.y[(40 + dy) * im.w + 40 + dx]);
  };
  // 9 x 235 spread over a disc of area pi 16^2 ~ 804 px: about 2.6 each.
  int64_t inside = 0, outside = 0;
  for (int32_t dy = -24; dy <= 24; ++dy) {
    for (int32_t dx = -24; dx <= 24; ++dx) {
      const double d = std::sqrt(dx * dx + dy * dy);
      if (d <= 14) {
        EXPECT_GE(at(disc, dx, dy), 22) << dx << "," << dy;
      }
      if (d <= 15) inside += at(disc, dx, dy) - 20;
      if (d >= 19) outside += std::abs(at(disc, dx, dy) - 20);
    }
  }
  EXPECT_EQ(outside, 0);
  EXPECT_GT(inside, 1500);

  // Highlight boost: the same point with gain 8 is several times brighter.
  setup.params.highlight_threshold = 200;
  setup.params.highlight_gain = 8.0f;
  const test::Rendered boosted = Render(im, setup);
  int64_t boosted_inside = 0;
  for (int32_t dy = -15; dy <= 15; ++dy) {
    for (int32_t dx = -15; dx <= 15; ++dx) {
      if (dx * dx + dy * dy <= 225) boosted_inside += at(boosted, dx, dy) - 20;
    }
  }
  EXPECT_GT(boosted_inside, 5 * inside);
}

TEST(RenderStage, HexagonalIrisGivesHexagonalBokeh) {
  const Image im = PointLight(48, 40);
  test::RenderSetup setup;
  setup.max_radius = 32;
  setup.params.focus = {84, 84, 8, 8};
  setup.params.highlight_threshold = 200;
  setup.params.highlight_gain = 8.0f;
  setup.params.aperture = {6, 0.0f, 0.0f};  // flat edges face +-x, vertices point +-y
  const test::Rendered hex = Render(im, setup);
  auto value = [&](int32_t dx, int32_t dy) { return hex.y[(40 + dy) * im.w + 48 + dx]; };
  // Half of the spot's peak: the extent along x (towards a flat edge, apothem 16 cos 30 = 13.9)
  // is clearly shorter than along y (towards a vertex, 16).
  const int32_t half = (value(0, 0) + 20) / 2;
  auto extent = [&](int32_t sx, int32_t sy) {
    int32_t e = 0;
    while (e < 30 && value(sx * (e + 1), sy * (e + 1)) >= half) ++e;
    return e;
  };
  EXPECT_GE(value(0, 0), 40);
  for (int32_t sign : {-1, 1}) {
    EXPECT_GE(extent(sign, 0), 12);
    EXPECT_LE(extent(sign, 0), 15);
    EXPECT_GE(extent(0, sign), extent(sign, 0) + 1);
    EXPECT_LE(extent(0, sign), 18);
  }
}

TEST(RenderStage, NothingIsAllocatedAfterConfigure) {
  test::TestScene scene = test::MakeLayeredScene(80, 64, 4);
  RenderConfig config;
  config.width = 80, config.height = 64, config.working_scale = 4;
  config.working_width = 20, config.working_height = 16, config.max_radius = 12;
  std::vector<uint8_t> block(RenderStage::RequiredBytes(config) + 64);
  Arena arena(block.data() + (64 - reinterpret_cast<uintptr_t>(block.data()) % 64),
              block.size() - 64);
  RenderStage stage;
  ASSERT_TRUE(stage.Configure(config, arena).ok());
  RenderParams params;
  params.aperture = {7, 10.0f, 0.3f};
  params.highlight_gain = 3.0f;
  params.highlight_threshold = 220;
  const size_t before = testing::AllocationCount();
  bool ok = stage.Begin(scene.Planar(), scene.WorkingDisp(), params).ok();
  int32_t total = 0;
  for (int32_t rows = 1; ok && rows > 0;) {
    ConstPlanarU8 strip;
    int32_t y0 = 0;
    ok = stage.NextStrip(&strip, &y0, &rows).ok();
    total += rows;
  }
  const size_t after = testing::AllocationCount();
  EXPECT_TRUE(ok);
  EXPECT_EQ(total, 64);
  EXPECT_EQ(after - before, 0u);
  EXPECT_LT(RenderStage::RequiredBytes(config), size_t{1} << 20);
}

TEST(RenderStage, RejectsBadInputWithAClearMessage) {
  RenderConfig config;
  config.width = 64, config.height = 48, config.working_scale = 4;
  config.working_width = 16, config.working_height = 12;
  EXPECT_EQ(RenderStage::Validate(config).code(), Code::kOk);
  RenderConfig bad = config;
  bad.max_radius = 200;
  EXPECT_EQ(RenderStage::Validate(bad).code(), Code::kInvalidArgument);
  bad = config;
  bad.working_width = 17;
  EXPECT_EQ(RenderStage::Validate(bad).code(), Code::kInvalidArgument);

  // An arena one byte short is reported, not overrun.
  const size_t need = RenderStage::RequiredBytes(config);
  std::vector<uint8_t> block(need + 64);
  uint8_t* base = block.data() + (64 - reinterpret_cast<uintptr_t>(block.data()) % 64);
  RenderStage stage;
  Arena small(base, need - 1);
  EXPECT_EQ(stage.Configure(config, small).code(), Code::kOutOfMemory);
  Arena arena(base, need);
  ASSERT_TRUE(stage.Configure(config, arena).ok());

  ConstPlanarU8 strip;
  int32_t y0 = 0, rows = 0;
  EXPECT_EQ(stage.NextStrip(&strip, &y0, &rows).code(), Code::kInvalidArgument);

  Image im(64, 48, 4);
  RenderParams p;
  EXPECT_TRUE(stage.Begin(im.Planar(), im.Disp(), p).ok());
  Image wrong(64, 32, 4);
  Status s = stage.Begin(wrong.Planar(), im.Disp(), p);
  EXPECT_EQ(s.code(), Code::kInvalidArgument);
  EXPECT_STREQ(s.message(), "render: reference is not 64x48 YCbCr 4:2:0");
  s = stage.Begin(im.Planar(), wrong.Disp(), p);
  EXPECT_STREQ(s.message(), "render: disparity is 16x8, expected 16x12");
  for (float f : {0.5f, 40.0f, NAN}) {
    p = RenderParams{};
    p.f_number = f;
    EXPECT_EQ(stage.Begin(im.Planar(), im.Disp(), p).code(), Code::kInvalidArgument) << f;
  }
  p = RenderParams{};
  p.aperture.blades = 2;
  EXPECT_STREQ(stage.Begin(im.Planar(), im.Disp(), p).message(),
               "render: 2 aperture blades (0 for a disc, or 3..12)");
  p = RenderParams{};
  p.aperture.curvature = 1.5f;
  EXPECT_EQ(stage.Begin(im.Planar(), im.Disp(), p).code(), Code::kInvalidArgument);
  p = RenderParams{};
  p.highlight_gain = 0.5f;
  EXPECT_EQ(stage.Begin(im.Planar(), im.Disp(), p).code(), Code::kInvalidArgument);
  p = RenderParams{};
  p.aperture.rotation_deg = INFINITY;
  EXPECT_EQ(stage.Begin(im.Planar(), im.Disp(), p).code(), Code::kInvalidArgument);
}

// The output bytes of a fixed render: the same value on x86-64, aarch64 and armhf (the unit
// tests also run under qemu) proves the render is bit-identical across them.
TEST(RenderStage, OutputIsBitIdenticalAcrossPlatforms) {
  const test::TestScene scene = test::MakeLayeredScene(96, 64, 4);
  test::RenderSetup setup;
  setup.max_radius = 12;
  setup.params.f_number = 2.0f;
  setup.params.aperture = {5, 17.0f, 0.25f};
  setup.params.highlight_threshold = 230;
  setup.params.highlight_gain = 4.0f;
  test::Rendered out;
  ASSERT_TRUE(test::RenderAll(scene.Planar(), scene.WorkingDisp(), 4, setup, &out).ok());
  uint64_t hash = 1469598103934665603ull;  // FNV-1a
  for (const std::vector<uint8_t>* p : {&out.y, &out.cb, &out.cr}) {
    for (uint8_t v : *p) hash = (hash ^ v) * 1099511628211ull;
  }
  EXPECT_EQ(hash, 13335697872477751754ull);
}

// Strips of several workers at once, and the ring rows they read filled by several workers
// (each with its own upsampler rows): the same bits as one worker.
TEST(RenderStage, OutputDoesNotDependOnTheWorkers) {
  const test::TestScene scene = test::MakeLayeredScene(96, 120, 4);
  test::RenderSetup setup;
  setup.max_radius = 12;
  setup.params.f_number = 2.0f;
  setup.params.highlight_threshold = 230;
  setup.params.highlight_gain = 4.0f;
  test::Rendered one;
  ASSERT_TRUE(test::RenderAll(scene.Planar(), scene.WorkingDisp(), 4, setup, &one).ok());
  for (int32_t workers = 2; workers <= 4; ++workers) {
    SCOPED_TRACE(workers);
    testing::BackwardsRunner runner(workers);
    setup.workers = workers;
    setup.runner = &runner;
    test::Rendered many;
    ASSERT_TRUE(test::RenderAll(scene.Planar(), scene.WorkingDisp(), 4, setup, &many).ok());
    EXPECT_TRUE(many.y == one.y);
    EXPECT_TRUE(many.cb == one.cb);
    EXPECT_TRUE(many.cr == one.cr);
  }
}

}  // namespace
}  // namespace lb
