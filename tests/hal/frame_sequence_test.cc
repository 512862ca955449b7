#include "hal/frame_sequence.h"

#include <gtest/gtest.h>

namespace lb {
namespace {

TEST(FrameSequenceTest, ConsecutiveFramesMissNothing) {
  FrameSequence seq;
  uint32_t missing = 99;
  for (uint32_t s = 7; s < 12; ++s) {
    ASSERT_TRUE(seq.Next(s, &missing));
    EXPECT_EQ(missing, 0u);
  }
}

TEST(FrameSequenceTest, GapCountsTheDroppedFrames) {
  FrameSequence seq;
  uint32_t missing = 0;
  ASSERT_TRUE(seq.Next(3, &missing));
  ASSERT_TRUE(seq.Next(6, &missing));
  EXPECT_EQ(missing, 2u);
  EXPECT_EQ(seq.last(), 6u);
}

TEST(FrameSequenceTest, WrapAroundIsContiguous) {
  FrameSequence seq;
  uint32_t missing = 0;
  ASSERT_TRUE(seq.Next(0xFFFFFFFEu, &missing));
  ASSERT_TRUE(seq.Next(0xFFFFFFFFu, &missing));
  ASSERT_TRUE(seq.Next(0u, &missing));
  EXPECT_EQ(missing, 0u);
  ASSERT_TRUE(seq.Next(2u, &missing));
  EXPECT_EQ(missing, 1u);
}

TEST(FrameSequenceTest, RepeatedOrBackwardSequenceIsRejected) {
  FrameSequence seq;
  uint32_t missing = 0;
  ASSERT_TRUE(seq.Next(10, &missing));
  EXPECT_FALSE(seq.Next(10, &missing));
  EXPECT_FALSE(seq.Next(9, &missing));
}

TEST(FrameSequenceTest, ResetStartsAfresh) {
  FrameSequence seq;
  uint32_t missing = 0;
  ASSERT_TRUE(seq.Next(10, &missing));
  seq.Reset();
  ASSERT_TRUE(seq.Next(2, &missing));
  EXPECT_EQ(missing, 0u);
}

}  // namespace
}  // namespace lb
