// The data term's row kernels one by one (data_term_kernels.h): every table this processor
// runs (AVX2, the C cost kernel compiled for SSSE3, NEON), forced rather than chosen, against
// the C reference, bit for bit, on random rows and on rows at the ends of the ranges (black and
// white images, the largest census weight and truncation, every view count, window sums at the
// 2295 cap), at widths around the vector steps.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "algo/depth/data_term_kernels.h"
#include "tests/algo/depth/kernel_variants.h"

namespace lb {
namespace {

const int32_t kWidths[] = {1, 2, 7, 15, 16, 17, 31, 32, 33, 47, 63, 64, 65, 97, 130};

using kerneltest::Others;

// Random bytes (kind 0), a smooth ramp with noise (1), or black and white (2: the extremes).
std::vector<uint8_t> Bytes(std::mt19937& rng, size_t n, int32_t kind) {
  std::vector<uint8_t> b(n);
  for (size_t i = 0; i < n; ++i) {
    const uint32_t r = rng();
    b[i] = static_cast<uint8_t>(kind == 0 ? r : kind == 1 ? (i * 5 + (r & 15)) : (r & 1) * 255);
  }
  return b;
}

TEST(DataTermKernels, CensusVariantsEqualTheReference) {
  LB_SKIP_WITHOUT_VARIANTS();
  std::mt19937 rng(11);
  for (int32_t w : kWidths) {
    for (int32_t kind = 0; kind < 3; ++kind) {
      std::vector<std::vector<uint8_t>> rows;
      const uint8_t* p[5];
      for (int32_t i = 0; i < 5; ++i) rows.push_back(Bytes(rng, w + 4, kind));
      for (int32_t i = 0; i < 5; ++i) p[i] = rows[i].data() + 2;
      const int32_t x0 = static_cast<int32_t>(rng() % w);
      std::vector<uint8_t> want(3 * w, 0xa5);
      dtk::kReference.census(p, x0, w, w, want.data());
      for (const dtk::Variant& v : Others()) {
        std::vector<uint8_t> got(3 * w, 0xa5);
        v.kernels->census(p, x0, w, w, got.data());
        ASSERT_EQ(got, want) << v.name << " w " << w << " kind " << kind;
      }
    }
  }
}

TEST(DataTermKernels, CostVariantsEqualTheReference) {
  LB_SKIP_WITHOUT_VARIANTS();
  std::mt19937 rng(12);
  const int32_t fracs[] = {0, 1, 2, 63, 64, 65, 127, 128, 129, 191, 192, 193, 254, 255};
  const int32_t truncs[] = {0, 1, 45, 254, 255, 256, 765};
  for (int32_t n : kWidths) {
    for (int32_t kind = 0; kind < 3; ++kind) {
      const ptrdiff_t plane = n + 1;
      const std::vector<uint8_t> ref = Bytes(rng, 3 * n, kind), img = Bytes(rng, 3 * (n + 1), kind);
      const std::vector<uint8_t> cref = Bytes(rng, 3 * plane, kind == 2 ? 2 : 0);
      const std::vector<uint8_t> cimg = Bytes(rng, 3 * plane, kind == 2 ? 2 : 0);
      for (int32_t f : fracs) {
        const int32_t trunc = truncs[rng() % 7];
        const int32_t cw = kind == 2 ? 10 : static_cast<int32_t>(rng() % 11);
        std::vector<uint8_t> want(n);
        dtk::kReference.cost(ref.data(), img.data(), cref.data(), cimg.data(), plane, n, f, trunc,
                             cw, want.data());
        for (const dtk::Variant& v : Others()) {
          std::vector<uint8_t> got(n);
          v.kernels->cost(ref.data(), img.data(), cref.data(), cimg.data(), plane, n, f, trunc, cw,
                          got.data());
          ASSERT_EQ(got, want) << v.name << " n " << n << " f " << f << " trunc " << trunc << " cw "
                               << cw << " kind " << kind;
        }
#if defined(__x86_64__)
        // The C source's own builds for SSSE3 and AVX2 (the second is the AVX2 kernel's
        // fallback for short rows), each when the processor has the instructions.
        std::vector<uint8_t> got(n);
        if (__builtin_cpu_supports("ssse3")) {
          dtk::CostRowCSsse3(ref.data(), img.data(), cref.data(), cimg.data(), plane, n, f, trunc,
                             cw, got.data());
          ASSERT_EQ(got, want) << "C for SSSE3 n " << n << " f " << f;
        }
        if (__builtin_cpu_supports("avx2")) {
          dtk::CostRowCAvx2(ref.data(), img.data(), cref.data(), cimg.data(), plane, n, f, trunc,
                            cw, got.data());
          ASSERT_EQ(got, want) << "C for AVX2 n " << n << " f " << f;
        }
#endif
      }
    }
  }
}

TEST(DataTermKernels, HSumVariantsEqualTheReference) {
  LB_SKIP_WITHOUT_VARIANTS();
  std::mt19937 rng(13);
  for (int32_t w : kWidths) {
    for (int32_t kind = 0; kind < 3; ++kind) {
      const std::vector<uint8_t> cost = Bytes(rng, w + 2, kind);
      const int32_t x0 = static_cast<int32_t>(rng() % w);
      std::vector<uint16_t> want(w, 0xbeef);
      dtk::kReference.hsum(cost.data() + 1, x0, w, want.data());
      for (const dtk::Variant& v : Others()) {
        std::vector<uint16_t> got(w, 0xbeef);
        v.kernels->hsum(cost.data() + 1, x0, w, got.data());
        ASSERT_EQ(got, want) << v.name << " w " << w << " kind " << kind;
      }
    }
  }
}

TEST(DataTermKernels, RectRowVariantsEqualTheReference) {
  LB_SKIP_WITHOUT_VARIANTS();
  std::mt19937 rng(15);
  for (int32_t w : kWidths) {
    for (int32_t kind = 0; kind < 3; ++kind) {
      const int32_t others = 1 + static_cast<int32_t>(rng() % dtk::kMaxOthers);
      const std::vector<uint8_t> ref = Bytes(rng, 3 * w, kind);
      const std::vector<uint8_t> cref = Bytes(rng, 3 * w, kind == 2 ? 2 : 0);
      std::vector<std::vector<uint8_t>> img, cimg;
      dtk::RectRow row;
      row.ref = ref.data();
      row.cref = cref.data();
      row.others = others;
      row.width = w;
      row.trunc = kind == 2 ? 765 : static_cast<int32_t>(rng() % 100);
      row.cw = kind == 2 ? 10 : static_cast<int32_t>(rng() % 11);
      row.invalid = static_cast<int32_t>(rng() % 256);
      for (int32_t j = 0; j < others; ++j) {
        img.push_back(Bytes(rng, 3 * w, kind));
        cimg.push_back(Bytes(rng, 3 * w, kind == 2 ? 2 : 0));
        row.img[j] = img.back().data();
        row.cimg[j] = cimg.back().data();
        // Shifts inside the row, partly or wholly outside it, whole pixels and fractions.
        const int32_t px = static_cast<int32_t>(rng() % (2 * w + 8)) - w - 4;
        // Quarter-pixel labels' fractions (0, 64, 128, 192) half the time, any other else.
        const int32_t f = rng() % 2 == 0 ? static_cast<int32_t>(rng() % 4) * 64
                                         : static_cast<int32_t>(rng() % 256);
        row.shift_q8[j] = px * 256 + f;
      }
      std::vector<uint8_t> pixel(w + 2 + 2 * dtk::kPixelSlack);
      row.pixel = pixel.data();
      // Columns: any, and a few at the row's start, middle and end (runs shorter than a
      // vector step, which the SIMD kernels take at either end of their run).
      const int32_t x0 = static_cast<int32_t>(rng() % w);
      const int32_t narrow = w < 5 ? w : 5;
      const int32_t windows[4][2] = {{x0, x0 + 1 + static_cast<int32_t>(rng() % (w - x0))},
                                     {0, narrow},
                                     {(w - narrow) / 2, (w - narrow) / 2 + narrow},
                                     {w - narrow, w}};
      for (const auto& cols : windows) {
        row.x0 = cols[0];
        row.x1 = cols[1];
        std::vector<std::vector<uint16_t>> want(others, std::vector<uint16_t>(w, 0xbeef));
        for (int32_t j = 0; j < others; ++j) row.hsum[j] = want[j].data();
        dtk::kReference.rect_row(row);
        for (const dtk::Variant& v : Others()) {
          std::vector<std::vector<uint16_t>> got(others, std::vector<uint16_t>(w, 0xbeef));
          for (int32_t j = 0; j < others; ++j) row.hsum[j] = got[j].data();
          v.kernels->rect_row(row);
          ASSERT_EQ(got, want) << v.name << " w " << w << " kind " << kind << " x0 " << row.x0
                               << " x1 " << row.x1;
        }
      }
    }
  }
}

TEST(DataTermKernels, SelectVariantsEqualTheReference) {
  LB_SKIP_WITHOUT_VARIANTS();
  std::mt19937 rng(14);
  for (int32_t w : kWidths) {
    for (int32_t others = 1; others <= 15; ++others) {
      const int32_t kind = static_cast<int32_t>(rng() % 4);
      // Horizontal 3-sums 0..765: random, or all at the cap (window sums of 2295), or 0 / 765;
      // or 0..423 (a pixel cost cap of 141) with views that do not see a run of columns (3-sums
      // of 423 on all three rows: a window of `unseen`).
      // The ring: 3 rows per view, `stride` apart (a little more than the row).
      const ptrdiff_t stride = w + 3;
      const int32_t unseen = kind == 3 ? 9 * 141 : 2295;
      std::vector<uint16_t> ring(static_cast<size_t>(3 * others * stride));
      for (uint16_t& s : ring) {
        const uint32_t v = rng();
        s = static_cast<uint16_t>(kind == 0   ? v % 766
                                  : kind == 1 ? 765
                                  : kind == 2 ? (v & 1) * 765
                                              : v % 424);
      }
      for (int32_t j = 0; kind == 3 && j < others; ++j) {
        if (rng() % 2 == 0) continue;
        const int32_t a = static_cast<int32_t>(rng() % w), b = static_cast<int32_t>(rng() % w);
        for (int32_t k = 0; k < 3; ++k)
          for (int32_t x = std::min(a, b); x <= std::max(a, b); ++x)
            ring[(3 * j + k) * stride + x] = 423;
      }
      const int32_t x0 = static_cast<int32_t>(rng() % w);
      std::vector<uint16_t> want(w, 0xbeef);
      dtk::kReference.select(ring.data(), stride, others, unseen, x0, w, want.data());
      for (const dtk::Variant& v : Others()) {
        std::vector<uint16_t> got(w, 0xbeef);
        v.kernels->select(ring.data(), stride, others, unseen, x0, w, got.data());
        ASSERT_EQ(got, want) << v.name << " w " << w << " others " << others << " kind " << kind;
      }
    }
  }
}

// Four other views, two of which see a column: the better of those two (the best half of the
// views that see it); where all four see it, the mean of the best two; where none, `unseen`.
TEST(DataTermKernels, ViewsThatDoNotSeeAPixelAreLeftOut) {
  constexpr int32_t kW = 40, kUnseen = 9 * 141;
  const ptrdiff_t stride = kW;
  std::vector<uint16_t> ring(static_cast<size_t>(3 * 4 * stride));
  auto window = [&](int32_t view, int32_t x, int32_t sum) {  // three rows, sum / 3 each
    for (int32_t k = 0; k < 3; ++k)
      ring[(3 * view + k) * stride + x] = static_cast<uint16_t>(sum / 3);
  };
  for (int32_t x = 0; x < kW; ++x) {
    window(0, x, x < 30 ? 300 : kUnseen);
    window(1, x, x < 30 ? 600 : kUnseen);
    window(2, x, x < 10 ? 900 : kUnseen);
    window(3, x, x < 10 ? 1200 : kUnseen);
  }
  dtk::Variant variants[dtk::kMaxVariants];
  const int32_t n = dtk::Variants(variants);
  for (int32_t i = 0; i < n; ++i) {
    std::vector<uint16_t> d(kW, 0);
    variants[i].kernels->select(ring.data(), stride, 4, kUnseen, 0, kW, d.data());
    for (int32_t x = 0; x < kW; ++x) {
      const int32_t want = x < 10 ? 450 : x < 30 ? 300 : kUnseen;
      ASSERT_EQ(d[x], want) << variants[i].name << " column " << x;
    }
  }
}

TEST(DataTermKernels, TheChosenTableIsOneOfTheVariants) {
  const DataTerm::Kernels* simd = dtk::SimdKernels();
  if (simd == nullptr) GTEST_SKIP() << "no SIMD table on this processor";
  bool found = false;
  for (const dtk::Variant& v : Others()) found = found || v.kernels == simd;
  EXPECT_TRUE(found);
  EXPECT_EQ(simd, dtk::SimdKernels());  // decided once
}

}  // namespace
}  // namespace lb
