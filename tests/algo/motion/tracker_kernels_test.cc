// The tracker's window kernels (algo/motion/tracker_kernels.h): the C reference against the
// bilinear sample it stands for, and every SIMD twin this processor runs against the reference,
// bit for bit, over window sides 3..17 and every kind of fraction.
#include "algo/motion/tracker_kernels.h"

#include <gtest/gtest.h>

#include <random>
#include <utility>
#include <vector>

#include "algo/core/cpu.h"

namespace lb {
namespace {

std::vector<std::pair<const char*, const tk::Kernels*>> Twins() {
  // What the tests' main read of this processor, as the programs do (tests/support/test_main.cc):
  // armhf's NEON table counts where the kernel says the core has NEON.
  const CpuFeatures cpu = CurrentCpu();
  std::vector<std::pair<const char*, const tk::Kernels*>> out;
  if (const tk::Kernels* k = cpu.avx2 ? tk::Avx2Kernels() : nullptr) out.push_back({"AVX2", k});
  if (const tk::Kernels* k = cpu.neon ? tk::NeonKernels() : nullptr) out.push_back({"NEON", k});
  return out;
}

// An image of random bytes, with runs of 0 and 255 so the extremes are reached.
std::vector<uint8_t> Noise(std::mt19937* rng, int32_t w, int32_t h) {
  std::vector<uint8_t> img(static_cast<size_t>(w) * h);
  for (uint8_t& p : img) p = static_cast<uint8_t>((*rng)() & 255);
  for (int32_t x = 0; x < w / 3; ++x) img[x] = 255;
  for (int32_t x = 0; x < w / 3; ++x) img[static_cast<size_t>(w) + x] = 0;
  return img;
}

TEST(TrackerKernels, ReferenceIsTheBilinearSampleInQ4) {
  std::mt19937 rng(7);
  constexpr int32_t kW = 24, kH = 24;
  const std::vector<uint8_t> img = Noise(&rng, kW, kH);
  for (const int32_t fx : {0, 1, 128, 200, 255}) {
    for (const int32_t fy : {0, 64, 255}) {
      std::vector<int32_t> out(11 * 11);
      tk::kReference.sample(img.data() + 2 * kW + 3, kW, fx, fy, 11, out.data());
      for (int32_t j = 0; j < 11; ++j) {
        for (int32_t i = 0; i < 11; ++i) {
          const uint8_t* a = img.data() + (2 + j) * kW + 3 + i;
          // The weights' product in exact integers: sum w p / 2^16, rounded half up to 1/16.
          const int64_t sum = int64_t{a[0]} * (256 - fx) * (256 - fy) +
                              int64_t{a[1]} * fx * (256 - fy) + int64_t{a[kW]} * (256 - fx) * fy +
                              int64_t{a[kW + 1]} * fx * fy;
          ASSERT_EQ(out[j * 11 + i], (sum + 2048) >> 12) << fx << " " << fy;
        }
      }
    }
  }
}

TEST(TrackerKernels, TwinsEqualTheReference) {
  const auto twins = Twins();
  if (twins.empty()) GTEST_SKIP() << "this processor runs no tracker kernels but the C reference";
  std::mt19937 rng(11);
  constexpr int32_t kW = 40, kH = 40;
  for (int32_t trial = 0; trial < 200; ++trial) {
    const std::vector<uint8_t> img = Noise(&rng, kW, kH);
    const int32_t n = 3 + static_cast<int32_t>(rng() % 15);  // 3..17
    const int32_t fx = trial % 5 == 0 ? 0 : static_cast<int32_t>(rng() % 256);
    const int32_t fy = trial % 7 == 0 ? 255 : static_cast<int32_t>(rng() % 256);
    // The window and its right and lower neighbours end at the image's last row and column.
    const int32_t x = trial % 2 ? kW - 1 - n : static_cast<int32_t>(rng() % (kW - n));
    const int32_t y = trial % 3 ? kH - 1 - n : static_cast<int32_t>(rng() % (kH - n));
    const uint8_t* p = img.data() + y * kW + x;
    std::vector<int32_t> tmpl(n * n), gx(n * n), gy(n * n);
    for (int32_t k = 0; k < n * n; ++k) {
      tmpl[k] = static_cast<int32_t>(rng() % 4081);
      gx[k] = static_cast<int32_t>(rng() % 8161) - 4080;
      gy[k] = k % 4 == 0 ? -4080 : static_cast<int32_t>(rng() % 8161) - 4080;
    }
    std::vector<int32_t> want(n * n);
    tk::kReference.sample(p, kW, fx, fy, n, want.data());
    const tk::WindowSums ref =
        tk::kReference.sums(p, kW, fx, fy, n, tmpl.data(), gx.data(), gy.data());
    for (const auto& [name, k] : twins) {
      std::vector<int32_t> got(n * n, -1);
      k->sample(p, kW, fx, fy, n, got.data());
      ASSERT_EQ(got, want) << name << " n " << n << " f " << fx << "," << fy;
      const tk::WindowSums s = k->sums(p, kW, fx, fy, n, tmpl.data(), gx.data(), gy.data());
      ASSERT_EQ(s.bx, ref.bx) << name << " n " << n;
      ASSERT_EQ(s.by, ref.by) << name << " n " << n;
      ASSERT_EQ(s.abs_err, ref.abs_err) << name << " n " << n;
    }
  }
}

// The largest sums: a 17 x 17 window of the largest errors against the largest gradients, the
// bound each twin's int32 lanes are sized for.
TEST(TrackerKernels, TwinsHoldTheLargestSums) {
  const auto twins = Twins();
  if (twins.empty()) GTEST_SKIP() << "this processor runs no tracker kernels but the C reference";
  constexpr int32_t kN = 17, kW = 18;
  const std::vector<uint8_t> img(kW * kW, 255);
  const std::vector<int32_t> tmpl(kN * kN, 0), g(kN * kN, 4080), neg(kN * kN, -4080);
  const tk::WindowSums ref =
      tk::kReference.sums(img.data(), kW, 0, 0, kN, tmpl.data(), g.data(), neg.data());
  EXPECT_EQ(ref.bx, int64_t{kN} * kN * 4080 * 4080);
  EXPECT_EQ(ref.by, -int64_t{kN} * kN * 4080 * 4080);
  for (const auto& [name, k] : twins) {
    const tk::WindowSums s = k->sums(img.data(), kW, 0, 0, kN, tmpl.data(), g.data(), neg.data());
    EXPECT_EQ(s.bx, ref.bx) << name;
    EXPECT_EQ(s.by, ref.by) << name;
    EXPECT_EQ(s.abs_err, ref.abs_err) << name;
  }
}

}  // namespace
}  // namespace lb
