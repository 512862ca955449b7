// The plane sweep's span kernels (warp_cost.h, in the data term's tables): every table this
// processor runs (AVX2, NEON), forced rather than chosen, against the C reference, bit for bit:
// runs of spans with random anchors (inside the view, leaving it on any side, crossing rows, on
// whole pixels and half pixels, at the last column and row, steep and reversed, mixed in one
// run), ending at the row's end or at an inner anchor, random column ranges, the extremes of
// the parameters; and whole rows through PlaneCostRow with random
// homographies, random column ranges (the w - 1 anchor) and planes without a map over part of
// the row.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <vector>

#include "algo/depth/data_term_kernels.h"
#include "algo/depth/warp_cost.h"
#include "algo/motion/plane_homography.h"
#include "tests/algo/depth/kernel_variants.h"

namespace lb {
namespace {

using kerneltest::Others;

// A reference and a view of one size (the view's rows padded by `pad` bytes), their censuses,
// filled with random bytes (kind 0), a noisy ramp (1) or black and white (2).
struct Views {
  int32_t width = 0, height = 0;
  std::vector<uint8_t> ref, view, census_ref, census_view;
  ptrdiff_t stride = 0;

  Views(std::mt19937& rng, int32_t w, int32_t h, int32_t pad, int32_t kind)
      : width(w), height(h), stride(3 * w + pad) {
    auto fill = [&](std::vector<uint8_t>& b, size_t n, int32_t k) {
      b.resize(n);
      for (size_t i = 0; i < n; ++i) {
        const uint32_t r = rng();
        b[i] = static_cast<uint8_t>(k == 0 ? r : k == 1 ? (i * 7 + (r & 31)) : (r & 1) * 255);
      }
    };
    fill(ref, static_cast<size_t>(3) * w * h, kind);
    // The view exactly as large as its rows need: a read past its end is caught by ASan.
    fill(view, static_cast<size_t>(stride) * (h - 1) + 3 * w, kind);
    fill(census_ref, static_cast<size_t>(3) * w * h, kind == 2 ? 2 : 0);
    fill(census_view, static_cast<size_t>(3) * w * h, kind == 2 ? 2 : 0);
  }

  WarpRow Row(int32_t y, int32_t trunc, int32_t cw, int32_t invalid) const {
    WarpRow r;
    r.view = view.data();
    r.stride = stride;
    r.census_view = census_view.data();
    r.ref = ref.data() + static_cast<ptrdiff_t>(3) * width * y;
    r.cref = census_ref.data() + static_cast<ptrdiff_t>(3) * width * y;
    r.width = width;
    r.height = height;
    r.trunc = trunc;
    r.cw = cw;
    r.invalid = static_cast<uint8_t>(invalid);
    return r;
  }

  WarpSource Source() const {
    return {ConstImageU8{ref.data(), width, height, 3, 3 * width},
            ConstImageU8{view.data(), width, height, 3, stride}, census_ref.data(),
            census_view.data()};
  }
};

// The end anchors of a span of n pixels starting at x0: the view position of x0 in Q16 and the
// step per pixel, by `kind`: 0 a handheld-like warp (about one pixel per pixel, a small slope in
// y) anywhere in or around the view, 1 random ends far and wide (steep, reversed, outside), 2 on
// whole pixels (fractions 0, up to the last column and row), 3 on half pixels (the nearest tap's
// rounding), 4 the same row for every pixel.
WarpSpanJob RandomSpan(std::mt19937& rng, int32_t w, int32_t h, int32_t x0, int32_t n,
                       int32_t kind) {
  std::uniform_real_distribution<double> u(0, 1);
  auto q16 = [](double px) { return static_cast<int32_t>(std::lround(px * 65536)); };
  double ax = 0, ay = 0, bx = 0, by = 0;
  switch (kind) {
    case 0: {
      ax = x0 + (u(rng) - 0.5) * 12;
      ay = (u(rng) * 1.2 - 0.1) * (h - 1);
      const double scale = 0.9 + 0.25 * u(rng), slope = (u(rng) - 0.5) * 0.2;
      bx = ax + n * scale;
      by = ay + n * slope;
      break;
    }
    case 1:
      ax = (u(rng) * 3 - 1) * w;
      bx = (u(rng) * 3 - 1) * w;
      ay = (u(rng) * 3 - 1) * h;
      by = (u(rng) * 3 - 1) * h;
      break;
    case 2: {
      ax = static_cast<double>(rng() % w);
      ay = static_cast<double>(rng() % h);
      const int32_t step = static_cast<int32_t>(rng() % 3) - 1;  // -1, 0, +1 px per pixel
      bx = ax + n * (step == 0 ? 1 : step);
      by = ay + (rng() % 2 == 0 ? 0 : n);
      if (rng() % 2 == 0) bx = w - 1, ax = bx - n;  // ends on the last column
      if (rng() % 2 == 0) ay = by = h - 1;          // the last row
      break;
    }
    case 3:
      ax = static_cast<double>(rng() % w) + 0.5;
      ay = static_cast<double>(rng() % h) - 0.5;
      bx = ax + n;
      by = ay;
      break;
    default:
      ax = x0 + u(rng) * 4 - 2;
      ay = by = u(rng) * (h - 1);
      bx = ax + n;
      break;
  }
  const int32_t lo = x0 + static_cast<int32_t>(rng() % (n + 1));
  const int32_t hi = std::min(w, lo + 1 + static_cast<int32_t>(rng() % (x0 + n + 1 - lo)));
  return WarpSpanJob{x0, n, q16(ax), q16(ay), q16(bx), q16(by), lo, std::max(hi, lo + 1)};
}

// A run of spans along row y as PlaneCostRow hands one over (warp_cost.h: WarpRun): from a
// random anchor column to the row's end (its short last span included) or to an inner anchor,
// each span's end anchor from RandomSpan's kinds (mixed within the run, so spans of the band
// sit beside steep, outside and crossing ones), the end anchor kept relative to the start one
// (the span's slope) or, for kinds 1 and 2, where RandomSpan put it; wanted columns random, or
// the whole run.
struct RandomRun {
  std::vector<int32_t> x_q16, y_q16;
  WarpRun run{};

  RandomRun(std::mt19937& rng, int32_t w, int32_t h) {
    const int32_t spans_to_end = (w - 1 + kAnchorStep - 1) / kAnchorStep;
    const int32_t x0 = kAnchorStep * static_cast<int32_t>(rng() % spans_to_end);
    const int32_t whole = (w - 1 - x0) / kAnchorStep;  // whole spans before the row's end
    const bool to_end = whole == 0 || rng() % 2 == 0;
    const int32_t count = to_end ? (w - 1 - x0 + kAnchorStep - 1) / kAnchorStep
                                 : 1 + static_cast<int32_t>(rng() % whole);
    const int32_t last = to_end ? w - 1 : x0 + kAnchorStep * count;
    for (int32_t k = 0; k < count; ++k) {
      const int32_t start = x0 + kAnchorStep * k;
      const int32_t n = std::min(kAnchorStep, last - start);
      const int32_t kind = static_cast<int32_t>(rng() % 5);
      const WarpSpanJob j = RandomSpan(rng, w, h, start, n, kind);
      if (k == 0) {
        x_q16.push_back(j.ax);
        y_q16.push_back(j.ay);
      }
      const bool absolute = (kind == 1 || kind == 2) && rng() % 2 == 0;
      x_q16.push_back(absolute ? j.bx : x_q16.back() + (j.bx - j.ax));
      y_q16.push_back(absolute ? j.by : y_q16.back() + (j.by - j.ay));
    }
    const int32_t end = to_end ? w : last;
    int32_t lo = x0, hi = end;
    if (rng() % 3 != 0) {
      lo = x0 + static_cast<int32_t>(rng() % (end - x0));
      hi = lo + 1 + static_cast<int32_t>(rng() % (end - lo));
    }
    run = WarpRun{x_q16.data(), y_q16.data(), x0, count, last, lo, hi};
  }
};

TEST(PlaneKernels, SpanVariantsEqualTheReference) {
  LB_SKIP_WITHOUT_VARIANTS();
  std::mt19937 rng(21);
  const int32_t truncs[] = {0, 1, 45, 254, 255, 256, 765};
  int64_t runs = 0, spans = 0;
  for (const int32_t w : {8, 9, 15, 16, 17, 24, 31, 33, 40, 64, 97, 161, 800}) {
    for (int32_t kind = 0; kind < 3; ++kind) {
      const int32_t h = 2 + static_cast<int32_t>(rng() % 20);
      const Views v(rng, w, h, kind == 1 ? 5 : 0, kind);
      for (int32_t trial = 0; trial < 300; ++trial) {
        const int32_t y = static_cast<int32_t>(rng() % h);
        const int32_t trunc = truncs[rng() % 7];
        const int32_t cw = kind == 2 ? 10 : static_cast<int32_t>(rng() % 11);
        const int32_t invalid = std::min(255, trunc + 24 * cw + 1);
        const WarpRow row = v.Row(y, trunc, cw, invalid);
        const RandomRun r(rng, w, h);
        ++runs;
        spans += r.run.count;
        std::vector<uint8_t> want(w, 0xa5);
        dtk::kReference.plane(row, r.run, want.data());
        for (int32_t x = 0; x < w; ++x) {
          if (x < r.run.lo || x >= r.run.hi) {
            ASSERT_EQ(want[x], 0xa5) << "unwanted column " << x;
          }
        }
        for (const dtk::Variant& var : Others()) {
          std::vector<uint8_t> got(w, 0xa5);
          var.kernels->plane(row, r.run, got.data());
          ASSERT_EQ(got, want) << var.name << " w " << w << " h " << h << " y " << y << " kind "
                               << kind << " trunc " << trunc << " cw " << cw << " run from "
                               << r.run.x0 << ", " << r.run.count << " spans to " << r.run.last
                               << " [" << r.run.lo << "," << r.run.hi << ") first anchors "
                               << r.run.x_q16[0] << "," << r.run.y_q16[0] << " -> "
                               << r.run.x_q16[1] << "," << r.run.y_q16[1];
        }
      }
    }
  }
  std::printf("%lld runs, %lld spans\n", static_cast<long long>(runs),
              static_cast<long long>(spans));
}

// A homography from a random small rotation (up to `deg`) and translation, at inverse depth rho.
PlaneHomography RandomPlane(std::mt19937& rng, int32_t w, int32_t h, double deg, double rho) {
  std::uniform_real_distribution<double> u(-1, 1);
  const double a = deg * M_PI / 180 * u(rng), b = deg * M_PI / 180 * u(rng);
  const double c = deg * M_PI / 180 * u(rng);
  ViewMotion m;
  // Small-angle rotation, re-orthogonalised enough for a test (Rodrigues' first order).
  const double r[3][3] = {{1, -c, b}, {c, 1, -a}, {-b, a, 1}};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) m.rotation[i][j] = r[i][j];
  }
  m.translation[0] = 0.05 * u(rng);
  m.translation[1] = 0.05 * u(rng);
  m.translation[2] = 0.02 * u(rng);
  const double f = 0.8 * w;
  return MakePlaneHomography(CameraIntrinsics{f, f, w / 2.0, h / 2.0}, m, rho);
}

// A row's anchors (PlaneAnchorsFn) against the reference, every count 1..kRunSpans: sums and
// changes of random homographies along rows in and around the view, and made ones at FromSums's
// edges: denominators at 2^20 - 1, 2^20, 2^32 - 1 and 2^32, numerators at +-(den 2^14 - 1) and
// +-den 2^14, quotients on and just beside a half (odd denominators), INT64_MIN.
TEST(PlaneKernels, AnchorVariantsEqualTheReference) {
  LB_SKIP_WITHOUT_VARIANTS();
  std::mt19937 rng(23);
  int64_t mapped = 0, refused = 0;
  auto compare = [&](const int64_t* sums, const int64_t* changes, const char* what,
                     int32_t max_count = kRunSpans) {
    for (int32_t count = 1; count <= max_count; ++count) {
      int32_t wx[kRunSpans], wy[kRunSpans];
      bool wok[kRunSpans];
      const bool want = dtk::PlaneAnchorsC(sums, changes, count, wx, wy, wok);
      for (int32_t k = 0; k < count; ++k) (wok[k] ? mapped : refused) += 1;
      for (const dtk::Variant& var : Others()) {
        int32_t gx[kRunSpans + 1], gy[kRunSpans + 1];
        bool gok[kRunSpans + 1];
        gx[count] = gy[count] = 0x5a5a5a5a;  // not written past count
        ASSERT_EQ(var.kernels->plane_anchors(sums, changes, count, gx, gy, gok), want)
            << var.name << " " << what << " count " << count;
        ASSERT_EQ(gx[count], 0x5a5a5a5a) << var.name << " " << what;
        for (int32_t k = 0; k < count; ++k) {
          ASSERT_EQ(gok[k], wok[k]) << var.name << " " << what << " anchor " << k;
          ASSERT_EQ(gx[k], wx[k]) << var.name << " " << what << " anchor " << k;
          ASSERT_EQ(gy[k], wy[k]) << var.name << " " << what << " anchor " << k;
        }
      }
    }
  };
  for (int32_t trial = 0; trial < 200; ++trial) {
    const PlaneHomography hom =
        RandomPlane(rng, 640, 480, trial < 100 ? 2.0 : 12.0, 0.2 + 0.8 * (trial % 5));
    const int32_t y = static_cast<int32_t>(rng() % 600) - 60;
    const int32_t x = static_cast<int32_t>(rng() % 800) - 80;
    const PlaneRowMap map(hom, y);
    int64_t sums[3], changes[3];
    map.Sums(x, sums);
    map.Changes(kAnchorStep, changes);
    compare(sums, changes, "homography");
  }
  const int64_t edges[] = {(int64_t{1} << 20) - 1, int64_t{1} << 20, (int64_t{1} << 32) - 1,
                           int64_t{1} << 32,       1000003,          (int64_t{1} << 31) + 1};
  for (const int64_t den : edges) {
    for (const int64_t n : {(den << 14) - 1, den << 14, -(den << 14) + 1, -(den << 14), den / 2,
                            -(den / 2) - 1, int64_t{0}, INT64_MIN}) {
      // Steps that cross the edges: the denominator by one each anchor, or the numerator.
      for (const int64_t dd : {int64_t{-1}, int64_t{0}, int64_t{1}}) {
        const int64_t sums[3] = {den - 20 * dd, n, n == INT64_MIN ? 0 : -n};
        const int64_t changes[3] = {dd, n == INT64_MIN ? 0 : dd, n == INT64_MIN ? 1 : -dd};
        compare(sums, changes, "edge");
      }
    }
  }
  // Quotients just at a whole value and just below the next (remainders 0, 1, den - 1, den - 2
  // of |n| 2^16 + den / 2), where the estimate is corrected: odd denominators, so 2^16 has an
  // inverse modulo den.
  std::uniform_int_distribution<int64_t> odd_den(int64_t{1} << 19, (int64_t{1} << 31) - 1);
  auto inverse_2_16 = [](int64_t den) {  // extended Euclid
    int64_t r0 = den, r1 = 65536 % den, t0 = 0, t1 = 1;
    while (r1 != 0) {
      const int64_t q = r0 / r1;
      std::swap(r0, r1);
      r1 -= q * r0;
      std::swap(t0, t1);
      t1 -= q * t0;
    }
    return (t0 % den + den) % den;
  };
  for (int32_t trial = 0; trial < 40000; ++trial) {
    const int64_t den = 2 * odd_den(rng) + 1;
    const int64_t targets[4] = {0, 1, den - 1, den - 2};
    const int64_t t = targets[trial % 4];
    const uint64_t residue =
        static_cast<uint64_t>(((t - den / 2) % den + den) % den) * inverse_2_16(den) % den;
    const int64_t a = static_cast<int64_t>(residue) + static_cast<int64_t>(rng() % 16384) * den;
    const int64_t sums[3] = {den, trial % 2 == 0 ? a : -a, trial % 3 == 0 ? -a : a};
    const int64_t changes[3] = {0, 0, 0};
    compare(sums, changes, "remainder", 4);
  }
  std::uniform_int_distribution<int64_t> big(-(int64_t{1} << 47), int64_t{1} << 47);
  std::uniform_int_distribution<int64_t> den_of(int64_t{1} << 19, int64_t{1} << 33);
  for (int32_t trial = 0; trial < 2000; ++trial) {
    const int64_t sums[3] = {den_of(rng) | 1, big(rng), big(rng)};
    const int64_t changes[3] = {big(rng) >> 20, big(rng) >> (trial % 30), big(rng) >> 10};
    compare(sums, changes, "random");
  }
  EXPECT_GT(mapped, 100000);
  EXPECT_GT(refused, 10000);
}

TEST(PlaneKernels, RowsThroughRandomHomographiesEqualTheReference) {
  LB_SKIP_WITHOUT_VARIANTS();
  std::mt19937 rng(22);
  for (const int32_t w : {8, 17, 33, 48, 49, 64, 161}) {
    const int32_t h = 24;
    const Views v(rng, w, h, 3, static_cast<int32_t>(rng() % 3));
    for (int32_t trial = 0; trial < 40; ++trial) {
      PlaneHomography hom =
          RandomPlane(rng, w, h, trial < 20 ? 2.0 : 12.0, 0.2 + 0.8 * (trial % 5));
      if (trial % 7 == 6) {
        // No map over the right part of every row: the denominator falls below its minimum.
        hom.m[6] = -(int64_t{1} << 30) / (w / 2 + 1);
      }
      const DataTermParams params{45 + static_cast<int32_t>(rng() % 200),
                                  static_cast<int32_t>(rng() % 11)};
      const int32_t invalid = std::min(255, params.color_trunc + 24 * params.census_weight + 1);
      for (int32_t y = 0; y < h; y += 5) {
        const int32_t x0 = static_cast<int32_t>(rng() % w);
        for (const int32_t x1 : {w, std::min(w, x0 + 1 + static_cast<int32_t>(rng() % 20))}) {
          const int32_t begin = x1 == w ? 0 : x0;
          std::vector<uint8_t> want(w, 0x5a);
          PlaneCostRow(hom, v.Source(), y, params, invalid, begin, x1, want.data(),
                       dtk::kReference.plane);
          for (const dtk::Variant& var : Others()) {
            std::vector<uint8_t> got(w, 0x5a);
            PlaneCostRow(hom, v.Source(), y, params, invalid, begin, x1, got.data(),
                         var.kernels->plane, var.kernels->plane_anchors);
            ASSERT_EQ(got, want) << var.name << " w " << w << " y " << y << " [" << begin << ", "
                                 << x1 << ") trial " << trial;
          }
        }
      }
    }
  }
}

// PlaneCostRow's runs against one span at a time: every column's cost is that of its span
// (anchors at multiples of kAnchorStep, the last span ending on column w - 1) mapped by
// PlaneHomography::Map and handed to the reference kernel alone, or `invalid` where an anchor of
// its span has no map. Rows wider than a run (kRunSpans spans), planes without a map left or
// right of a random column, random column ranges; at least 10 % of the columns asked for are
// without a map and 10 % with.
TEST(PlaneKernels, RowsEqualTheirSpansOneByOne) {
  std::mt19937 rng(23);
  int64_t with = 0, without = 0;
  for (const int32_t w : {1, 2, 16, 17, 18, 33, 800, 1000}) {
    const int32_t h = 24;
    const Views v(rng, w, h, 3, static_cast<int32_t>(rng() % 3));
    for (int32_t trial = 0; trial < 30; ++trial) {
      PlaneHomography hom = RandomPlane(rng, w, h, 2.0, 0.2 + 0.8 * (trial % 5));
      const int32_t y = static_cast<int32_t>(rng() % h);
      if (trial % 3 != 0) {
        // No map left (or right) of a random column of row y: the denominator falls to its
        // minimum there.
        const int64_t xc = static_cast<int64_t>(rng() % w);
        hom.m[6] = (trial % 3 == 1 ? 1 : -1) * ((int64_t{1} << 30) / w);
        hom.m[8] = (int64_t{1} << 20) - hom.m[6] * xc - hom.m[7] * y;
      }
      const DataTermParams params{45, 4};
      const int32_t invalid = std::min(255, params.color_trunc + 24 * params.census_weight + 1);
      const int32_t begin = trial % 2 == 0 ? 0 : static_cast<int32_t>(rng() % w);
      const int32_t end = begin + 1 + static_cast<int32_t>(rng() % (w - begin));
      std::vector<uint8_t> got(w, 0x5a), want(w, 0x5a);
      PlaneCostRow(hom, v.Source(), y, params, invalid, begin, end, got.data(),
                   dtk::kReference.plane);
      const WarpRow row = v.Row(y, params.color_trunc, params.census_weight, invalid);
      for (int32_t x = begin; x < end; ++x) {
        int32_t x0 = x / kAnchorStep * kAnchorStep;
        if (x0 == w - 1 && x0 > 0) x0 -= kAnchorStep;  // w - 1 ends the span before it
        const int32_t x1 = std::min(x0 + kAnchorStep, w - 1);
        int32_t a[2], b[2];
        if (!hom.Map(x0, y, &a[0], &b[0]) || !hom.Map(x1, y, &a[1], &b[1])) {
          want[x] = static_cast<uint8_t>(invalid);
          ++without;
          continue;
        }
        dtk::kReference.plane(row, WarpRun{a, b, x0, 1, x1, x, x + 1}, want.data());
        ++with;
      }
      ASSERT_EQ(got, want) << "w " << w << " y " << y << " [" << begin << ", " << end << ") trial "
                           << trial;
    }
  }
  EXPECT_GT(without * 10, with + without);
  EXPECT_GT(with * 10, with + without);
}

}  // namespace
}  // namespace lb
