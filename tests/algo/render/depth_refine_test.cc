#include "algo/render/depth_refine.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "firmware/platform/worker_pool.h"

namespace lb {
namespace {

// The map's grid keeps at least half the photo's side or 1 MP, whichever is smaller, and is no
// finer than that: one step coarser would miss it (or be coarser than the depth stage's).
TEST(DepthRefine, TheMapKeepsHalfTheSideOrAMegapixel) {
  EXPECT_EQ(DepthRefiner::MapScale(4056, 3040, 7), 3);
  EXPECT_EQ(DepthRefiner::MapScale(1280, 960, 2), 2);
  EXPECT_EQ(DepthRefiner::MapScale(1390, 1110, 3), 2);
  EXPECT_EQ(DepthRefiner::MapScale(640, 480, 1), 1);
  for (int32_t w : {320, 1000, 1390, 2028, 2592, 3280, 4056, 4608, 6000, 8192}) {
    const int32_t h = w * 3 / 4;
    const int32_t ws = (w + 639) / 640;
    const int32_t s = DepthRefiner::MapScale(w, h, ws);
    const int64_t half = int64_t{w / 2} * (h / 2), want = half < (1 << 20) ? half : (1 << 20);
    EXPECT_GE(int64_t{w / s} * (h / s), want) << w;
    EXPECT_LE(s, ws) << w;
    if (s < ws) {
      EXPECT_LT(int64_t{w / (s + 1)} * (h / (s + 1)), want) << w;
    }
  }
}

struct Photo {
  int32_t w, h, ws, ww, wh, ms, mw, mh;
  std::vector<uint8_t> y, cb, cr, confidence;
  std::vector<uint16_t> disp;
  Photo(int32_t width, int32_t height, int32_t work_scale)
      : w(width), h(height), ws(work_scale), ww(width / work_scale), wh(height / work_scale) {
    ms = DepthRefiner::MapScale(w, h, ws);
    mw = w / ms, mh = h / ms;
    y.resize(static_cast<size_t>(w) * h);
    cb.assign(static_cast<size_t>((w + 1) / 2) * ((h + 1) / 2), 128);
    cr = cb;
    for (int32_t j = 0; j < h; ++j)
      for (int32_t i = 0; i < w; ++i) y[j * w + i] = static_cast<uint8_t>(i > w / 3 ? 200 : 40);
    disp.resize(static_cast<size_t>(ww) * wh);
    confidence.resize(disp.size());
    for (int32_t j = 0; j < wh; ++j) {
      for (int32_t i = 0; i < ww; ++i) {
        disp[j * ww + i] = static_cast<uint16_t>(i * ws > w / 3 ? 5 << 8 : (1 << 8) + j * 3);
        confidence[j * ww + i] = static_cast<uint8_t>((i * 37 + j * 11) % 256);
      }
    }
  }
  ConstPlanarU8 Ref() const {
    ConstPlanarU8 ref;
    ref.count = 3;
    ref.planes[0] = MakeView(y.data(), w, h);
    ref.planes[1] = MakeView(cb.data(), (w + 1) / 2, (h + 1) / 2);
    ref.planes[2] = MakeView(cr.data(), (w + 1) / 2, (h + 1) / 2);
    return ref;
  }
  // The map and its confidence, made with `workers` workers.
  void Map(int32_t workers, std::vector<uint16_t>* map, std::vector<uint8_t>* map_confidence) {
    RefineConfig c;
    c.width = w, c.height = h, c.work_scale = ws, c.work_width = ww, c.work_height = wh;
    c.map_scale = ms, c.map_width = mw, c.map_height = mh, c.workers = workers;
    std::vector<uint8_t> block(DepthRefiner::RequiredBytes(c) + Arena::kAlign);
    Arena arena(Arena::AlignUp(block.data()), block.size() - Arena::kAlign);
    DepthRefiner r;
    r.Carve(c, arena);
    ASSERT_FALSE(arena.overflowed());
    WorkerPool pool;
    ASSERT_TRUE(pool.Start(workers).ok());
    r.SetRunner(&pool);
    map->assign(static_cast<size_t>(mw) * mh, 0);
    map_confidence->assign(map->size(), 0);
    r.Run(Ref(), MakeView(disp.data(), ww, wh), MakeView(confidence.data(), ww, wh),
          MakeView(map->data(), mw, mh), MakeView(map_confidence->data(), mw, mh));
  }
};

// Values are map px per view step (the depth stage's times work_scale / map_scale): a flat
// surface keeps its depth, and a reader that knows only the photo and the map gets the blur.
TEST(DepthRefine, ValuesAreInMapPixels) {
  Photo p(420, 315, 7);
  std::vector<uint16_t> map;
  std::vector<uint8_t> confidence;
  ASSERT_NO_FATAL_FAILURE(p.Map(1, &map, &confidence));
  // Deep inside the flat right-hand surface: 5 working px a step, 5 * 7 / 2 map px.
  ASSERT_EQ(p.ms, 2);
  const int32_t want = (5 << 8) * 7 / 2;
  for (int32_t j = 5; j < p.mh - 5; ++j) {
    for (int32_t i = p.mw / 2; i < p.mw - 5; ++i) EXPECT_EQ(map[j * p.mw + i], want) << i;
  }
  // The confidence: the depth stage's at the nearest of its pixels.
  for (int32_t j = 0; j < p.mh; ++j) {
    for (int32_t i = 0; i < p.mw; ++i) {
      const int32_t wx = (i * p.ms + p.ms / 2) / p.ws, wy = (j * p.ms + p.ms / 2) / p.ws;
      ASSERT_EQ(confidence[j * p.mw + i], p.confidence[wy * p.ww + wx]);
    }
  }
}

// The same bits for any number of workers, on an odd map scale (3: 12 MP) and an even one.
TEST(DepthRefine, TheSameMapForOneAndTwoWorkers) {
  struct Size {
    int32_t w, h, ws;
  };
  for (const Size& size : {Size{4056, 3040, 7}, Size{300, 225, 5}}) {
    Photo p(size.w, size.h, size.ws);
    std::vector<uint16_t> one, two;
    std::vector<uint8_t> c1, c2;
    ASSERT_NO_FATAL_FAILURE(p.Map(1, &one, &c1));
    ASSERT_NO_FATAL_FAILURE(p.Map(2, &two, &c2));
    EXPECT_EQ(one, two) << "map scale " << p.ms;
    EXPECT_EQ(c1, c2);
  }
}

}  // namespace
}  // namespace lb
