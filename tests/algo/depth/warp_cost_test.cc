// The plane-sweep data term (warp_cost.h): the anchor interpolation against the exact Map, and
// the fixed-point costs against a float reference written from the definition (ProjectPlane in
// double, float bilinear colour, the nearest tap's census Hamming distance, the same 3x3 window
// and best half).
#include "algo/depth/warp_cost.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <vector>

#include "algo/depth/data_term.h"
#include "algo/motion/plane_homography.h"
#include "tests/algo/motion/burst.h"

namespace lb {
namespace {

// Rotation by `deg` about a unit axis (Rodrigues), and a translation of `frac` of the depth.
ViewMotion RandomMotion(std::mt19937& rng, double max_deg, double max_frac) {
  std::uniform_real_distribution<double> u(-1, 1);
  double axis[3] = {u(rng), u(rng), u(rng)};
  const double n = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  for (double& a : axis) a /= n;
  const double th = max_deg * M_PI / 180 * (0.5 + 0.5 * std::fabs(u(rng)));
  const double c = std::cos(th), s = std::sin(th), t = 1 - c;
  const double x = axis[0], y = axis[1], z = axis[2];
  ViewMotion m;
  const double r[3][3] = {{t * x * x + c, t * x * y - s * z, t * x * z + s * y},
                          {t * x * y + s * z, t * y * y + c, t * y * z - s * x},
                          {t * x * z - s * y, t * y * z + s * x, t * z * z + c}};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) m.rotation[i][j] = r[i][j];
  }
  double dir[3] = {u(rng), u(rng), 0.3 * u(rng)};
  const double dn = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
  for (int i = 0; i < 3; ++i) m.translation[i] = max_frac * dir[i] / dn;
  return m;
}

// Worst |interpolated - exact| over every span of the given rows, in px.
double WorstAnchorError(const PlaneHomography& h, int32_t w, int32_t hgt, int32_t row_step) {
  int32_t xq[kAnchorStep + 1], yq[kAnchorStep + 1];
  int64_t worst = 0;
  for (int32_t y = 0; y < hgt; y += row_step) {
    for (int32_t x0 = 0; x0 < w - 1; x0 += kAnchorStep) {
      const int32_t x1 = std::min(x0 + kAnchorStep, w - 1);
      EXPECT_TRUE(WarpSpan(h, x0, x1, y, xq, yq));
      for (int32_t x = x0; x <= x1; ++x) {
        int32_t ex = 0, ey = 0;
        EXPECT_TRUE(h.Map(x, y, &ex, &ey));
        worst = std::max<int64_t>(worst, std::abs(int64_t{xq[x - x0]} - ex));
        worst = std::max<int64_t>(worst, std::abs(int64_t{yq[x - x0]} - ey));
      }
    }
  }
  return static_cast<double>(worst) / 65536.0;
}

// The row map PlaneCostRow uses gives Map's results exactly: on the planes of random motions
// over whole rows, and on quotients built to sit at their rounding boundaries (exactly at half a
// Q16 step, just below and above, the largest and smallest denominators and numerators) with
// both signs, where an estimate off by one would show.
TEST(WarpCostTest, RowMapEqualsMap) {
  std::mt19937 rng(11);
  const CameraIntrinsics k{512.0, 512.0, 320, 240};
  int64_t compared = 0;
  auto same = [&](const PlaneHomography& h, int32_t x, int32_t y) {
    int32_t ex = 0, ey = 0, gx = 0, gy = 0;
    const bool e = h.Map(x, y, &ex, &ey);
    const bool g = PlaneRowMap(h, y).At(x, &gx, &gy);
    ASSERT_EQ(e, g) << x << "," << y;
    int32_t dx = 0, dy = 0;
    ASSERT_EQ(PlaneRowMap(h, y).At<true>(x, &dx, &dy), e) << x << "," << y;
    if (e) {
      ASSERT_EQ(ex, gx) << x << "," << y;
      ASSERT_EQ(ey, gy) << x << "," << y;
      ASSERT_EQ(ex, dx) << x << "," << y;
      ASSERT_EQ(ey, dy) << x << "," << y;
      ++compared;
    }
  };
  for (int32_t trial = 0; trial < 40; ++trial) {
    const ViewMotion m = RandomMotion(rng, 5, 0.05);
    const PlaneHomography h = MakePlaneHomography(k, m, 0.05 + trial * 0.5);
    for (int32_t y = -40; y < 520; y += 7) {
      for (int32_t x = -40; x < 680; ++x) same(h, x, y);
    }
  }
  // Odd denominators, so 2^16 has an inverse modulo den and a numerator can be chosen for any
  // remainder of |n| 2^16 + den / 2: 0 and 1 (a quotient just at or above a whole value), den - 1
  // and den - 2 (just below the next).
  std::uniform_int_distribution<int64_t> den_of(int64_t{1} << 19, (int64_t{1} << 31) - 1);
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
  for (int32_t trial = 0; trial < 100000; ++trial) {
    const int64_t den = trial % 5 == 0   ? (int64_t{1} << 20) + 1
                        : trial % 5 == 1 ? (int64_t{1} << 32) - 1
                                         : 2 * den_of(rng) + 1;
    const int64_t targets[4] = {0, 1, den - 1, den - 2};
    const int64_t t = targets[trial % 4];
    const uint64_t residue =
        static_cast<uint64_t>(((t - den / 2) % den + den) % den) * inverse_2_16(den) % den;
    // |n| = residue + j den below den 2^14 (else Map refuses it, which is compared too).
    const int64_t j = static_cast<int64_t>(rng() % (1u << 14));
    const int64_t a = static_cast<int64_t>(residue) + j * den;
    ASSERT_EQ(((a << 16) + den / 2) % den, t);
    PlaneHomography h;
    h.m[8] = den;
    h.m[2] = trial % 8 < 4 ? a : -a;
    h.m[5] = (trial / 8) % 2 == 0 ? a : -a;
    same(h, 0, 0);
  }
  EXPECT_GT(compared, 1000000);
}

// Stated bound (warp_cost.h): rotations up to 2 degrees, translations up to 2 % of the depth,
// at 640x480 (f = 0.8 w and the synthetic scene's 65 degree field of view): chord error
// 16^2 / 8 * 2 * sin(2 deg) / f / D <= 1/215 px, plus the Q16 rounding of the anchors. The
// planes are the ones a 2 % translation gives from 0.05 to 1 of the depth's inverse (where the
// plane term rho t is largest). A pure translation is affine along rows: exact to 1 Q16 step.
TEST(WarpCostTest, AnchorInterpolationIsWithinBoundOfTheExactMap) {
  std::mt19937 rng(7);
  double worst = 0;
  for (const double f : {512.0, 502.2}) {
    const CameraIntrinsics k{f, f, 320, 240};
    for (int32_t i = 0; i < 6; ++i) {
      const ViewMotion m = RandomMotion(rng, 2.0, 0.02);
      for (const double rho : {0.05, 0.5, 1.0}) {
        worst = std::max(worst, WorstAnchorError(MakePlaneHomography(k, m, rho), 640, 480, 23));
      }
    }
    const ViewMotion shift = RandomMotion(rng, 0.0, 0.02);
    EXPECT_LE(WorstAnchorError(MakePlaneHomography(k, shift, 1.0), 640, 480, 31), 1.0 / 65536);
  }
  std::printf("anchor interpolation: worst %.5f px (1/%.0f) over 2 degree, 2 %% motions\n", worst,
              1 / worst);
  EXPECT_LE(worst, 1.0 / 200);
}

// The kernels fill a span with the invalid cost, without sampling it, when SpanOutsideView says
// so: that must hold only when every one of its positions (WarpSpan's) rounds to outside the
// view. Random affine maps (positions moving up to 3 px per pixel either way, in both axes) put
// spans inside, across every edge and far outside of a 64x48 view.
TEST(WarpCostTest, SpanOutsideViewOnlyWhenEveryPositionIsOutside) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  WarpRow row;
  row.width = 64;
  row.height = 48;
  int32_t outside = 0, inside = 0;
  for (int32_t trial = 0; trial < 20000; ++trial) {
    PlaneHomography h;
    auto q30 = [](double v) { return static_cast<int64_t>(std::llround(v * (1 << 30))); };
    h.m[0] = q30(3 * u(rng));
    h.m[1] = q30(0.2 * u(rng));
    h.m[2] = q30(100 * u(rng));
    h.m[3] = q30(trial % 4 == 0 ? 0.0 : 3 * u(rng));
    h.m[4] = q30(1 + 0.2 * u(rng));
    h.m[5] = q30(80 * u(rng));
    h.m[8] = int64_t{1} << 30;
    const int32_t n = trial % 3 == 0 ? 1 + static_cast<int32_t>(rng() % kAnchorStep) : kAnchorStep;
    const int32_t x0 = static_cast<int32_t>(rng() % 48), y = static_cast<int32_t>(rng() % 48);
    int32_t xq[kAnchorStep + 1], yq[kAnchorStep + 1];
    ASSERT_TRUE(WarpSpan(h, x0, x0 + n, y, xq, yq));
    const WarpSpanJob job{x0, n, xq[0], yq[0], xq[n], yq[n], x0, x0 + n + 1};
    if (!SpanOutsideView(row, job)) {
      ++inside;
      continue;
    }
    ++outside;
    for (int32_t i = 0; i <= n; ++i) {
      const int32_t xs = (xq[i] + 128) >> 8, ys = (yq[i] + 128) >> 8;
      ASSERT_TRUE(xs < 0 || xs > 63 * 256 || ys < 0 || ys > 47 * 256)
          << "trial " << trial << " pixel " << i << " at " << xs / 256.0 << ", " << ys / 256.0;
    }
  }
  EXPECT_GT(outside, 2000);
  EXPECT_GT(inside, 2000);
}

std::vector<uint32_t> Census(const ConstImageU8& img) {
  const int32_t w = img.width, h = img.height;
  auto luma = [&](int32_t x, int32_t y) {
    const uint8_t* p = img.At(std::clamp(x, 0, w - 1), std::clamp(y, 0, h - 1));
    return (77 * p[0] + 150 * p[1] + 29 * p[2] + 128) >> 8;
  };
  std::vector<uint32_t> out(static_cast<size_t>(w) * h);
  for (int32_t y = 0; y < h; ++y) {
    for (int32_t x = 0; x < w; ++x) {
      uint32_t bits = 0;
      for (int32_t dy = -2; dy <= 2; ++dy) {
        for (int32_t dx = -2; dx <= 2; ++dx) {
          if (dx != 0 || dy != 0) bits = (bits << 1) | (luma(x + dx, y + dy) < luma(x, y) ? 1 : 0);
        }
      }
      out[y * w + x] = bits;
    }
  }
  return out;
}

// D from its definition at the exact positions (nominal), and the interval the fixed-point D
// must lie in when its positions are off the exact ones by up to `delta` px per axis: a sample's
// colour then moves by at most 2 delta G + 0.5 per channel (G: the largest step between
// neighbours in the 4x4 taps around it, the 0.5 the rounding), the nearest census tap may be
// either neighbour when the position is within delta of a half pixel, and a sample within delta
// of a view's edge may be valid or not (cost 0..invalid). Window sums and order statistics are
// monotone, so the bounds go through the window and the best-half mean as they are, for a given
// set of views that see the pixel (a window not all outside). A window whose samples are all
// outside or unsure may or may not see it: the bounds take the extremes over both.
struct Reference {
  std::vector<float> d, lo, hi;
};

struct SampleCost {
  float nominal, lo, hi;
  bool outside = false, unsure = false;  // outside the view at the exact position; near its edge
};

// Per view, computed once: the census and each pixel's largest channel step to its right and
// lower neighbours.
struct ViewData {
  std::vector<uint32_t> census;
  std::vector<int32_t> step;
};

ViewData Prepare(const ConstImageU8& v) {
  const int32_t w = v.width, h = v.height;
  ViewData d{Census(v), std::vector<int32_t>(static_cast<size_t>(w) * h, 0)};
  for (int32_t y = 0; y < h; ++y) {
    for (int32_t x = 0; x < w; ++x) {
      for (int32_t c = 0; c < 3; ++c) {
        int32_t& g = d.step[y * w + x];
        if (x + 1 < w) g = std::max(g, std::abs(v.At(x, y)[c] - v.At(x + 1, y)[c]));
        if (y + 1 < h) g = std::max(g, std::abs(v.At(x, y)[c] - v.At(x, y + 1)[c]));
      }
    }
  }
  return d;
}

SampleCost Sample(const ConstImageU8& view, const ViewData& data, const uint8_t* ref_rgb,
                  uint32_t cref, double vx, double vy, const DataTermParams& prm, double delta) {
  const uint32_t* census = data.census.data();
  const int32_t w = view.width, h = view.height;
  const float invalid =
      std::min(255.0f, static_cast<float>(prm.color_trunc + 24 * prm.census_weight + 1));
  auto edge = [&](double p, int32_t size) {
    return std::fabs(p) <= delta || std::fabs(p - (size - 1)) <= delta;
  };
  const bool valid = vx >= 0 && vy >= 0 && vx <= w - 1 && vy <= h - 1;
  const bool unsure = edge(vx, w) || edge(vy, h);
  if (!valid) return {invalid, unsure ? 0 : invalid, invalid, true, unsure};
  const int32_t ix = static_cast<int32_t>(vx), iy = static_cast<int32_t>(vy);
  const float fx = static_cast<float>(vx - ix), fy = static_cast<float>(vy - iy);
  const int32_t ix1 = std::min(ix + 1, w - 1), iy1 = std::min(iy + 1, h - 1);
  const float wt[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
  const int32_t tx[4] = {ix, ix1, ix, ix1}, ty[4] = {iy, iy, iy1, iy1};
  int32_t g = 0;
  for (int32_t y = std::max(0, iy - 1); y <= std::min(h - 1, iy + 2); ++y) {
    for (int32_t x = std::max(0, ix - 1); x <= std::min(w - 1, ix + 2); ++x) {
      g = std::max(g, data.step[y * w + x]);
    }
  }
  float ad = 0;
  for (int32_t c = 0; c < 3; ++c) {
    float s = 0;
    for (int t = 0; t < 4; ++t) s += wt[t] * view.At(tx[t], ty[t])[c];
    ad += std::fabs(ref_rgb[c] - s);
  }
  const float trunc = static_cast<float>(prm.color_trunc);
  const float e = static_cast<float>(3 * (0.5 + 2 * delta * g));
  const float a = std::min(ad, trunc);
  const float a_lo = std::max(0.0f, std::min(ad - e, trunc)), a_hi = std::min(ad + e, trunc);
  // Nearest census tap, rounded half up; either neighbour when within delta of the half.
  auto taps = [&](float f, int32_t i0, int32_t i1, int32_t* lo, int32_t* hi) {
    *lo = *hi = f >= 0.5f ? i1 : i0;
    if (std::fabs(f - 0.5f) <= delta) {
      *lo = i0;
      *hi = i1;
    }
  };
  int32_t x_lo, x_hi, y_lo, y_hi;
  taps(fx, ix, ix1, &x_lo, &x_hi);
  taps(fy, iy, iy1, &y_lo, &y_hi);
  int32_t h_min = 24, h_max = 0;
  for (int32_t y = y_lo; y <= y_hi; ++y) {
    for (int32_t x = x_lo; x <= x_hi; ++x) {
      const int32_t ham = __builtin_popcount(cref ^ census[y * w + x]);
      h_min = std::min(h_min, ham);
      h_max = std::max(h_max, ham);
    }
  }
  const int32_t nx = fx >= 0.5f ? ix1 : ix, ny = fy >= 0.5f ? iy1 : iy;
  const float cw = static_cast<float>(prm.census_weight);
  const float ham = static_cast<float>(__builtin_popcount(cref ^ census[ny * w + nx]));
  SampleCost out{std::min(255.0f, a + cw * ham), std::min(255.0f, a_lo + cw * h_min),
                 std::min(255.0f, a_hi + cw * h_max)};
  if (unsure) out.lo = 0, out.hi = invalid;
  out.unsure = unsure;
  return out;
}

Reference ReferenceTerm(const motiontest::Burst& b, const std::vector<ViewData>& data,
                        const DataTermParams& prm, double rho, double delta) {
  const int32_t w = b.scene.width(), h = b.scene.height(), ref = b.scene.reference();
  std::vector<std::vector<SampleCost>> cost;  // per other view
  for (int32_t v = 0; v < b.scene.views(); ++v) {
    if (v == ref) continue;
    const ViewMotion& m = b.scene.pose(v);
    std::vector<SampleCost> c(static_cast<size_t>(w) * h);
    for (int32_t y = 0; y < h; ++y) {
      for (int32_t x = 0; x < w; ++x) {
        double vx = 0, vy = 0;
        ProjectPlane(b.intrinsics, m, rho, x + 0.5, y + 0.5, &vx, &vy);
        c[y * w + x] = Sample(b.views[v], data[v], b.views[ref].At(x, y),
                              data[ref].census[y * w + x], vx - 0.5, vy - 0.5, prm, delta);
      }
    }
    cost.push_back(std::move(c));
  }
  const size_t views = cost.size();
  // The mean of the best half of `sums` over the views in `seen` (bit v), or of all when none.
  auto best_half = [&](const float* sums, uint32_t seen) {
    float kept[16];
    size_t n = 0;
    for (size_t v = 0; v < views; ++v)
      if (seen == 0 || (seen >> v & 1)) kept[n++] = sums[v];
    std::sort(kept, kept + n);
    const size_t keep = (n + 1) / 2;
    float mean = 0;
    for (size_t k = 0; k < keep; ++k) mean += kept[k] / static_cast<float>(keep);
    return mean;
  };
  Reference out;
  out.d.resize(static_cast<size_t>(w) * h);
  out.lo.resize(out.d.size());
  out.hi.resize(out.d.size());
  for (int32_t y = 0; y < h; ++y) {
    for (int32_t x = 0; x < w; ++x) {
      float sums[3][16];
      uint32_t sees = 0, either = 0;  // bit v: sees at the exact positions; may or may not
      for (size_t v = 0; v < views; ++v) {
        const std::vector<SampleCost>& c = cost[v];
        float s[3] = {0, 0, 0};
        bool in = false, surely_in = false, any_unsure = false;
        for (int32_t dy = -1; dy <= 1; ++dy) {
          for (int32_t dx = -1; dx <= 1; ++dx) {
            const SampleCost& q =
                c[std::clamp(y + dy, 0, h - 1) * w + std::clamp(x + dx, 0, w - 1)];
            s[0] += q.nominal;
            s[1] += q.lo;
            s[2] += q.hi;
            in = in || !q.outside;
            surely_in = surely_in || (!q.outside && !q.unsure);
            any_unsure = any_unsure || q.unsure;
          }
        }
        for (int i = 0; i < 3; ++i) sums[i][v] = s[i];
        if (in) sees |= 1u << v;
        if (!surely_in && any_unsure) either |= 1u << v;
      }
      out.d[y * w + x] = best_half(sums[0], sees);
      // Every choice for the views that may or may not see the pixel (the others as they are).
      float lo = 1e9f, hi = -1e9f;
      for (uint32_t set = 0; set < (1u << views); ++set) {
        if ((set ^ sees) & ~either) continue;
        lo = std::min(lo, best_half(sums[1], set));
        hi = std::max(hi, best_half(sums[2], set));
      }
      out.lo[y * w + x] = lo;
      out.hi[y * w + x] = hi;
    }
  }
  return out;
}

struct Fixed {
  std::vector<uint8_t> memory;
  DataTerm term;
};

void PrepareTerm(Fixed& f, const motiontest::Burst& b, const DataTermParams& params) {
  const int32_t w = b.scene.width(), h = b.scene.height(), n = b.scene.views();
  Arena plan;
  DataTerm planner;
  planner.Carve(plan, w, h, n);
  f.memory.assign(plan.used() + Arena::kAlign, 0);
  void* const base = Arena::AlignUp(f.memory.data());
  Arena arena(base, plan.used());
  f.term.Carve(arena, w, h, n);
  ASSERT_FALSE(arena.overflowed());
  f.term.SetParams(params, b.scene.reference());
  f.term.Prepare(b.views.data());
}

// Every view's homography of the plane at inverse depth rho, from the scene's true poses.
std::vector<PlaneHomography> TruePlanes(const motiontest::Burst& b, double rho) {
  std::vector<PlaneHomography> planes(b.scene.views());
  for (int32_t v = 0; v < b.scene.views(); ++v) {
    planes[v] = MakePlaneHomography(b.intrinsics, b.scene.pose(v), rho);
  }
  return planes;
}

// Stated tolerance: every fixed-point D lies within the reference's interval (above) for a
// position error delta = 1/512 (Q8 weights) + 2^-16 (Map) + the anchors' chord bound for this
// focal length and the burst's rotations of at most 1 degree (warp_cost.h; 1/109 px at
// f ~ 125 px), widened by 1 for the Q15 mean. Against the nominal (exact-position) reference the
// mean difference must stay below 4 of D's 0..2295: the nearest census tap
// flips, by up to 24 census weights, where a position lies within delta of a half pixel.
TEST(WarpCostTest, FixedPointAgreesWithFloatReference) {
  motiontest::Burst b;
  ASSERT_TRUE(motiontest::MakeBurst(motiontest::Handheld(3), 160, 120, 4, &b));
  const int32_t w = b.scene.width(), h = b.scene.height();
  const double rho_min = b.scene.inverse_depth_min_q12() / 4096.0;
  const double rho_max = b.scene.inverse_depth_max_q12() / 4096.0;
  const double chord =
      kAnchorStep * kAnchorStep / 8.0 * 2 * std::sin(M_PI / 180) / b.intrinsics.fx / 0.97;
  const double delta = 1.0 / 512 + 1.0 / 65536 + chord;
  std::vector<ViewData> data;
  for (const ConstImageU8& v : b.views) data.push_back(Prepare(v));
  for (const DataTermParams params : {DataTermParams{}, DataTermParams{200, 2}}) {
    Fixed f;
    PrepareTerm(f, b, params);
    for (const double t : {0.0, 0.3, 0.7, 1.0}) {
      const double rho = rho_min + t * (rho_max - rho_min);
      const std::vector<PlaneHomography> planes = TruePlanes(b, rho);
      f.term.SetPlanes(planes.data());
      std::vector<uint16_t> fixed(static_cast<size_t>(w) * h);
      f.term.ComputeRows(0, 0, h, fixed.data(), w);
      const Reference expect = ReferenceTerm(b, data, params, rho, delta);
      double sum = 0, worst = 0, width = 0;
      int32_t outside = 0;
      for (size_t i = 0; i < fixed.size(); ++i) {
        const double d = std::fabs(fixed[i] - expect.d[i]);
        sum += d;
        worst = std::max(worst, d);
        width += expect.hi[i] - expect.lo[i];
        outside += fixed[i] < expect.lo[i] - 1 || fixed[i] > expect.hi[i] + 1;
      }
      const double n = static_cast<double>(fixed.size());
      std::printf("rho %.3f: |fixed - float| mean %.3f worst %.1f; interval width mean %.1f\n", rho,
                  sum / n, worst, width / n);
      EXPECT_EQ(outside, 0) << "rho " << rho;
      EXPECT_LT(sum / n, 4.0) << "rho " << rho;
    }
  }
}

// Restricted moves compute D over column ranges that start anywhere: the anchors stay on their
// grid, so every range gives the whole row's values bit for bit (widths around the anchor step,
// the last column as the end of the span before it).
TEST(WarpCostTest, ColumnRangesEqualTheWholeRow) {
  for (const int32_t w : {33, 40, 49}) {
    motiontest::Burst b;
    ASSERT_TRUE(motiontest::MakeBurst(motiontest::Handheld(5), w, 24, 3, &b));
    const int32_t h = b.scene.height();
    Fixed f;
    PrepareTerm(f, b, DataTermParams{});
    const std::vector<PlaneHomography> planes =
        TruePlanes(b, b.scene.inverse_depth_min_q12() / 4096.0);
    f.term.SetPlanes(planes.data());
    std::vector<uint16_t> whole(static_cast<size_t>(w) * h);
    f.term.ComputeRows(0, 0, h, whole.data(), w);
    for (int32_t x0 = 0; x0 < w; x0 += 3) {
      for (const int32_t x1 : {x0 + 1, std::min(w, x0 + 17), w}) {
        std::vector<uint16_t> rect(whole.size(), 0xabcd);
        f.term.ComputeRect(0, x0, x1, 2, h - 2, rect.data() + 2 * w, w);
        for (int32_t y = 2; y < h - 2; ++y) {
          for (int32_t x = x0; x < x1; ++x) {
            ASSERT_EQ(rect[y * w + x], whole[y * w + x])
                << "width " << w << " x " << x << " of [" << x0 << ", " << x1 << ")";
          }
        }
      }
    }
  }
}

// The plane sweep through the whole data term, its SIMD kernels (and the reference rows they
// take prepared once per row for every view) against the C reference, bit for bit: whole images
// and rectangles starting anywhere, at widths around the kernel's steps and spans, planes across
// the scene's depths, two parameter sets.
TEST(WarpCostTest, SimdDataTermEqualsTheCReference) {
  for (const int32_t w : {16, 33, 50, 97}) {
    motiontest::Burst b;
    ASSERT_TRUE(motiontest::MakeBurst(motiontest::Handheld(7), w, 30, 4, &b));
    const int32_t h = b.scene.height();
    for (const DataTermParams params : {DataTermParams{}, DataTermParams{200, 2}}) {
      Fixed simd, plain;
      PrepareTerm(simd, b, params);
      PrepareTerm(plain, b, params);
      if (!simd.term.UseSimd(true)) GTEST_SKIP() << "no SIMD kernels on this CPU";
      ASSERT_FALSE(plain.term.UseSimd(false));
      for (const double t : {0.0, 0.5, 1.0}) {
        const double lo = b.scene.inverse_depth_min_q12() / 4096.0;
        const double hi = b.scene.inverse_depth_max_q12() / 4096.0;
        const std::vector<PlaneHomography> planes = TruePlanes(b, lo + t * (hi - lo));
        simd.term.SetPlanes(planes.data());
        plain.term.SetPlanes(planes.data());
        std::vector<uint16_t> a(static_cast<size_t>(w) * h), c(a.size());
        simd.term.ComputeRows(0, 0, h, a.data(), w);
        plain.term.ComputeRows(0, 0, h, c.data(), w);
        ASSERT_EQ(a, c) << "width " << w << " depth " << t;
        for (int32_t x0 = 0; x0 < w; x0 += 7) {
          const int32_t x1 = std::min(w, x0 + 1 + (x0 * 5) % 23);
          simd.term.ComputeRect(0, x0, x1, 3, h - 3, a.data() + 3 * w, w);
          plain.term.ComputeRect(0, x0, x1, 3, h - 3, c.data() + 3 * w, w);
          ASSERT_EQ(a, c) << "width " << w << " [" << x0 << ", " << x1 << ") depth " << t;
        }
      }
    }
  }
}

}  // namespace
}  // namespace lb
