// The processor's features as the firmware reads them and algo/ picks its kernels from.
#include "firmware/platform/cpu_features.h"

#include <gtest/gtest.h>

namespace lb {
namespace {

TEST(CpuFeatures, DetectionAgreesWithTheArchitecture) {
  const CpuFeatures f = DetectCpu();
#if defined(__x86_64__)
  EXPECT_FALSE(f.neon);
  EXPECT_EQ(f.avx2, __builtin_cpu_supports("avx2") != 0);
  EXPECT_TRUE(f.ssse3 || !f.avx2) << "every AVX2 processor has SSSE3";
#elif defined(__aarch64__)
  EXPECT_TRUE(f.neon) << "NEON is part of AArch64";
  EXPECT_FALSE(f.avx2);
#else
  EXPECT_FALSE(f.avx2);
  RecordProperty("neon", f.neon ? "yes" : "no");
#endif
}

TEST(CpuFeatures, WhatTheFirmwareHandsInIsWhatTheStagesSee) {
  const CpuFeatures before = CurrentCpu();
  CpuFeatures none;
  SetCpu(none);
  EXPECT_FALSE(CurrentCpu().avx2);
  EXPECT_FALSE(CurrentCpu().neon);
  UseThisCpu();
  const CpuFeatures seen = CurrentCpu(), detected = DetectCpu();
  EXPECT_EQ(seen.avx2, detected.avx2);
  EXPECT_EQ(seen.ssse3, detected.ssse3);
  EXPECT_EQ(seen.neon, detected.neon);
  SetCpu(before);
}

}  // namespace
}  // namespace lb
