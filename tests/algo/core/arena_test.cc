#include "algo/core/arena.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace lb {
namespace {

TEST(Arena, PlanningCountsWhatAllocationUses) {
  Arena plan;
  EXPECT_EQ(plan.Allocate<uint8_t>(10), nullptr);
  (void)plan.AllocateImage<uint16_t>(33, 7, 3);
  const size_t needed = plan.used();
  EXPECT_GE(needed, 10u + 33u * 7u * 3u * 2u);

  alignas(64) static uint8_t block[1 << 16];
  Arena real(block, needed);
  uint8_t* a = real.Allocate<uint8_t>(10);
  ImageU16 img = real.AllocateImage<uint16_t>(33, 7, 3);
  ASSERT_NE(a, nullptr);
  ASSERT_NE(img.data, nullptr);
  EXPECT_FALSE(real.overflowed());
  EXPECT_EQ(real.used(), needed);
  EXPECT_EQ(reinterpret_cast<uintptr_t>(img.data) % Arena::kAlign, 0u);
  EXPECT_EQ(img.stride * sizeof(uint16_t) % Arena::kAlign, 0u);
  EXPECT_GE(img.stride, 33 * 3);
}

TEST(Arena, OverflowIsReportedNotHidden) {
  alignas(64) static uint8_t block[256];
  Arena arena(block, sizeof(block));
  EXPECT_NE(arena.Allocate<uint8_t>(200), nullptr);
  EXPECT_EQ(arena.Allocate<uint8_t>(200), nullptr);
  EXPECT_TRUE(arena.overflowed());
}

TEST(Arena, AlignUpFindsTheNextBoundaryInsideTheBuffer) {
  alignas(Arena::kAlign) uint8_t buffer[3 * Arena::kAlign];
  for (size_t offset = 0; offset <= Arena::kAlign; ++offset) {
    uint8_t* p = buffer + offset;
    const auto* q = static_cast<uint8_t*>(Arena::AlignUp(p));
    EXPECT_EQ(reinterpret_cast<uintptr_t>(q) % Arena::kAlign, 0u) << offset;
    EXPECT_GE(q, p);
    EXPECT_LT(q - p, static_cast<ptrdiff_t>(Arena::kAlign)) << offset;
  }
}

}  // namespace
}  // namespace lb
