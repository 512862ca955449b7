// The fixed-point data term against a float reference written from its definition (data_term.h):
// float interpolation of colour and of the census Hamming distance, no rounding anywhere, the
// same 3x3 window and best-half mean. The census itself is a binary descriptor of the integer
// luma (the same definition in both).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "algo/depth/data_term.h"
#include "tests/algo/depth/synthetic_views.h"

namespace lb {
namespace {

std::vector<uint32_t> ReferenceCensus(const ConstImageU8& img) {
  const int32_t w = img.width, h = img.height;
  std::vector<int32_t> luma(static_cast<size_t>(w) * h);
  for (int32_t y = 0; y < h; ++y)
    for (int32_t x = 0; x < w; ++x) {
      const uint8_t* p = img.At(x, y);
      luma[y * w + x] = (77 * p[0] + 150 * p[1] + 29 * p[2] + 128) >> 8;
    }
  auto at = [&](int32_t x, int32_t y) {
    return luma[std::clamp(y, 0, h - 1) * w + std::clamp(x, 0, w - 1)];
  };
  std::vector<uint32_t> out(luma.size());
  for (int32_t y = 0; y < h; ++y)
    for (int32_t x = 0; x < w; ++x) {
      uint32_t bits = 0;
      for (int32_t dy = -2; dy <= 2; ++dy)
        for (int32_t dx = -2; dx <= 2; ++dx) {
          if (dx == 0 && dy == 0) continue;
          bits = (bits << 1) | (at(x + dx, y + dy) < at(x, y) ? 1u : 0u);
        }
      out[y * w + x] = bits;
    }
  return out;
}

std::vector<float> ReferenceDataTerm(const std::vector<ConstImageU8>& views, int32_t ref,
                                     const DataTermParams& params, float disp) {
  const int32_t w = views[0].width, h = views[0].height, n = static_cast<int32_t>(views.size());
  std::vector<std::vector<uint32_t>> census;
  for (const auto& v : views) census.push_back(ReferenceCensus(v));
  const float invalid =
      std::min(255.0f, static_cast<float>(params.color_trunc + 24 * params.census_weight + 1));
  std::vector<std::vector<float>> pixel;   // per other view
  std::vector<std::vector<bool>> outside;  // per other view: the sample lies outside it
  for (int32_t v = 0; v < n; ++v) {
    if (v == ref) continue;
    std::vector<float> cost(static_cast<size_t>(w) * h);
    std::vector<bool> out(cost.size(), false);
    for (int32_t y = 0; y < h; ++y)
      for (int32_t x = 0; x < w; ++x) {
        const float pos = static_cast<float>(x) - static_cast<float>(v - ref) * disp;
        const float x0f = std::floor(pos);
        const float f = pos - x0f;
        const int32_t x0 = static_cast<int32_t>(x0f);
        if (x0 < 0 || x0 > w - 1 || (f > 0 && x0 + 1 > w - 1)) {
          cost[y * w + x] = invalid;
          out[y * w + x] = true;
          continue;
        }
        const int32_t x1 = f > 0 ? x0 + 1 : x0;
        float ad = 0;
        for (int32_t c = 0; c < 3; ++c) {
          const float s = (1 - f) * views[v].At(x0, y)[c] + f * views[v].At(x1, y)[c];
          ad += std::fabs(views[ref].At(x, y)[c] - s);
        }
        const uint32_t cr = census[ref][y * w + x];
        const float ham = (1 - f) * __builtin_popcount(cr ^ census[v][y * w + x0]) +
                          f * __builtin_popcount(cr ^ census[v][y * w + x1]);
        cost[y * w + x] = std::min(255.0f, std::min(ad, static_cast<float>(params.color_trunc)) +
                                               params.census_weight * ham);
      }
    pixel.push_back(std::move(cost));
    outside.push_back(std::move(out));
  }
  std::vector<float> out(static_cast<size_t>(w) * h);
  for (int32_t y = 0; y < h; ++y)
    for (int32_t x = 0; x < w; ++x) {
      // The windows of the views that see the pixel (not all 9 samples outside), or of all
      // views when none does.
      std::vector<float> sums, seen;
      for (size_t v = 0; v < pixel.size(); ++v) {
        float s = 0;
        bool sees = false;
        for (int32_t dy = -1; dy <= 1; ++dy)
          for (int32_t dx = -1; dx <= 1; ++dx) {
            const int32_t i = std::clamp(y + dy, 0, h - 1) * w + std::clamp(x + dx, 0, w - 1);
            s += pixel[v][i];
            sees = sees || !outside[v][i];
          }
        sums.push_back(s);
        if (sees) seen.push_back(s);
      }
      if (!seen.empty()) sums = seen;
      const size_t keep = (sums.size() + 1) / 2;
      std::sort(sums.begin(), sums.end());
      float total = 0;
      for (size_t i = 0; i < keep; ++i) total += sums[i];
      out[y * w + x] = total / static_cast<float>(keep);
    }
  return out;
}

struct Fixed {
  std::vector<uint8_t> memory;
  DataTerm term;
};

void CarveTerm(Fixed& f, int32_t width, int32_t height, int32_t views) {
  Arena plan;
  DataTerm planner;
  planner.Carve(plan, width, height, views);
  f.memory.assign(plan.used() + Arena::kAlign, 0);
  void* const base = Arena::AlignUp(f.memory.data());
  Arena arena(base, plan.used());
  f.term.Carve(arena, width, height, views);
  ASSERT_FALSE(arena.overflowed());
}

void PrepareTerm(Fixed& f, const synth::Burst& b, const DataTermParams& params) {
  CarveTerm(f, b.width, b.height, static_cast<int32_t>(b.views.size()));
  f.term.SetParams(params, b.reference);
  f.term.Prepare(b.views.data());
}

// Stated tolerance: rounding the interpolated colour moves a pixel cost by at most 3 x 0.5 and
// the interpolated Hamming cost by at most 0.5, so a window sum by at most 9 x 2 = 18; the mean of
// the best half (order statistics move no more than their inputs) adds the final rounding, 0.5.
// So |fixed - float| <= 18.5 of D's 0..2295 (0.8 %). The mean difference is a bias: at quarter-
// pixel fractions the Hamming cost often lands on exact halves, which round up; it stays below 5.
TEST(DataTermTest, FixedPointAgreesWithFloatReference) {
  for (int32_t views : {2, 3, 5, 7}) {
    const int32_t ref = views / 2;
    const synth::Burst b = synth::MakeBurst(48, 20, views, ref, 2, 5, 14, 34, 4, 16, 11u + views);
    for (const DataTermParams params :
         {DataTermParams{}, DataTermParams{20, 3}, DataTermParams{200, 2}}) {
      Fixed f;
      PrepareTerm(f, b, params);
      for (int32_t disp_q8 : {0, 64, 320, 512 + 77, 1280, 1530}) {
        std::vector<uint16_t> fixed(static_cast<size_t>(b.width) * b.height);
        f.term.ComputeRows(disp_q8, 0, b.height, fixed.data(), b.width);
        const std::vector<float> expect =
            ReferenceDataTerm(b.views, ref, params, static_cast<float>(disp_q8) / 256.0f);
        double sum = 0, worst = 0;
        for (size_t i = 0; i < fixed.size(); ++i) {
          const double d = std::fabs(fixed[i] - expect[i]);
          sum += d;
          worst = std::max(worst, d);
        }
        EXPECT_LE(worst, 18.5) << views << " views, disparity " << disp_q8 << "/256";
        EXPECT_LT(sum / static_cast<double>(fixed.size()), 5.0) << views << " views";
      }
    }
  }
}

TEST(DataTermTest, RowBandsEqualTheWholeImage) {
  const synth::Burst b = synth::MakeBurst(40, 24, 5, 2, 1, 4, 10, 30, 5, 18, 3u);
  Fixed f;
  PrepareTerm(f, b, DataTermParams{});
  std::vector<uint16_t> whole(static_cast<size_t>(40) * 24), bands(whole.size());
  f.term.ComputeRows(300, 0, 24, whole.data(), 40);
  for (int32_t y0 = 0; y0 < 24; y0 += 7) {
    const int32_t y1 = std::min(24, y0 + 7);
    f.term.ComputeRows(300, y0, y1, bands.data() + y0 * 40, 40);
  }
  EXPECT_EQ(whole, bands);
}

// The winner-take-all goes down the image in bands, label by label, each label carrying its
// 3-sums from band to band: bands of any height, two labels taking turns (each on its own ring,
// which starts as garbage), must give the whole image's values bit for bit.
TEST(DataTermTest, CarriedBandsEqualTheWholeImage) {
  const int32_t w = 40, h = 24;
  const synth::Burst b = synth::MakeBurst(w, h, 5, 2, 1, 4, 10, 30, 5, 18, 4u);
  Fixed f;
  PrepareTerm(f, b, DataTermParams{});
  const int32_t disps[2] = {300, 700};
  std::vector<uint16_t> rings[2], bands[2], whole[2];
  for (int32_t i = 0; i < 2; ++i) {
    rings[i].assign(f.term.CarriedRingSize(), static_cast<uint16_t>(0x5a5a + i));
    bands[i].assign(static_cast<size_t>(w) * h, 0xabcd);
    whole[i].assign(bands[i].size(), 0);
    f.term.ComputeRows(disps[i], 0, h, whole[i].data(), w);
  }
  int32_t y0 = 0;
  for (const int32_t rows : {7, 1, 2, 9, 5}) {
    for (int32_t i = 0; i < 2; ++i) {
      f.term.ComputeRowsCarried(disps[i], nullptr, y0, y0 + rows, y0 > 0, rings[i].data(),
                                bands[i].data() + y0 * w, w);
    }
    y0 += rows;
  }
  ASSERT_EQ(y0, h);
  EXPECT_EQ(whole[0], bands[0]);
  EXPECT_EQ(whole[1], bands[1]);
}

// Restricted moves compute D over rectangles: every column range, at the borders and inside,
// must give the whole image's values bit for bit, and write nothing outside it.
TEST(DataTermTest, RectanglesEqualTheWholeImage) {
  const int32_t w = 70, h = 20;
  const synth::Burst b = synth::MakeBurst(w, h, 5, 2, 1, 4, 10, 50, 5, 16, 8u);
  Fixed f;
  PrepareTerm(f, b, DataTermParams{});
  for (int32_t disp_q8 : {0, 300, 1000}) {
    std::vector<uint16_t> whole(static_cast<size_t>(w) * h);
    f.term.ComputeRows(disp_q8, 0, h, whole.data(), w);
    for (const auto& [x0, x1] : {std::pair{0, 1}, {0, 33}, {1, 2}, {5, 40}, {17, 70}, {69, 70}}) {
      std::vector<uint16_t> rect(whole.size(), 0xabcd);
      f.term.ComputeRect(disp_q8, x0, x1, 3, 11, rect.data() + 3 * w, w);
      for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
          const bool inside = y >= 3 && y < 11 && x >= x0 && x < x1;
          ASSERT_EQ(rect[y * w + x], inside ? whole[y * w + x] : 0xabcd)
              << "x " << x << " y " << y << " of [" << x0 << ", " << x1 << ")";
        }
      }
    }
  }
}

// A restricted move computes each row over its own runs of columns (ComputeRuns): rows of one
// run or several, of different widths, empty rows between them and runs at the image's borders
// must give the whole image's values bit for bit, and write nothing outside their runs.
TEST(DataTermTest, RowRunsEqualTheWholeImage) {
  const int32_t w = 70, h = 20;
  const synth::Burst b = synth::MakeBurst(w, h, 5, 2, 1, 4, 10, 50, 5, 16, 9u);
  Fixed f;
  PrepareTerm(f, b, DataTermParams{});
  // Per row: wide, narrow, empty, at either border, two or four runs; the first and last rows
  // included.
  const std::vector<std::vector<int32_t>> pick = {
      {0, 70},        {5, 40},      {},       {69, 70},
      {0, 3, 60, 70}, {0, 1},       {30, 31}, {2, 9, 20, 24, 40, 41, 50, 66},
      {40, 40},       {1, 2, 5, 33}};
  std::vector<RowRuns> runs(h);
  for (int32_t y = 0; y < h; ++y) {
    const std::vector<int32_t>& p = pick[(y * 3) % pick.size()];
    runs[y].count = static_cast<int32_t>(p.size() / 2);
    for (size_t i = 0; i < p.size(); ++i) runs[y].x[i] = p[i];
  }
  auto inside = [&](int32_t x, int32_t y) {
    for (int32_t k = 0; k < runs[y].count; ++k) {
      if (x >= runs[y].x[2 * k] && x < runs[y].x[2 * k + 1]) return true;
    }
    return false;
  };
  for (int32_t disp_q8 : {0, 300, 1000}) {
    std::vector<uint16_t> whole(static_cast<size_t>(w) * h);
    f.term.ComputeRows(disp_q8, 0, h, whole.data(), w);
    for (const auto& [y0, y1] : {std::pair{0, h}, {3, 11}, {19, 20}}) {
      std::vector<uint16_t> out(whole.size(), 0xabcd);
      f.term.ComputeRuns(disp_q8, runs.data(), y0, y1, out.data() + y0 * w, w);
      for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
          const bool in = y >= y0 && y < y1 && inside(x, y);
          ASSERT_EQ(out[y * w + x], in ? whole[y * w + x] : 0xabcd)
              << "x " << x << " y " << y << " rows [" << y0 << ", " << y1 << ")";
        }
      }
    }
  }
}

// The runs a caller makes from its marked columns cover every one of them, in order and apart,
// at most RowRuns::kMax, none narrower than the kernels' step, and split only where the gap is
// worth a run's set-up.
TEST(DataTermTest, RunsFromMarksCoverEveryMark) {
  const int32_t w = 300;
  uint32_t seed = 7;
  auto next = [&]() { return seed = seed * 1664525u + 1013904223u; };
  for (int32_t trial = 0; trial < 400; ++trial) {
    std::vector<uint8_t> mark(w, 0);
    const int32_t blobs = static_cast<int32_t>(next() % 9);
    for (int32_t i = 0; i < blobs; ++i) {
      const int32_t a = static_cast<int32_t>(next() % w);
      const int32_t n = 1 + static_cast<int32_t>(next() % 40);
      for (int32_t x = a; x < a + n && x < w; ++x) mark[x] = 1;
    }
    const int32_t lo = static_cast<int32_t>(next() % 50),
                  hi = w - static_cast<int32_t>(next() % 50);
    const int32_t join = trial % 2 == 0 ? 16 : 64;
    RowRuns runs;
    runs.FromMarks(mark.data(), lo, hi, w, join);
    ASSERT_LE(runs.count, RowRuns::kMax);
    for (int32_t k = 0; k < runs.count; ++k) {
      const int32_t a = runs.x[2 * k], b = runs.x[2 * k + 1];
      ASSERT_GE(a, 0);
      ASSERT_LE(b, w);
      ASSERT_GE(b - a, RowRuns::kMinWidth) << "trial " << trial;
      if (k > 0) {
        ASSERT_GE(a - runs.x[2 * k - 1], join) << "trial " << trial << ": runs this close join";
      }
    }
    for (int32_t x = lo; x < hi; ++x) {
      if (mark[x] == 0) continue;
      bool covered = false;
      for (int32_t k = 0; k < runs.count; ++k) {
        covered |= x >= runs.x[2 * k] && x < runs.x[2 * k + 1];
      }
      ASSERT_TRUE(covered) << "trial " << trial << ": column " << x;
    }
  }
}

TEST(DataTermTest, TrueDisparityCostsLeastOnTexturedPlanes) {
  const synth::Burst b = synth::MakeBurst(64, 32, 5, 2, 2, 6, 20, 44, 8, 24, 5u);
  Fixed f;
  PrepareTerm(f, b, DataTermParams{});
  std::vector<uint16_t> at_back(64 * 32), at_front(64 * 32);
  f.term.ComputeRows(2 * 256, 0, 32, at_back.data(), 64);
  f.term.ComputeRows(6 * 256, 0, 32, at_front.data(), 64);
  // Inside the rectangle, away from its border, the front disparity must win; outside the
  // background one (ignoring the image border, where samples fall outside the views).
  EXPECT_LT(at_front[16 * 64 + 32], at_back[16 * 64 + 32]);
  EXPECT_LT(at_back[4 * 64 + 30], at_front[4 * 64 + 30]);
  EXPECT_EQ(at_front[16 * 64 + 32], 0) << "an exact match costs nothing";
}

// The SIMD kernels against the C reference, bit for bit: widths around the vector steps (and
// below them), every Q8 fraction (view steps of +/-1 at disparities 0..255, larger steps and
// whole-pixel shifts beyond), truncations either side of 255, every census weight, random,
// smooth and black/white images (saturating sums).
TEST(DataTermTest, SimdKernelsEqualTheCReference) {
  {
    Fixed probe;
    CarveTerm(probe, 8, 8, 2);
    if (!probe.term.UseSimd(true)) GTEST_SKIP() << "no SIMD kernels on this CPU";
  }
  std::mt19937 rng(2024);
  const int32_t widths[] = {8, 9, 15, 16, 17, 31, 32, 33, 47, 48, 63, 64, 65, 97, 130};
  const int32_t truncs[] = {1, 2, 45, 127, 128, 200, 254, 255, 256, 400, 765};
  int32_t round = 0;
  for (int32_t w : widths) {
    for (int32_t pass = 0; pass < 3; ++pass, ++round) {
      const int32_t h = 8 + static_cast<int32_t>(rng() % 5);
      const int32_t views = 2 + static_cast<int32_t>(rng() % 15);
      const int32_t ref = static_cast<int32_t>(rng() % static_cast<uint32_t>(views));
      std::vector<std::vector<uint8_t>> pixels(views, std::vector<uint8_t>(3 * w * h));
      for (auto& p : pixels) {
        const uint32_t kind = rng() % 3;
        for (size_t i = 0; i < p.size(); ++i) {
          const uint32_t r = rng();
          p[i] = static_cast<uint8_t>(kind == 0   ? r
                                      : kind == 1 ? (i / 3) * 5 + (r & 15)
                                                  : (r & 1) * 255);
        }
      }
      std::vector<ConstImageU8> imgs;
      for (const auto& p : pixels) imgs.push_back(MakeView(p.data(), w, h, 3));
      Fixed simd, plain;
      CarveTerm(simd, w, h, views);
      CarveTerm(plain, w, h, views);
      ASSERT_TRUE(simd.term.UseSimd(true));
      ASSERT_FALSE(plain.term.UseSimd(false));
      const DataTermParams params{truncs[round % 11], round % 11};
      simd.term.SetParams(params, ref);
      plain.term.SetParams(params, ref);
      simd.term.Prepare(imgs.data());
      plain.term.Prepare(imgs.data());
      for (int32_t v = 0; v < views; ++v) {
        ASSERT_TRUE(
            std::equal(plain.term.census(v), plain.term.census(v) + 3 * w * h, simd.term.census(v)))
            << "census, width " << w << ", view " << v;
      }
      std::vector<uint16_t> a(static_cast<size_t>(w) * h), b(a.size());
      for (int32_t d = 0; d < 256 + 24; ++d) {
        const int32_t disp_q8 = d < 256 ? d : (d - 256) * 97 + 256;
        simd.term.ComputeRows(disp_q8, 0, h, a.data(), w);
        plain.term.ComputeRows(disp_q8, 0, h, b.data(), w);
        ASSERT_EQ(a, b) << "width " << w << ", " << views << " views, reference " << ref
                        << ", disparity " << disp_q8 << "/256, trunc " << params.color_trunc
                        << ", census weight " << params.census_weight;
      }
    }
  }
}

}  // namespace
}  // namespace lb
