#include "algo/core/fixed_point.h"

#include <gtest/gtest.h>

namespace lb::fx {
namespace {

TEST(FixedPoint, FromDoubleRoundsHalfAwayFromZero) {
  EXPECT_EQ(FromDouble<8>(1.0), 256);
  EXPECT_EQ(FromDouble<8>(0.5 / 256.0), 1);
  EXPECT_EQ(FromDouble<8>(-0.5 / 256.0), -1);
  EXPECT_EQ(FromDouble<15>(0.299), 9798);
}

TEST(FixedPoint, RoundShiftRoundsHalfUp) {
  EXPECT_EQ(RoundShift<int32_t>(383, 8), 1);    // 1.496
  EXPECT_EQ(RoundShift<int32_t>(384, 8), 2);    // 1.5
  EXPECT_EQ(RoundShift<int32_t>(-384, 8), -1);  // -1.5 rounds up to -1
}

TEST(FixedPoint, SaturateClampsToType) {
  EXPECT_EQ(Saturate<int16_t>(40000), 32767);
  EXPECT_EQ(Saturate<int16_t>(-40000), -32768);
  EXPECT_EQ(Saturate<uint8_t>(-3), 0);
  EXPECT_EQ(AddSat(INT32_MAX, 5), INT32_MAX);
  EXPECT_EQ(AddSat(INT32_MIN, -5), INT32_MIN);
}

TEST(FixedPoint, MulShiftKeepsPrecisionOfWideProducts) {
  // 1.5 (Q15) x 1.25 (Q15) = 1.875 (Q15)
  EXPECT_EQ(MulShift(FromDouble<15>(1.5), FromDouble<15>(1.25), 15), FromDouble<15>(1.875));
  EXPECT_EQ(MulShift(int64_t{1} << 40, int64_t{1} << 20, 30), int64_t{1} << 30);
}

}  // namespace
}  // namespace lb::fx
