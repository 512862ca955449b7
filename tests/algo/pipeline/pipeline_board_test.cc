// The board's default path at the board's sizes: a handheld burst through auto geometry (the
// motion stage included), configured once, then capture, depth and every rendered strip with
// no heap allocation. Its own binary with the label data: minutes under the sanitizers (Debug),
// seconds in Release, where scripts/test.sh runs it. The same path at a quarter of the size
// runs everywhere (pipeline_test.cc, label unit).
#include <gtest/gtest.h>

#include "tests/algo/pipeline/pipeline_burst.h"

namespace lb {
namespace {

using pipelinetest::ExpectBoardPathAllocatesNothing;

TEST(Pipeline, TheBoardsDefaultPathAllocatesNothingAfterConfigure) {
  ExpectBoardPathAllocatesNothing(1280, 960);  // the daemon's default sensor mode
}

TEST(Pipeline, TheBoardsDefaultPathAt12MegapixelsAllocatesNothingAfterConfigure) {
  ExpectBoardPathAllocatesNothing(4056, 3040);
}

TEST(Pipeline, TheBoardsDefaultPathAt12MegapixelsAllocatesNothingWithFourThreads) {
  ExpectBoardPathAllocatesNothing(4056, 3040, 640, 480, 0.01, 4);
}

}  // namespace
}  // namespace lb
