// The refocusd program as the board runs it (synthetic sensor, FIFO button): its command line,
// clean shutdown on SIGTERM, and SIGKILL at random moments of a photo, after which a photo's
// name holds a whole JPEG or nothing and the next start clears the leftovers.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "tests/firmware/codecs/jpeg_test_util.h"
#include "tests/firmware/daemon/refocusd_process.h"

namespace lb::test {
namespace {

constexpr int kStartMs = 10000;
constexpr int kPhotoMs = 180000;  // one photo under the sanitizers on a loaded 2-core machine

// A whole JPEG: libjpeg decodes every row, and the file ends with the EOI marker.
void ExpectWholeJpeg(const std::string& path, int32_t width, int32_t height) {
  const std::vector<uint8_t> bytes = ReadFile(path);
  ASSERT_GE(bytes.size(), 4u) << path;
  EXPECT_EQ(bytes[bytes.size() - 2], 0xFF) << path;
  EXPECT_EQ(bytes[bytes.size() - 1], 0xD9) << path;
  int32_t w = 0, h = 0;
  std::vector<uint8_t> ycc;
  std::string error;
  ASSERT_TRUE(DecodeYcc(bytes, &w, &h, &ycc, &error)) << path << ": " << error;
  EXPECT_EQ(w, width);
  EXPECT_EQ(h, height);
}

TEST(RefocusdCommandTest, VersionHelpAndUsageErrors) {
  std::string out;
  EXPECT_EQ(RunRefocusd({"--version"}, &out), 0);
  EXPECT_EQ(out.rfind("refocusd 0.", 0), 0u) << out;
  EXPECT_NE(out.find("synthetic"), std::string::npos) << out;
  EXPECT_EQ(RunRefocusd({"--help"}, &out), 0);
  EXPECT_NE(out.find("--config FILE"), std::string::npos) << out;
  EXPECT_EQ(RunRefocusd({"--frobnicate"}, &out), 2);
  EXPECT_NE(out.find("refocusd: unknown option"), std::string::npos) << out;
  EXPECT_EQ(RunRefocusd({"--config"}, &out), 2);
  EXPECT_EQ(RunRefocusd({"--config", "/nonexistent.conf"}, &out), 1);
  EXPECT_EQ(out, "refocusd: /nonexistent.conf: cannot open: No such file or directory\n");
}

void WriteFile(const std::string& path, const std::string& text) {
  FILE* f = fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr) << path;
  fputs(text.c_str(), f);
  fclose(f);
}

// The line --check-config starts with: the backends `refocusd --version` names.
std::string BackendsLine() {
  std::string out;
  if (RunRefocusd({"--version"}, &out) != 0) return "refocusd --version failed";
  const size_t at = out.find("(sensor backends: "), end = out.rfind(')');
  if (at == std::string::npos || end == std::string::npos || end < at) return "no backends";
  return "refocusd: sensor backends: " + out.substr(at + 18, end - at - 18) + "\n";
}

TEST(RefocusdCommandTest, CheckConfigReportsTheLine) {
  ScratchDir dir;
  const std::string good = dir.Path("good.conf"), bad = dir.Path("bad.conf");
  ASSERT_EQ(mkfifo(dir.Path("button").c_str(), 0600), 0);
  // Everything at start holds: the synthetic camera, a FIFO button, a writable folder.
  WriteFile(good, "backend = synthetic\nf_number = 2\nbutton = " + dir.Path("button") +
                      "\noutput_dir = " + dir.dir() + "\n");
  WriteFile(bad, "backend = synthetic\n# comment\nf_number = 0.5\n");
  std::string out;
  EXPECT_EQ(RunRefocusd({"--check-config", "--config", good}, &out), 0);
  EXPECT_EQ(out, BackendsLine() + "refocusd: " + good + ": configuration OK\n");
  EXPECT_EQ(RunRefocusd({"--check-config", "--config", bad}, &out), 1);
  EXPECT_EQ(out, "refocusd: " + bad + ":3: f_number: '0.5' is not a number from 1 to 22\n");
}

// --check-config says OK only for a camera and a folder refocusd can use.
TEST(RefocusdCommandTest, CheckConfigChecksTheCameraTheButtonAndTheFolder) {
  ScratchDir dir;
  const std::string conf = dir.Path("refocusd.conf");
  ASSERT_EQ(mkfifo(dir.Path("button").c_str(), 0600), 0);
  WriteFile(dir.Path("photos"), "");
  WriteFile(conf, "backend = v4l2\ndevice = " + dir.Path("video7") + "\nbutton = " +
                      dir.Path("button") + "\noutput_dir = " + dir.Path("photos") + "\n");
  std::string out;
  EXPECT_EQ(RunRefocusd({"--check-config", "--config", conf}, &out), 1);
  EXPECT_EQ(out, BackendsLine() + "refocusd: camera " + dir.Path("video7") +
                     ": no such device\nrefocusd: output folder " + dir.Path("photos") +
                     ": not a folder (a regular file)\n");

  WriteFile(conf, "device = /dev/null\nbutton = " + dir.Path("no-button") +
                      "\noutput_dir = " + dir.Path("card/DCIM") + "\n");
  EXPECT_EQ(RunRefocusd({"--check-config", "--config", conf}, &out), 1);
  EXPECT_EQ(out,
            BackendsLine() + "refocusd: camera /dev/null: not a V4L2 device\nrefocusd: button: " +
                dir.Path("no-button") +
                ": cannot open: No such file or directory (errno 2)\nrefocusd: output folder " +
                dir.Path("card/DCIM") + ": no such file or directory\n");
}

TEST(RefocusdCommandTest, MissingButtonIsAClearStartupError) {
  ScratchDir dir;
  RefocusdProcess d(dir.dir(), "button = " + dir.Path("no-such-button") + "\n");
  ASSERT_TRUE(d.Start());
  EXPECT_EQ(d.Wait(kStartMs), 1);
  EXPECT_NE(d.log().find("error: " + dir.Path("no-such-button") + ": cannot open"),
            std::string::npos)
      << d.log();
}

// A folder refocusd cannot write must not lose the first press: it says why it is not ready,
// refuses a press with the reason, keeps checking, and is ready once the folder is there.
TEST(RefocusdProcessTest, OutputFolderThatIsAFileIsNotReadyUntilItIsAFolder) {
  ScratchDir dir;
  const std::string photos = dir.Path("photos");
  WriteFile(photos, "");
  RefocusdProcess d(dir.dir(), "output_dir = " + photos + "\n");
  ASSERT_TRUE(d.Start());
  ASSERT_TRUE(d.WaitForLine("not ready: will check again in 1 s", kStartMs)) << d.log();
  EXPECT_EQ(d.Count("error: output folder " + photos + ": not a folder (a regular file)"), 1)
      << d.log();
  d.Press();
  ASSERT_TRUE(d.WaitForLine(
      "press: refused, not ready: output folder " + photos + ": not a folder (a regular file)",
      kStartMs))
      << d.log();
  EXPECT_EQ(d.Count("ready: sensor"), 0) << d.log();
  // The card is mounted: found by a later check, without a press.
  ASSERT_EQ(unlink(photos.c_str()), 0);
  ASSERT_EQ(mkdir(photos.c_str(), 0755), 0);
  ASSERT_TRUE(d.WaitForLine("ready: sensor synthetic", kStartMs)) << d.log();
  EXPECT_EQ(d.Count("info: output folder " + photos + ": writable now"), 1) << d.log();
  d.Press();
  ASSERT_TRUE(d.WaitForLine("photo 1: saved " + photos + "/IMG_", kPhotoMs)) << d.log();
  d.Signal(SIGTERM);
  EXPECT_EQ(d.Wait(kStartMs), 0) << d.log();
  EXPECT_EQ(d.Count("stopped: 1 photo(s) saved, 0 failed, 1 press(es) refused"), 1) << d.log();
}

TEST(RefocusdProcessTest, SigtermWhileWaitingForTheCameraStopsAtOnce) {
  ScratchDir dir;
  RefocusdProcess d(dir.dir(), "backend = v4l2\ndevice = " + dir.Path("video7") + "\n");
  ASSERT_TRUE(d.Start());
  ASSERT_TRUE(d.WaitForLine("not ready:", kStartMs)) << d.log();
  EXPECT_EQ(d.Count("error: camera " + dir.Path("video7") + ": no such device"), 1) << d.log();
  d.Signal(SIGTERM);
  EXPECT_EQ(d.Wait(2000), 0) << d.log();
  EXPECT_EQ(d.Count("ready: sensor"), 0) << d.log();
}

TEST(RefocusdProcessTest, SigtermLetsThePhotoInProgressFinish) {
  ScratchDir dir;
  // Large enough that the signal lands while the photo is being taken, not after it.
  RefocusdProcess d(dir.dir(), "resolution = 1280x960\nlabels = 32\n");
  ASSERT_TRUE(d.Start());
  ASSERT_TRUE(d.WaitForLine("ready: sensor", kStartMs)) << d.log();
  d.Press();
  ASSERT_TRUE(d.WaitForLine("press: photo 1", kStartMs)) << d.log();
  d.Signal(SIGTERM);
  EXPECT_EQ(d.Wait(kPhotoMs), 0) << d.log();
  EXPECT_EQ(d.Count("stopping: finishing photo 1 first"), 1) << d.log();
  EXPECT_EQ(d.Count("stopped: 1 photo(s) saved, 0 failed"), 1) << d.log();
  std::vector<std::string> photos, temps;
  ListPhotos(d.out_dir(), &photos, &temps);
  ASSERT_EQ(photos.size(), 1u) << d.log();
  EXPECT_TRUE(temps.empty());
  ExpectWholeJpeg(d.out_dir() + "/" + photos[0], 1280, 960);
}

TEST(RefocusdProcessTest, KilledAtRandomMomentsLeavesWholePhotosOrNothing) {
  ScratchDir dir;
  RefocusdProcess d(dir.dir(), "");
  // One clean photo first, to learn how long a photo takes on this machine.
  ASSERT_TRUE(d.Start());
  ASSERT_TRUE(d.WaitForLine("ready: sensor", kStartMs)) << d.log();
  timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  d.Press();
  ASSERT_TRUE(d.WaitForLine("photo 1: saved", kPhotoMs)) << d.log();
  clock_gettime(CLOCK_MONOTONIC, &t1);
  const double photo_us = static_cast<double>(t1.tv_sec - t0.tv_sec) * 1e6 +
                          static_cast<double>(t1.tv_nsec - t0.tv_nsec) * 1e-3;
  d.Signal(SIGTERM);
  ASSERT_EQ(d.Wait(kPhotoMs), 0) << d.log();

  std::mt19937 rng(20261123);
  // Half the kills anywhere in the photo, half while it is written into its temporary (created
  // only once the depth is done, so late in the photo).
  std::uniform_real_distribution<double> anywhere(0.0, 1.2), late(0.8, 1.02);
  constexpr int kTrials = 50;
  int leftovers_seen = 0, removed_reported = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    std::vector<std::string> photos, temps;
    ListPhotos(d.out_dir(), &photos, &temps);
    ASSERT_TRUE(d.Start());
    ASSERT_TRUE(d.WaitForLine("ready: sensor", kStartMs)) << d.log();
    // Leftovers of the previous kill are gone before the first press.
    std::vector<std::string> after;
    ListPhotos(d.out_dir(), &photos, &after);
    EXPECT_TRUE(after.empty()) << "trial " << trial << ": " << after[0];
    if (!temps.empty()) {
      ++leftovers_seen;
      removed_reported +=
          d.Count("output: removed " + std::to_string(temps.size()) + " unfinished");
    }
    d.Press();
    double f = anywhere(rng);
    if (trial % 2 == 0) {
      usleep(static_cast<useconds_t>(f * photo_us));
    } else {
      // The other half while the photo is being written: as soon as its temporary shows, or
      // after a random moment of its last fifth if it never showed in time.
      f = late(rng);
      std::vector<std::string> seen_photos, seen_temps;
      for (int waited = 0; waited < f * photo_us && seen_temps.empty(); waited += 100) {
        usleep(100);
        ListPhotos(d.out_dir(), &seen_photos, &seen_temps);
      }
    }
    d.Signal(SIGKILL);
    ASSERT_EQ(d.Wait(kPhotoMs), 128 + SIGKILL);
    ListPhotos(d.out_dir(), &photos, &temps);
    for (const std::string& name : photos) {
      ExpectWholeJpeg(d.out_dir() + "/" + name, 160, 120);
      if (HasFailure()) {
        FAIL() << "trial " << trial << " (kill after " << f << " of a photo): " << name;
      }
    }
  }
  // The last kill's leftovers go at the next start too.
  ASSERT_TRUE(d.Start());
  ASSERT_TRUE(d.WaitForLine("ready: sensor", kStartMs)) << d.log();
  d.Signal(SIGTERM);
  EXPECT_EQ(d.Wait(kPhotoMs), 0) << d.log();
  std::vector<std::string> photos, temps;
  ListPhotos(d.out_dir(), &photos, &temps);
  EXPECT_TRUE(temps.empty());
  printf("%d kills: %zu photos whole, %d runs found a temporary left by the previous kill\n",
         kTrials, photos.size(), leftovers_seen);
  // The kills did land inside photos (each leaves its temporary), and every start cleared them.
  EXPECT_GT(leftovers_seen, kTrials / 10);
  EXPECT_EQ(removed_reported, leftovers_seen);
}

}  // namespace
}  // namespace lb::test
