// The depth map's confidence: on synthetic bursts with known depth (rectified shifts, and the
// plane sweep of a handheld burst), its low-confidence pixels hold a far larger share of wrong
// depth than its high-confidence ones; a textureless burst is low confidence almost everywhere;
// the map changes no bit of the depth map.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "algo/depth/depth_stage.h"
#include "tests/algo/depth/handheld.h"
#include "tests/algo/depth/synthetic_views.h"

namespace lb {
namespace {

using handheld::Stage;

// One label per px per view step, labels 0..labels-1.
DepthConfig Config(const synth::Burst& b, int32_t labels) {
  DepthConfig c = synth::SmallConfig(b, labels, 256);
  c.confidence = true;
  return c;
}

uint32_t Hash(uint32_t v) {
  v ^= v >> 13;
  v *= 0x5bd1e995u;
  v ^= v >> 15;
  return v;
}

// The two-layer burst of synthetic_views.h, with a flat grey patch painted on the background
// plane (scene columns px0..px1-1 and rows py0..py1-1, so it moves with the plane from view to
// view) and sensor noise of +-3 levels, different in every view, over the whole patch: its
// depth is a guess. flat_all: the whole scene flat grey with noise (nothing to match).
synth::Burst PatchedBurst(int32_t w, int32_t h, int32_t px0, int32_t px1, int32_t py0, int32_t py1,
                          bool flat_all) {
  const int32_t views = 5, ref = 2, back = 2, front = 6;
  const int32_t fx0 = w / 2, fx1 = w / 2 + w / 4, fy0 = h / 4, fy1 = h / 2 + h / 4;
  synth::Burst b = synth::MakeBurst(w, h, views, ref, back, front, fx0, fx1, fy0, fy1, 21u);
  for (int32_t k = 0; k < views; ++k) {
    const int32_t step = k - ref;
    for (int32_t y = 0; y < h; ++y) {
      for (int32_t x = 0; x < w; ++x) {
        const int32_t xf = x + step * front;
        const bool in_front = xf >= fx0 && xf < fx1 && y >= fy0 && y < fy1;
        const int32_t xs = x + step * back;
        const bool patch = !in_front && xs >= px0 && xs < px1 && y >= py0 && y < py1;
        if (!patch && !flat_all) continue;
        for (int32_t c = 0; c < 3; ++c) {
          const uint32_t noise = Hash(static_cast<uint32_t>((k * h + y) * w + x) * 3u + c) % 7;
          b.pixels[k][(static_cast<size_t>(y) * w + x) * 3 + c] =
              static_cast<uint8_t>(120 + 10 * c + noise);
        }
      }
    }
  }
  return b;
}

// Wrong depth of three kinds: the flat patch (a guess), the strips the foreground hides from
// some views, and the truth (labels 2 and 6) falling between the coarse pass's labels (0, 4, 8),
// which it can miss on this fine texture.
struct Split {
  int64_t low = 0, high = 0, low_wrong = 0, high_wrong = 0;
};

// Pixels below and at or above kLowConfidence, and the wrong ones among them.
Split Count(const uint8_t* confidence, const std::vector<bool>& wrong) {
  Split s;
  for (size_t p = 0; p < wrong.size(); ++p) {
    if (confidence[p] < DepthStage::kLowConfidence) {
      ++s.low;
      s.low_wrong += wrong[p] ? 1 : 0;
    } else {
      ++s.high;
      s.high_wrong += wrong[p] ? 1 : 0;
    }
  }
  return s;
}

TEST(ConfidenceTest, LowConfidenceHoldsTheWrongDepth) {
  const int32_t w = 160, h = 96;
  // A flat patch over a fifth of the background, left of the foreground rectangle.
  const synth::Burst b = PatchedBurst(w, h, 16, 64, 20, 76, false);
  Stage s;
  ASSERT_TRUE(s.Configure(Config(b, 12)).ok());
  ASSERT_TRUE(s.Compute(b.views.data()).ok());
  const uint8_t* confidence = s.depth.confidence();
  ASSERT_NE(confidence, nullptr);
  // The split is the product's own: kLowConfidence is what the retake hint counts, so this
  // checks the threshold it uses, not one chosen for the test (a median would put half the
  // pixels on each side whatever the map says).
  std::vector<bool> wrong(static_cast<size_t>(w) * h);
  for (int32_t p = 0; p < w * h; ++p) {
    wrong[p] = s.depth.labels()[p] > b.truth[p] + 1 || s.depth.labels()[p] < b.truth[p] - 1;
  }
  const Split split = Count(confidence, wrong);
  const int64_t low = split.low, high = split.high, low_wrong = split.low_wrong,
                high_wrong = split.high_wrong;
  ASSERT_EQ(low, s.depth.stats().low_confidence);
  // Enough of each for the shares to mean something.
  ASSERT_GT(low, w * h / 20);
  ASSERT_GT(high, w * h / 4);
  ASSERT_GT(low_wrong, 0);
  const double low_share = static_cast<double>(low_wrong) / static_cast<double>(low);
  const double high_share = static_cast<double>(high_wrong) / static_cast<double>(high);
  RecordProperty("low_wrong_percent", std::to_string(100 * low_share));
  RecordProperty("high_wrong_percent", std::to_string(100 * high_share));
  EXPECT_GE(low_share, 3 * high_share);
}

// The plane sweep of a handheld burst through its true poses: wrong depth sits where the map is
// unsure. Its labels are a quarter pixel apart (of the mean baseline's motion) and the map counts
// a final label within two of the winner-take-all's as its minimum (confidence.h), so wrong is
// off the truth by more than two labels, half a pixel; by more than one, sub-label placement
// counts as wrong and the shares differ by less.
TEST(ConfidenceTest, PlaneSweepLowConfidenceHoldsTheWrongDepth) {
  motiontest::Burst b;
  ASSERT_TRUE(motiontest::MakeBurst(motiontest::Handheld(6), 160, 120, 5, &b));
  handheld::Labels l = handheld::HandheldLabels(b, 0.1);
  l.config.confidence = true;
  Stage s;
  ASSERT_TRUE(s.Configure(l.config).ok());
  ASSERT_TRUE(s.depth.SetPlanes(handheld::Planes(b, l).data()).ok());
  ASSERT_TRUE(s.Compute(b.views.data()).ok());
  const int32_t w = b.scene.width(), h = b.scene.height();
  std::vector<uint16_t> truth(static_cast<size_t>(w) * h);
  ASSERT_TRUE(b.scene.InverseDepthRows(1, 0, h, truth.data(), w).ok());
  std::vector<bool> wrong(truth.size());
  for (size_t i = 0; i < truth.size(); ++i) {
    const double err = s.disp[i] / 256.0 - truth[i] / 4096.0 * l.px_per_inv_depth;
    wrong[i] = err > 0.5 || err < -0.5;
  }
  const Split split = Count(s.depth.confidence(), wrong);
  ASSERT_GT(split.low, 0);
  ASSERT_GT(split.high, 0);
  const double low_share = static_cast<double>(split.low_wrong) / static_cast<double>(split.low);
  const double high_share = static_cast<double>(split.high_wrong) / static_cast<double>(split.high);
  RecordProperty("low_px", std::to_string(split.low));
  RecordProperty("low_wrong_percent", std::to_string(100 * low_share));
  RecordProperty("high_wrong_percent", std::to_string(100 * high_share));
  EXPECT_GE(low_share, 3 * high_share);
}

TEST(ConfidenceTest, TexturelessBurstIsLowConfidence) {
  const int32_t w = 96, h = 64;
  const synth::Burst b = PatchedBurst(w, h, 0, 0, 0, 0, true);
  Stage s;
  ASSERT_TRUE(s.Configure(Config(b, 12)).ok());
  ASSERT_TRUE(s.Compute(b.views.data()).ok());
  EXPECT_GT(s.depth.stats().low_confidence, int64_t{w} * h * 9 / 10);
}

TEST(ConfidenceTest, DepthMapIsTheSameWithoutTheMap) {
  const synth::Burst b = PatchedBurst(160, 96, 16, 64, 20, 76, false);
  for (const bool blocks : {true, false}) {
    for (const int32_t step : {1, 4}) {
      DepthConfig c = Config(b, 12);
      c.coarse_blocks = blocks;
      c.coarse_step = step;
      Stage with, without;
      ASSERT_TRUE(with.Configure(c).ok());
      c.confidence = false;
      ASSERT_TRUE(without.Configure(c).ok());
      ASSERT_TRUE(with.Compute(b.views.data()).ok());
      ASSERT_TRUE(without.Compute(b.views.data()).ok());
      EXPECT_EQ(with.disp, without.disp) << "blocks " << blocks << " step " << step;
      EXPECT_EQ(without.depth.confidence(), nullptr);
      EXPECT_LT(DepthStage::RequiredBytes(c), with.depth.stats().arena_bytes + 1);
    }
  }
}

}  // namespace
}  // namespace lb
