// The depth stage: expansion moves never raise the energy and are optimal against single-pixel
// switches, a two-layer burst is recovered, the depth map's bits are pinned (the same value must
// come out under qemu on ARM), the arena bound holds and bad input is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <tuple>
#include <utility>

#include <cstdlib>

#include <cstdint>
#include <string>
#include <vector>

#include "algo/depth/depth_stage.h"
#include "tests/algo/depth/synthetic_views.h"

namespace lb {
namespace {

struct Stage {
  std::vector<uint8_t> memory;
  DepthStage depth;
  std::vector<uint16_t> disp;

  Status Configure(const DepthConfig& c) {
    const size_t bytes = DepthStage::RequiredBytes(c);
    memory.assign(bytes + Arena::kAlign, 0);
    void* const base = Arena::AlignUp(memory.data());
    Arena arena(base, bytes);
    disp.assign(static_cast<size_t>(c.width) * c.height, 0);
    return depth.Configure(c, arena);
  }
  Status Compute(const synth::Burst& b) {
    return depth.Compute(b.views.data(), MakeView(disp.data(), b.width, b.height));
  }
};

TEST(DepthStageTest, EnergyNeverRisesAcrossExpansionMoves) {
  for (uint32_t seed : {1u, 2u, 3u}) {
    const synth::Burst b = synth::MakeBurst(24, 16, 4, 1, 1, 3, 6, 17, 3, 12, seed);
    for (int32_t trunc : {1, 2, 8}) {
      DepthConfig c = synth::SmallConfig(b, 8, 128);
      c.max_cycles = 0;  // winner-take-all only; the test runs the moves
      c.smooth_weight = 40;
      c.smooth_trunc = trunc;
      Stage s;
      ASSERT_TRUE(s.Configure(c).ok());
      ASSERT_TRUE(s.Compute(b).ok());
      int64_t energy = DepthStageProbe::TrackedEnergy(s.depth);
      ASSERT_EQ(DepthStageProbe::Energy(s.depth, s.depth.labels()), energy);
      // A full cycle, then cycles of moves restricted to labels near alpha (coarse to fine).
      for (int32_t window : {255, 2, 1}) {
        for (int32_t alpha = 0; alpha < c.labels; ++alpha) {
          DepthStageProbe::ExpandMove(s.depth, alpha, window);
          // Recomputed from scratch, not the stage's own bookkeeping.
          const int64_t after = DepthStageProbe::Energy(s.depth, s.depth.labels());
          ASSERT_EQ(after, DepthStageProbe::TrackedEnergy(s.depth));
          ASSERT_LE(after, energy)
              << "alpha " << alpha << " trunc " << trunc << " window " << window;
          energy = after;
        }
      }
    }
  }
}

// Two layers far apart in depth: a move restricted to labels near alpha looks only at the
// rectangles around one layer, and the pixels with no such label in their 3x3 neighbourhood
// keep theirs. Its bookkeeping (the energy, the labels) must match a recomputation.
TEST(DepthStageTest, RestrictedMovesLookOnlyNearTheirLabels) {
  const synth::Burst b = synth::MakeBurst(64, 40, 5, 2, 1, 6, 20, 44, 10, 30, 5u);
  DepthConfig c = synth::SmallConfig(b, 33, 64);
  c.max_cycles = 0;
  c.smooth_weight = 40;
  Stage s;
  ASSERT_TRUE(s.Configure(c).ok());
  ASSERT_TRUE(s.Compute(b).ok());
  for (int32_t alpha = 0; alpha < c.labels; ++alpha)
    DepthStageProbe::ExpandMove(s.depth, alpha);  // settle
  const int32_t w = b.width, h = b.height;
  const int64_t n = int64_t{w} * h;
  int64_t energy = DepthStageProbe::TrackedEnergy(s.depth);
  int32_t small_moves = 0;
  for (int32_t window : {1, 2, 3}) {
    for (int32_t alpha = 0; alpha < c.labels; ++alpha) {
      const int64_t cut_before = s.depth.stats().cut_pixels;
      const std::vector<uint8_t> before(s.depth.labels(), s.depth.labels() + n);
      DepthStageProbe::ExpandMove(s.depth, alpha, window);
      const int64_t after = DepthStageProbe::Energy(s.depth, s.depth.labels());
      ASSERT_EQ(after, DepthStageProbe::TrackedEnergy(s.depth))
          << "alpha " << alpha << " window " << window;
      ASSERT_LE(after, energy);
      energy = after;
      for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
          bool near = false;
          for (int32_t dy = -1; dy <= 1; ++dy) {
            for (int32_t dx = -1; dx <= 1; ++dx) {
              const int32_t qx = std::clamp(x + dx, 0, w - 1), qy = std::clamp(y + dy, 0, h - 1);
              near |= std::abs(before[qy * w + qx] - alpha) <= window;
            }
          }
          if (!near) {
            ASSERT_EQ(s.depth.labels()[y * w + x], before[y * w + x]) << x << "," << y;
          }
        }
      }
      const int64_t cut = s.depth.stats().cut_pixels - cut_before;
      small_moves += cut > 0 && cut < n / 2;
    }
  }
  EXPECT_GT(small_moves, 0) << "no move was restricted to part of the image";
}

// Coarse to fine with the coarse pass on 2x2 blocks (the default), odd sizes included: the
// blocks' energy as the coarse moves tracked it equals the energy of the same labels on the
// pixels, recomputed; the fine moves only lower it, and their bookkeeping matches a
// recomputation from scratch.
TEST(DepthStageTest, CoarseBlocksHaveThePixelsEnergy) {
  for (const auto& [w, h] : {std::pair{64, 40}, {63, 41}, {9, 8}}) {
    const synth::Burst b = synth::MakeBurst(w, h, 5, 2, 1, 6, w / 3, 2 * w / 3, h / 4, h / 2, 9u);
    DepthConfig c = synth::SmallConfig(b, 33, 64);
    ASSERT_TRUE(c.coarse_blocks);
    ASSERT_GT(c.coarse_step, 1);
    Stage s;
    ASSERT_TRUE(s.Configure(c).ok());
    ASSERT_TRUE(s.Compute(b).ok());
    const DepthStats& st = s.depth.stats();
    EXPECT_EQ(st.coarse_energy, st.handover_energy) << w << "x" << h;
    EXPECT_LE(st.coarse_energy, st.initial_energy);
    EXPECT_LE(st.energy, st.handover_energy);
    EXPECT_EQ(DepthStageProbe::Energy(s.depth, s.depth.labels()), st.energy);
  }
}

// The hand-over takes the winner-take-all's pixel D where a block kept the label it won there,
// and computes the rest: the same labels, energies and output as computing every D again, odd
// sizes included; some pixels are taken and some computed.
TEST(DepthStageTest, HandoverFromTheWinnersIsExact) {
  int64_t kept = 0, computed = 0;
  for (const auto& [w, h, labels] :
       {std::tuple{64, 40, 33}, {63, 41, 64}, {9, 8, 33}, {31, 17, 20}}) {
    const synth::Burst b = synth::MakeBurst(w, h, 5, 2, 1, 6, w / 3, 2 * w / 3, h / 4, h / 2, 5u);
    const DepthConfig c = synth::SmallConfig(b, labels, 64);
    Stage taken, again;
    ASSERT_TRUE(taken.Configure(c).ok());
    ASSERT_TRUE(again.Configure(c).ok());
    DepthStageProbe::KeepWinners(again.depth, false);
    ASSERT_TRUE(taken.Compute(b).ok());
    ASSERT_TRUE(again.Compute(b).ok());
    EXPECT_EQ(DepthStageProbe::HandoverKept(again.depth), 0);
    kept += DepthStageProbe::HandoverKept(taken.depth);
    computed += w * h - DepthStageProbe::HandoverKept(taken.depth);
    const DepthStats &st = taken.depth.stats(), &sa = again.depth.stats();
    EXPECT_EQ(st.handover_energy, sa.handover_energy) << w << "x" << h;
    EXPECT_EQ(st.coarse_energy, st.handover_energy) << w << "x" << h;
    EXPECT_EQ(st.energy, sa.energy) << w << "x" << h;
    EXPECT_TRUE(
        std::equal(taken.depth.labels(), taken.depth.labels() + w * h, again.depth.labels()))
        << w << "x" << h;
    EXPECT_EQ(taken.disp, again.disp) << w << "x" << h;
  }
  EXPECT_GT(kept, 0) << "no pixel took the winner-take-all's D";
  EXPECT_GT(computed, 0) << "no block changed its label in the coarse moves";
}

// The coarse pass keeps its block D, rings and winners in the solver's spare whatever the label
// count: Carve makes the room, else the hand-over takes nothing and the moves compute the
// blocks' D again (slower, the same bits).
TEST(DepthStageTest, CoarsePassHasRoomForItsCostsAtAnyLabelCount) {
  const synth::Burst b = synth::MakeBurst(48, 32, 5, 2, 1, 6, 16, 32, 8, 16, 5u);
  for (const int32_t labels : {16, 64, 128, 256}) {
    const DepthConfig c = synth::SmallConfig(b, labels, 16);
    Stage s;
    ASSERT_TRUE(s.Configure(c).ok());
    ASSERT_TRUE(s.Compute(b).ok());
    EXPECT_GT(DepthStageProbe::HandoverKept(s.depth), 0) << labels << " labels";
    EXPECT_EQ(DepthStageProbe::WinnerStripes(s.depth), 1) << labels << " labels";
  }
}

TEST(DepthStageTest, MoveResultBeatsEverySinglePixelSwitch) {
  const synth::Burst b = synth::MakeBurst(16, 12, 3, 1, 1, 2, 4, 11, 2, 9, 9u);
  DepthConfig c = synth::SmallConfig(b, 5, 128);
  c.max_cycles = 0;
  c.smooth_weight = 60;
  Stage s;
  ASSERT_TRUE(s.Configure(c).ok());
  ASSERT_TRUE(s.Compute(b).ok());
  const size_t n = static_cast<size_t>(b.width) * b.height;
  for (int32_t i = 0; i < 2 * c.labels; ++i) {
    // A full cycle, then one restricted to labels next to alpha.
    const int32_t alpha = i % c.labels, window = i < c.labels ? 255 : 1;
    DepthStageProbe::ExpandMove(s.depth, alpha, window);
    const int64_t energy = DepthStageProbe::TrackedEnergy(s.depth);
    std::vector<uint8_t> labels(s.depth.labels(), s.depth.labels() + n);
    // The move is optimal over all subsets of the pixels it frees switching to alpha, so over
    // single pixels too.
    for (size_t p = 0; p < n; ++p) {
      if (labels[p] == alpha || std::abs(labels[p] - alpha) > window) continue;
      const uint8_t keep = labels[p];
      labels[p] = static_cast<uint8_t>(alpha);
      ASSERT_GE(DepthStageProbe::Energy(s.depth, labels.data()), energy)
          << "pixel " << p << " alpha " << alpha;
      labels[p] = keep;
    }
  }
}

// The sub-label fit reads D(f - 1), D(f) and D(f + 1) that the moves kept on the way (each
// move computes D only next to labels near its own, on pieces of its rectangles): wherever the
// output leaves a label's disparity, it must be the parabola through the true D, recomputed
// here from scratch for every label; and the fit must have happened on most pixels.
TEST(DepthStageTest, SubLabelFitUsesTheTrueCosts) {
  for (uint32_t seed : {5u, 21u}) {
    const synth::Burst b = synth::MakeBurst(64, 40, 5, 2, 2, 6, 20, 44, 10, 30, seed);
    const DepthConfig c = synth::SmallConfig(b, 33, 64);  // coarse to fine, subpixel: the defaults
    Stage s;
    ASSERT_TRUE(s.Configure(c).ok());
    ASSERT_TRUE(s.Compute(b).ok());
    const size_t n = static_cast<size_t>(b.width) * b.height;
    std::vector<std::vector<uint16_t>> d(static_cast<size_t>(c.labels), std::vector<uint16_t>(n));
    for (int32_t l = 0; l < c.labels; ++l) DepthStageProbe::Costs(s.depth, l, d[l].data());
    int32_t fitted = 0, inner = 0;
    for (size_t p = 0; p < n; ++p) {
      const int32_t f = s.depth.labels()[p];
      const int32_t label_q8 = s.depth.LabelDispQ8(f) + DepthStage::MapBiasQ8(c);
      if (f == 0 || f + 1 == c.labels) {
        EXPECT_EQ(s.disp[p], label_q8) << "pixel " << p;
        continue;
      }
      ++inner;
      if (s.disp[p] == label_q8) continue;  // not fitted, or a vertex on the label
      ++fitted;
      const int32_t cm = d[f - 1][p], c0 = d[f][p], cp = d[f + 1][p];
      const int32_t curvature = cm + cp - 2 * c0;
      ASSERT_TRUE(c0 <= cm && c0 <= cp && curvature > 0) << "pixel " << p;
      const int32_t step_q8 = (s.depth.LabelDispQ8(f + 1) - s.depth.LabelDispQ8(f - 1)) / 2;
      EXPECT_EQ(s.disp[p], label_q8 + ((cm - cp) * step_q8) / (2 * curvature)) << "pixel " << p;
    }
    EXPECT_GT(fitted, inner / 8) << "seed " << seed;  // about a quarter here
  }
}

TEST(DepthStageTest, RecoversTwoLayers) {
  const synth::Burst b = synth::MakeBurst(64, 40, 5, 2, 2, 6, 20, 44, 10, 30, 21u);
  DepthConfig c = synth::SmallConfig(b, 33, 64);  // 0 .. 8 px per step in quarter pixels
  Stage s;
  ASSERT_TRUE(s.Configure(c).ok());
  ASSERT_TRUE(s.Compute(b).ok());
  EXPECT_LE(s.depth.stats().energy, s.depth.stats().initial_energy);
  EXPECT_GE(s.depth.stats().cycles, 1);
  int32_t good = 0, total = 0;
  for (int32_t y = 0; y < b.height; ++y) {
    for (int32_t x = 8; x < b.width - 8; ++x) {  // the outer views miss the image border
      ++total;
      const int32_t err = s.disp[y * b.width + x] - (b.truth[y * b.width + x] << 8);
      good += (err < 0 ? -err : err) <= 64;
    }
  }
  EXPECT_GE(good, total * 97 / 100) << good << " of " << total;
}

// The burst and the parameters of the pinned bits below.
synth::Burst PinnedBurst() { return synth::MakeBurst(48, 32, 5, 2, 1, 4, 14, 34, 6, 24, 77u); }
DepthConfig PinnedConfig(const synth::Burst& b) {
  DepthConfig c = synth::SmallConfig(b, 24, 64);
  // Pinned parameters, so tuning the defaults does not move the value.
  c.color_trunc = 45;
  c.census_weight = 6;
  c.smooth_weight = 32;
  c.smooth_trunc = 8;
  c.edge_threshold = 16;
  c.edge_weight_q8 = 96;
  c.max_cycles = 2;
  c.coarse_step = 4;
  c.fine_window = 2;
  c.subpixel = true;
  return c;
}

// What the pinned bits stand for, with a stated tolerance, so that a deliberate change to the
// stage reads as better or worse: the share of pixels (off the border the outer views miss)
// within a quarter pixel of the truth.
TEST(DepthStageTest, PinnedBurstIsCloseToTheTruth) {
  const synth::Burst b = PinnedBurst();
  Stage s;
  ASSERT_TRUE(s.Configure(PinnedConfig(b)).ok());
  ASSERT_TRUE(s.Compute(b).ok());
  int32_t good = 0, total = 0;
  for (int32_t y = 0; y < b.height; ++y) {
    for (int32_t x = 6; x < b.width - 6; ++x) {
      ++total;
      const int32_t err = s.disp[y * b.width + x] - (b.truth[y * b.width + x] << 8);
      good += (err < 0 ? -err : err) <= 64;
    }
  }
  RecordProperty("within_quarter_px_percent", std::to_string(100.0 * good / total));
  EXPECT_GE(good, total * 94 / 100) << good << " of " << total;
}

// FNV-1a of the disparity map of a fixed burst. The burst is integer-made, the stage integer-only:
// this value is the same on x86-64, aarch64 and armhf (the test runs under qemu there).
TEST(DepthStageTest, DepthMapBitsArePinned) {
  const synth::Burst b = PinnedBurst();
  Stage s;
  ASSERT_TRUE(s.Configure(PinnedConfig(b)).ok());
  ASSERT_TRUE(s.Compute(b).ok());
  EXPECT_EQ(synth::DisparityHash(s.disp), 2225568840u)
      << "energy " << s.depth.stats().energy
      << ": if PinnedBurstIsCloseToTheTruth passes, the change kept the "
         "map within its tolerance; re-pin on x86-64, check under qemu";
}

// The smoothness prices a step of disparity, not of a label: labels half as far apart cost half
// as much a step and truncate twice as many steps later, within the solver's limits.
TEST(DepthStageTest, SmoothnessFollowsTheLabelSpacing) {
  DepthConfig c;
  c.labels = 65;
  c.smooth_weight = 96;
  c.smooth_trunc = 8;
  auto at = [&c](int32_t spacing_q8) {
    c.disp_min_q8 = -32 * spacing_q8;
    c.disp_max_q8 = c.disp_min_q8 + 64 * spacing_q8;
    return DepthStage::SmoothnessFor(c);
  };
  const DepthStage::Smoothness stated = at(DepthConfig::kSmoothSpacingQ8);
  EXPECT_EQ(stated.weight, 96);
  EXPECT_EQ(stated.trunc, 8);
  const DepthStage::Smoothness fine = at(DepthConfig::kSmoothSpacingQ8 / 2);
  EXPECT_EQ(fine.weight, 48);
  EXPECT_EQ(fine.trunc, 16);
  const DepthStage::Smoothness coarse = at(DepthConfig::kSmoothSpacingQ8 * 4);
  EXPECT_EQ(coarse.weight, 384);
  EXPECT_EQ(coarse.trunc, 2);
  // A step over the truncation costs the same whatever the spacing.
  EXPECT_EQ(fine.weight * fine.trunc, stated.weight * stated.trunc);
  EXPECT_EQ(coarse.weight * coarse.trunc, stated.weight * stated.trunc);
  // Very fine labels: the truncation stops at 64, a weight never rounds to nothing.
  c.smooth_weight = 2;
  const DepthStage::Smoothness finest = at(1);
  EXPECT_EQ(finest.trunc, 64);
  EXPECT_EQ(finest.weight, 1);
  // Very coarse ones: the weight stays within what the graph's arcs hold.
  c.smooth_weight = DepthStage::MaxSmoothWeight(1);
  c.smooth_trunc = 1;
  const DepthStage::Smoothness widest = at(1000);
  EXPECT_EQ(widest.trunc, 1);
  EXPECT_EQ(widest.weight, DepthStage::MaxSmoothWeight(1));
  c.smooth_weight = 0;
  EXPECT_EQ(at(1000).weight, 0);  // no smoothness stays none
}

TEST(DepthStageTest, ArenaFor640x480With7ViewsAnd64LabelsIsAtMost24MiB) {
  DepthConfig c;
  c.width = 640;
  c.height = 480;
  c.views = 7;
  c.reference = 3;
  c.labels = 64;
  c.disp_max_q8 = 16 << 8;
  for (const ViewGeometry g : {ViewGeometry::kRectified, ViewGeometry::kKnownPoses}) {
    c.geometry = g;
    ASSERT_TRUE(DepthStage::Validate(c).ok());
    EXPECT_LE(DepthStage::RequiredBytes(c), size_t{24} << 20) << static_cast<int>(g);
  }
}

TEST(DepthStageTest, RefusesBadConfigurationsAndInputs) {
  DepthConfig c;
  c.width = 32;
  c.height = 16;
  c.views = 3;
  c.reference = 1;
  c.labels = 8;
  c.disp_max_q8 = 512;
  ASSERT_TRUE(DepthStage::Validate(c).ok());
  DepthConfig bad = c;
  bad.labels = 300;
  EXPECT_EQ(DepthStage::Validate(bad).code(), Code::kInvalidArgument);
  bad = c;
  bad.smooth_weight = 100000;
  EXPECT_EQ(DepthStage::Validate(bad).code(), Code::kInvalidArgument);
  // The solver's arcs are 16 bits: smoothness x truncation at most 16383.
  bad = c;
  bad.smooth_weight = 2048;
  bad.smooth_trunc = 8;
  EXPECT_EQ(DepthStage::Validate(bad).code(), Code::kInvalidArgument);
  bad.smooth_weight = 2047;
  EXPECT_TRUE(DepthStage::Validate(bad).ok());
  bad = c;
  bad.reference = 3;
  EXPECT_EQ(DepthStage::Validate(bad).code(), Code::kInvalidArgument);
  for (const ViewGeometry g : {ViewGeometry::kHandheld, ViewGeometry::kAuto}) {
    bad = c;
    bad.geometry = g;
    EXPECT_EQ(DepthStage::Validate(bad).code(), Code::kInvalidArgument) << static_cast<int>(g);
  }

  const synth::Burst b = synth::MakeBurst(32, 16, 3, 1, 1, 2, 8, 20, 4, 12, 5u);
  Stage s;
  ASSERT_TRUE(s.Configure(c).ok());
  std::vector<uint16_t> small(16 * 16);
  const Status wrong_out = s.depth.Compute(b.views.data(), MakeView(small.data(), 16, 16));
  EXPECT_EQ(wrong_out.code(), Code::kInvalidArgument);
  std::vector<ConstImageU8> views = b.views;
  views[2].width = 31;
  const Status wrong_view = s.depth.Compute(views.data(), MakeView(s.disp.data(), 32, 16));
  EXPECT_EQ(wrong_view.code(), Code::kInvalidArgument);
  EXPECT_NE(std::string(wrong_view.message()).find("view 2"), std::string::npos);
}

}  // namespace
}  // namespace lb
