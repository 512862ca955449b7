// refocusd's start and stop as a user meets them: a web page that cannot start costs nothing
// while the camera runs on, SIGHUP ends it as SIGTERM does (after the photo in progress), and a
// web setting that cannot work is a configuration error on its line.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "tests/firmware/codecs/jpeg_test_util.h"
#include "tests/firmware/daemon/refocusd_process.h"

namespace lb::test {
namespace {

constexpr int kStartMs = 10000;
constexpr int kPhotoMs = 180000;  // one photo under the sanitizers on a loaded 2-core machine
constexpr char kToken[] = "lifecycle-token-0123456789";

std::string WebRoot() {
  const char* src = getenv("LB_SOURCE_DIR");
  return std::string(src ? src : ".") + "/firmware/web/www";
}

void WriteFile(const std::string& path, const std::string& text) {
  FILE* f = fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr) << path;
  fputs(text.c_str(), f);
  fclose(f);
}

// The threads of a refocusd that has said `line` and then had half a second to settle.
int ThreadsAfter(RefocusdProcess* d, const std::string& line) {
  EXPECT_TRUE(d->WaitForLine("ready: sensor", kStartMs)) << d->log();
  EXPECT_TRUE(d->WaitForLine(line, kStartMs)) << d->log();
  d->WaitForLine("no such line", 500);
  return d->Threads();
}

TEST(RefocusdLifecycleTest, AWebPageThatCannotStartKeepsNoRenderer) {
  // Hold a port so refocusd cannot bind it.
  const int holder = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(bind(holder, reinterpret_cast<sockaddr*>(&a), sizeof(a)), 0);
  ASSERT_EQ(listen(holder, 1), 0);
  socklen_t len = sizeof(a);
  getsockname(holder, reinterpret_cast<sockaddr*>(&a), &len);
  const int port = ntohs(a.sin_port);

  ScratchDir off_dir, taken_dir;
  RefocusdProcess off(off_dir.dir(), "threads = 2\n");
  ASSERT_TRUE(off.Start());
  const int off_threads = ThreadsAfter(&off, "ready: sensor");
  RefocusdProcess taken(taken_dir.dir(), "threads = 2\nweb = 127.0.0.1:" + std::to_string(port) +
                                             "\nweb_token = " + kToken +
                                             "\nweb_root = " + WebRoot() + "\n");
  ASSERT_TRUE(taken.Start());
  const int taken_threads = ThreadsAfter(&taken, "the camera runs without the web page");
  // The renderer's thread and its workers are gone with the page.
  EXPECT_GT(off_threads, 0);
  EXPECT_EQ(taken_threads, off_threads) << taken.log();
  printf("threads: web off %d, web on a taken port %d\n", off_threads, taken_threads);

  // And the camera still works.
  taken.Press();
  EXPECT_TRUE(taken.WaitForLine("photo 1: saved", kPhotoMs)) << taken.log();
  for (RefocusdProcess* d : {&off, &taken}) {
    d->Signal(SIGTERM);
    EXPECT_EQ(d->Wait(kStartMs), 0) << d->log();
  }
  close(holder);
}

TEST(RefocusdLifecycleTest, SighupFinishesThePhotoInProgressThenExitsCleanly) {
  ScratchDir dir;
  // Slow enough that the signal lands while the photo is being taken.
  RefocusdProcess d(dir.dir(), "resolution = 1280x960\nlabels = 32\n");
  ASSERT_TRUE(d.Start());
  ASSERT_TRUE(d.WaitForLine("ready: sensor", kStartMs)) << d.log();
  d.Press();
  ASSERT_TRUE(d.WaitForLine("press: photo 1", kStartMs)) << d.log();
  d.Signal(SIGHUP);
  EXPECT_EQ(d.Wait(kPhotoMs), 0) << d.log();
  EXPECT_EQ(d.Count("stopping: finishing photo 1 first"), 1) << d.log();
  EXPECT_EQ(d.Count("stopped: 1 photo(s) saved, 0 failed"), 1) << d.log();
  std::vector<std::string> photos, temps;
  ListPhotos(d.out_dir(), &photos, &temps);
  ASSERT_EQ(photos.size(), 1u) << d.log();
  EXPECT_TRUE(temps.empty());
  const std::vector<uint8_t> bytes = ReadFile(d.out_dir() + "/" + photos[0]);
  int32_t w = 0, h = 0;
  std::vector<uint8_t> ycc;
  std::string error;
  ASSERT_TRUE(DecodeYcc(bytes, &w, &h, &ycc, &error)) << error;
  EXPECT_EQ(w, 1280);
  EXPECT_EQ(h, 960);
}

TEST(RefocusdLifecycleTest, SighupWhileIdleExitsCleanly) {
  ScratchDir dir;
  RefocusdProcess d(dir.dir(), "");
  ASSERT_TRUE(d.Start());
  ASSERT_TRUE(d.WaitForLine("ready: sensor", kStartMs)) << d.log();
  d.Signal(SIGHUP);
  EXPECT_EQ(d.Wait(kStartMs), 0) << d.log();
}

// The web lines of a configuration that is otherwise fine for --check-config.
std::string CheckConfigWith(const ScratchDir& dir, const std::string& web, std::string* out) {
  const std::string conf = dir.Path("web.conf");
  mkdir(dir.Path("photos").c_str(), 0755);
  mkfifo(dir.Path("button").c_str(), 0600);
  WriteFile(conf, "backend = synthetic\nbutton = " + dir.Path("button") +
                      "\noutput_dir = " + dir.Path("photos") + "\n" + web);
  RunRefocusd({"--check-config", "--config", conf}, out);
  return conf;
}

TEST(RefocusdLifecycleTest, AWebRootWithoutThePageIsAnErrorOnItsLine) {
  ScratchDir dir;
  std::string out;
  const std::string web = std::string("web = 127.0.0.1:8080\nweb_token = ") + kToken + "\n";
  std::string conf = CheckConfigWith(dir, web + "web_root = " + dir.Path("nowhere") + "\n", &out);
  EXPECT_EQ(out, "refocusd: " + conf + ":6: web_root: cannot read " + dir.Path("nowhere") +
                     "/index.html: No such file or directory\n");
  EXPECT_EQ(RunRefocusd({"--check-config", "--config", conf}, &out), 1);

  // A folder without the page.
  const std::string empty = dir.Path("www");
  mkdir(empty.c_str(), 0755);
  CheckConfigWith(dir, web + "web_root = " + empty + "\n", &out);
  EXPECT_NE(out.find(conf + ":6: web_root: cannot read " + empty + "/index.html"),
            std::string::npos)
      << out;

  // The default folder, where no package has put the page, points at the web line.
  if (access("/usr/share/refocusd/www/index.html", F_OK) != 0) {
    CheckConfigWith(dir, web, &out);
    EXPECT_NE(out.find(conf + ":4: web is on but the page's files are missing: cannot read "
                              "/usr/share/refocusd/www/index.html"),
              std::string::npos)
        << out;
  }

  // refocusd itself stops at the same line instead of serving 404s.
  RefocusdProcess d(dir.dir(), std::string("web = 127.0.0.1:0\nweb_token = ") + kToken +
                                   "\nweb_root = " + empty + "\n");
  ASSERT_TRUE(d.Start());
  EXPECT_EQ(d.Wait(kStartMs), 1) << d.log();
  EXPECT_NE(d.log().find("refocusd.conf:8: web_root: cannot read " + empty + "/index.html"),
            std::string::npos)
      << d.log();
  EXPECT_EQ(d.Count("listening"), 0) << d.log();

  // With the page there, the same lines are fine.
  CheckConfigWith(dir, web + "web_root = " + WebRoot() + "\n", &out);
  EXPECT_NE(out.find("configuration OK"), std::string::npos) << out;
}

TEST(RefocusdLifecycleTest, PortZeroIsAnErrorOnItsLine) {
  ScratchDir dir;
  std::string out;
  const std::string conf = CheckConfigWith(
      dir,
      std::string("web = 127.0.0.1:0\nweb_token = ") + kToken + "\nweb_root = " + WebRoot() + "\n",
      &out);
  EXPECT_EQ(RunRefocusd({"--check-config", "--config", conf}, &out), 1);
  EXPECT_EQ(out, "refocusd: " + conf +
                     ":4: web: port 0 is not a port a browser can find; name one (e.g. 8080)\n");
}

}  // namespace
}  // namespace lb::test
