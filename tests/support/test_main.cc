// The main of every unit test: the kernel tables the tests' stages pick are the ones the
// programs would pick on this processor (firmware/cli and firmware/daemon hand DetectCpu() to
// algo/ at start). So on a 32-bit ARM core with NEON, every pinned photo, map and energy is
// checked on the NEON kernels, and elsewhere on the SIMD tables the board or PC would run.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "firmware/platform/cpu_features.h"

int main(int argc, char** argv) {
  testing::InitGoogleMock(&argc, argv);
  lb::UseThisCpu();
  return RUN_ALL_TESTS();
}
