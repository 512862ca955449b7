// The map a photo carries on the multi-view sets in ../shared/data (captures we did not make), at
// the ground truth's size, against the depth stage's own grid (what photos carried before the
// map); each enlarged to the truth's size where smaller, the map as the product enlarges it (one
// side at a depth edge), the grid as the render did. The product's default path (auto geometry, 64
// labels), each scored as its benchmark does after the scale and offset small motion cannot know:
// Middlebury, more than 1 px in the evaluated pair's units on the nonocc mask (every pixel of known
// disparity for sawtooth and barn1); HCI, BadPix 0.3 outside a 16 px border. The map must be no
// worse anywhere and better on the whole. Label data: skips without the sets.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "algo/pipeline/pipeline.h"
#include "algo/render/depth_upsample.h"
#include "firmware/platform/arena_block.h"
#include "tests/algo/depth/hci.h"
#include "tests/algo/depth/middlebury.h"

namespace lb {
namespace {

struct Set {
  std::string name;
  int32_t width = 0, height = 0, reference = 0, border = 0;
  const std::vector<std::vector<uint8_t>>* views = nullptr;
  std::vector<float> truth;  // px per view step; NaN where not evaluated
  double threshold = 1;      // px per view step
};

// Bad share after a scale and offset fit over the evaluated pixels: least squares, then twice
// more over the pixels within 4 thresholds of the last fit.
double FittedBad(const Set& s, const std::vector<float>& map) {
  double a = 1, c = 0, band = -1;
  auto each = [&](auto&& fn) {
    for (int32_t y = s.border; y < s.height - s.border; ++y) {
      for (int32_t x = s.border; x < s.width - s.border; ++x) {
        const float t = s.truth[static_cast<size_t>(y) * s.width + x];
        if (std::isfinite(t))
          fn(static_cast<double>(map[static_cast<size_t>(y) * s.width + x]),
             static_cast<double>(t));
      }
    }
  };
  for (int round = 0; round < 3; ++round) {
    double n = 0, se = 0, st = 0, see = 0, set = 0;
    each([&](double e, double t) {
      if (band > 0 && std::fabs(a * e + c - t) > band) return;
      n += 1, se += e, st += t, see += e * e, set += e * t;
    });
    const double det = n * see - se * se;
    if (!(n > 1) || !(std::fabs(det) > 0)) break;
    a = (n * set - se * st) / det;
    c = (st - a * se) / n;
    band = 4 * s.threshold;
  }
  double bad = 0, total = 0;
  each([&](double e, double t) { total += 1, bad += std::fabs(a * e + c - t) > s.threshold; });
  return total > 0 ? 100.0 * bad / total : 100.0;
}

// `img` at the reference's size: itself, or enlarged by the edge-aware upsampling.
std::vector<float> AtFullSize(const Pipeline& p, ConstImageU16 img, bool one_side) {
  const ConstPlanarU8 ref = p.reference();
  const int32_t w = ref.planes[0].width, h = ref.planes[0].height;
  std::vector<float> out(static_cast<size_t>(w) * h);
  if (img.width == w) {
    for (int32_t y = 0; y < h; ++y)
      for (int32_t x = 0; x < w; ++x) out[static_cast<size_t>(y) * w + x] = img.Row(y)[x];
    return out;
  }
  const int32_t scale = w / img.width;
  DepthUpsampler up;
  Arena plan;
  up.Carve(plan, w, h, scale, img.width, img.height);
  std::vector<uint8_t> bytes(plan.used() + Arena::kAlign);
  Arena arena(Arena::AlignUp(bytes.data()), plan.used());
  up.Carve(arena, w, h, scale, img.width, img.height);
  up.Begin(ref, img, one_side ? p.map_confidence() : ConstImageU8{}, one_side);
  std::vector<uint16_t> row(static_cast<size_t>(w));
  for (int32_t y = 0; y < h; ++y) {
    up.Row(y, row.data());
    for (int32_t x = 0; x < w; ++x) out[static_cast<size_t>(y) * w + x] = row[x];
  }
  return out;
}

// The product's default path over the set's views; the map and the stage's grid scored.
void Score(const Set& s, double* grid_bad, double* map_bad) {
  PipelineConfig c;
  c.width = s.width;
  c.height = s.height;
  c.frames = static_cast<int32_t>(s.views->size());
  c.reference = s.reference;
  c.labels = 64;
  c.geometry = ViewGeometry::kAuto;
  c.render = false;
  size_t bytes = 0;
  ASSERT_TRUE(Pipeline::RequiredBytes(c, &bytes).ok());
  ArenaBlock block;
  ASSERT_TRUE(block.Reserve(bytes, "for the pipeline").ok());
  Pipeline p;
  ASSERT_TRUE(p.Configure(c, block.data(), bytes).ok());
  for (int32_t v = 0; v < c.frames; ++v) {
    FrameInfo info;
    info.index = v;
    info.width = s.width;
    info.height = s.height;
    ASSERT_TRUE(p.BeginFrame(info).ok());
    FrameRows rows;
    rows.height = s.height;
    rows.planes[0] = (*s.views)[v].data();
    rows.strides[0] = 3 * static_cast<ptrdiff_t>(s.width);
    ASSERT_TRUE(p.Rows(rows).ok());
    ASSERT_TRUE(p.EndFrame().ok());
  }
  const Status depth = p.ComputeDepth();
  ASSERT_TRUE(depth.ok()) << depth.message();
  if (!p.depth_warning().ok()) {
    // Whether a set is refused is view_order_test's; here there is no map to score.
    printf("[ sets ] %-14s refused: %s\n", s.name.c_str(), p.depth_warning().message());
    *grid_bad = *map_bad = -1;
    return;
  }
  *grid_bad = FittedBad(s, AtFullSize(p, p.disparity_q8(), false));
  *map_bad = FittedBad(s, AtFullSize(p, p.map_q8(), true));
  printf("[ sets ] %-14s the stage's grid %6.2f %%, the map %6.2f %%\n", s.name.c_str(), *grid_bad,
         *map_bad);
}

TEST(MapSets, TheMapIsNoWorseThanTheStagesGridAndBetterOverall) {
  const std::string mb_dir = middlebury::DataDir(), hci_dir = hci::DataDir();
  if (mb_dir.empty() && hci_dir.empty())
    GTEST_SKIP() << "../shared/data is absent: no multi-view set to measure";
  double grid_sum = 0, map_sum = 0;
  int sets = 0;
  for (const char* name : {"tsukuba", "venus", "teddy", "sawtooth", "barn1"}) {
    if (mb_dir.empty()) break;
    middlebury::Set m;
    ASSERT_TRUE(middlebury::Load(mb_dir, name, &m).ok()) << name;
    Set s;
    s.name = name;
    s.width = m.width, s.height = m.height, s.reference = m.reference;
    s.views = &m.views;
    s.truth.resize(m.truth.size());
    const bool masked = !m.mask.empty();
    for (size_t i = 0; i < m.truth.size(); ++i) {
      const bool known = m.truth[i] > 0 && (!masked || m.mask[i] == 255);
      s.truth[i] = known ? m.truth[i] : NAN;
    }
    s.threshold = 1.0 / m.eval_steps;
    double grid = 0, map = 0;
    ASSERT_NO_FATAL_FAILURE(Score(s, &grid, &map));
    EXPECT_LE(map, grid * 1.02 + 0.05) << name;
    grid_sum += grid, map_sum += map, ++sets;
  }
  for (hci::Layout layout :
       {hci::Layout::kRow5, hci::Layout::kCross5, hci::Layout::kRow9, hci::Layout::kColumn9}) {
    if (hci_dir.empty()) break;
    hci::Burst b;
    ASSERT_TRUE(hci::Load(hci_dir, layout, &b).ok());
    Set s;
    s.name = std::string("hci ") + hci::LayoutName(layout);
    s.width = b.width, s.height = b.height, s.reference = b.reference, s.border = 16;
    s.views = &b.views;
    s.truth = b.truth;
    s.threshold = 0.3;
    double grid = 0, map = 0;
    ASSERT_NO_FATAL_FAILURE(Score(s, &grid, &map));
    if (grid < 0) continue;
    EXPECT_LE(map, grid * 1.02 + 0.05) << s.name;
    grid_sum += grid, map_sum += map, ++sets;
  }
  printf("[ sets ] mean over %d sets: the stage's grid %.2f %%, the map %.2f %%\n", sets,
         grid_sum / sets, map_sum / sets);
  EXPECT_LT(map_sum, grid_sum);
}

}  // namespace
}  // namespace lb
