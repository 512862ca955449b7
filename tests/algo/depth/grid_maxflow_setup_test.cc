// GridMaxflow's row kernel (grid_maxflow_setup.h): every SIMD twin this processor runs (AVX2,
// NEON), forced rather than chosen, against the C reference, byte for byte and queue entry for
// queue entry: random rows of every width up to a few steps, starting anywhere, with balances
// and arcs that are often 0, small or at their extremes, over garbage left in the nodes.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "algo/core/cpu.h"
#include "algo/depth/grid_maxflow_setup.h"

namespace lb {
namespace {

struct Variant {
  const char* name;
  const gmf::Kernels* kernels;
};

// Every twin this processor runs (armhf: NEON where the kernel says the core has it, as the
// tests' main reads it).
std::vector<Variant> Twins() {
  std::vector<Variant> v;
  const CpuFeatures cpu = CurrentCpu();
  if (const gmf::Kernels* k = cpu.avx2 ? gmf::Avx2Kernels() : nullptr) v.push_back({"AVX2", k});
  if (const gmf::Kernels* k = cpu.neon ? gmf::NeonKernels() : nullptr) v.push_back({"NEON", k});
  return v;
}

// A row's inputs: nine rows of `width` + 2 values, column x at [x + 1].
struct Rows {
  std::vector<int32_t> data[9];
  GridMaxflowRows in{};

  Rows(std::mt19937& rng, int32_t width) {
    std::uniform_int_distribution<int32_t> kind(0, 5);
    auto balance = [&]() -> int32_t {
      switch (kind(rng)) {
        case 0:
        case 1:
          return 0;
        case 2:
          return static_cast<int32_t>(rng() % 9) - 4;
        case 3:
          return static_cast<int32_t>(rng() % 4001) - 2000;
        case 4:
          return rng() % 2 ? (1 << 30) - 1 : -(1 << 30) + 1;
        default:
          return static_cast<int32_t>(rng() % (1u << 29)) - (1 << 28);
      }
    };
    auto arc = [&]() -> int32_t {
      switch (kind(rng)) {
        case 0:
        case 1:
        case 2:
          return 0;
        case 3:
          return static_cast<int32_t>(rng() % 5);
        case 4:
          return 0xffff;
        default:
          return static_cast<int32_t>(rng() % 0x10000);
      }
    };
    for (int i = 0; i < 9; ++i) {
      // Balances: tcap, up_tcap, down_tcap (rows 0, 6, 8); arcs and flows elsewhere.
      const bool is_balance = i == 0 || i == 6 || i == 8;
      data[i].resize(static_cast<size_t>(width) + 2);
      for (int32_t& v : data[i]) v = is_balance ? balance() : arc();
    }
    const int32_t* p[9];
    for (int i = 0; i < 9; ++i) p[i] = data[i].data() + 1;
    in = {p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8]};
  }
};

TEST(GridMaxflowSetup, TwinsEqualTheReference) {
  const std::vector<Variant> twins = Twins();
  if (twins.empty()) GTEST_SKIP() << "this processor runs no row kernel but the C reference";
  std::mt19937 rng(4242);
  constexpr int32_t kSlack = 8;  // the queue's room past its end
  for (int trial = 0; trial < 4000; ++trial) {
    const int32_t width = 1 + static_cast<int32_t>(rng() % 40);
    const Rows rows(rng, width);
    const int32_t x = 1 + static_cast<int32_t>(rng() % static_cast<uint32_t>(width));
    const int32_t x1 = x + static_cast<int32_t>(rng() % static_cast<uint32_t>(width - x + 1));
    const int32_t base = static_cast<int32_t>(rng() % 100000);
    const int32_t start = static_cast<int32_t>(rng() % 5);  // entries already queued
    std::vector<uint8_t> garbage(16 * static_cast<size_t>(width + 1));
    for (uint8_t& b : garbage) b = static_cast<uint8_t>(rng());
    std::vector<int32_t> queue_garbage(static_cast<size_t>(start + width + kSlack));
    for (int32_t& q : queue_garbage) q = static_cast<int32_t>(rng());

    std::vector<uint8_t> ref_row = garbage;
    std::vector<int32_t> ref_queue = queue_garbage;
    int32_t ref_count = start;
    ASSERT_EQ(gmf::kReference.init_nodes(rows.in, ref_row.data(), x, x1, base, ref_queue.data(),
                                         &ref_count),
              x1);
    for (const Variant& v : twins) {
      SCOPED_TRACE(testing::Message() << v.name << " trial " << trial << " width " << width << " x "
                                      << x << ".." << x1);
      std::vector<uint8_t> row = garbage;
      std::vector<int32_t> queue = queue_garbage;
      int32_t count = start;
      const int32_t stop =
          v.kernels->init_nodes(rows.in, row.data(), x, x1, base, queue.data(), &count);
      ASSERT_GE(stop, x);
      ASSERT_LE(stop, x1);
      gmf::kReference.init_nodes(rows.in, row.data(), stop, x1, base, queue.data(), &count);
      ASSERT_EQ(row, ref_row);
      ASSERT_EQ(count, ref_count);
      for (int32_t i = 0; i < count; ++i) ASSERT_EQ(queue[i], ref_queue[i]) << i;
    }
  }
}

}  // namespace
}  // namespace lb
