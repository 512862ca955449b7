// Soak: 500 presses in a row through the real program (synthetic sensor, small frames). Every
// photo is saved, and neither resident memory nor open descriptors grow once warmed up.
#include <gtest/gtest.h>
#include <signal.h>

#include <cstdio>
#include <string>
#include <vector>

#include "tests/firmware/codecs/jpeg_test_util.h"
#include "tests/firmware/daemon/refocusd_process.h"

namespace lb::test {
namespace {

TEST(RefocusdSoakTest, FiveHundredPressesGrowNothing) {
  constexpr int kPresses = 500, kWarmUp = 50;
  // Allocator noise on a process of ~10 MiB; a per-photo leak of even 1 KiB shows above it.
  constexpr long kSlackKib = 256;
  ScratchDir dir;
  RefocusdProcess d(dir.dir(), "resolution = 128x96\nlabels = 8\n");
  ASSERT_TRUE(d.Start());
  ASSERT_TRUE(d.WaitForLine("ready: sensor", 10000)) << d.log();
  long rss_warm = 0;
  int fds_warm = 0;
  for (int i = 1; i <= kPresses; ++i) {
    d.Press();
    ASSERT_TRUE(d.WaitForLine("photo " + std::to_string(i) + ": saved", 60000))
        << d.log().substr(d.log().size() > 2000 ? d.log().size() - 2000 : 0);
    if (i == kWarmUp) {
      rss_warm = d.ResidentKib();
      fds_warm = d.OpenFds();
    }
  }
  const long rss_end = d.ResidentKib();
  const int fds_end = d.OpenFds();
  printf("after %d photos: %ld KiB resident, %d descriptors; after %d: %ld KiB, %d\n", kWarmUp,
         rss_warm, fds_warm, kPresses, rss_end, fds_end);
  ASSERT_GT(rss_warm, 0);
  EXPECT_LE(rss_end, rss_warm + kSlackKib);
  EXPECT_EQ(fds_end, fds_warm);
  d.Signal(SIGTERM);
  EXPECT_EQ(d.Wait(30000), 0);
  EXPECT_EQ(d.Count("stopped: 500 photo(s) saved, 0 failed, 0 press(es) refused"), 1)
      << d.log().substr(d.log().size() - 500);
  std::vector<std::string> photos, temps;
  ListPhotos(d.out_dir(), &photos, &temps);
  EXPECT_EQ(photos.size(), static_cast<size_t>(kPresses));
  EXPECT_TRUE(temps.empty());
}

}  // namespace
}  // namespace lb::test
