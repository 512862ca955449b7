// Soak: the camera comes first. The real refocusd takes photos while idle and while 16 clients
// (from four loopback addresses, inside the per-address limit) fetch thumbnails of a 12 MP
// photo without pause; a press under that load must take about as long as an idle one, both
// measured in this run (the machine's speed and other load cancel out of the ratio). refocusd
// runs on one CPU, so the page's work and the camera's contend as on a board with every core
// busy, whatever this machine has.
#include <gtest/gtest.h>
#include <sched.h>
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "firmware/codecs/jpeg_writer.h"
#include "tests/firmware/codecs/jpeg_test_util.h"
#include "tests/firmware/daemon/refocusd_process.h"
#include "tests/firmware/web/http_client.h"

namespace lb::test {
namespace {

constexpr char kToken[] = "soak-token-0123456789";
constexpr double kMaxRatio = 1.3;

struct ThumbnailLoad {
  std::atomic<bool> stop{false};
  std::atomic<int> ok{0}, busy{0}, other{0};
  std::vector<std::thread> threads;

  void Start(int port, int clients) {
    stop = false;
    const std::string auth = std::string("Authorization: Bearer ") + kToken + "\r\n";
    for (int t = 0; t < clients; ++t) {
      threads.emplace_back([=, this] {
        const std::string source = "127.0.0." + std::to_string(1 + t % 4);
        while (!stop.load()) {
          const int fd = ConnectLoopbackFrom(source.c_str(), port);
          const HttpResponse r =
              fd < 0 ? HttpResponse() : HttpOn(fd, "GET", "/thumbs/big.jpg", auth, "", 60000);
          if (r.status == 200) {
            ++ok;
          } else if (r.status == 503) {
            ++busy;
          } else {
            ++other;
            std::this_thread::sleep_for(std::chrono::milliseconds(50));  // no refusal storm
          }
        }
      });
    }
  }
  void Join() {
    stop = true;
    for (std::thread& t : threads) t.join();
    threads.clear();
  }
};

int PortFromLog(const std::string& log) {
  const std::string key = "web: listening on 127.0.0.1:";
  const size_t at = log.find(key);
  return at == std::string::npos ? 0 : atoi(log.c_str() + at + key.size());
}

// Seconds from the press to its photo's "saved" line; < 0 when it never came.
double Press(RefocusdProcess& d, int photo) {
  const auto t0 = std::chrono::steady_clock::now();
  d.Press();
  if (!d.WaitForLine("photo " + std::to_string(photo) + ": saved", 120000)) return -1.0;
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

TEST(WebCameraFirstSoakTest, APressUnderThumbnailLoadTakesAboutAsLongAsAnIdleOne) {
  ScratchDir dir;
  const char* src = getenv("LB_SOURCE_DIR");
  RefocusdProcess d(dir.dir(), std::string("resolution = 2028x1520\nlabels = 64\nframes = 8\n") +
                                   "threads = 1\nweb = 127.0.0.1:0\nweb_token = " + kToken +
                                   "\nweb_root = " + (src ? src : ".") + "/firmware/web/www\n");
  {
    std::vector<uint8_t> big;
    ASSERT_TRUE(EncodeYCbCr420(MakeTexture(4056, 3040).View(), 90, &big).ok());
    std::ofstream(d.out_dir() + "/big.jpg", std::ios::binary)
        .write(reinterpret_cast<const char*>(big.data()), static_cast<std::streamsize>(big.size()));
  }
  // The child inherits the starting thread's CPUs; the clients, made after, do not.
  cpu_set_t all, one;
  ASSERT_EQ(sched_getaffinity(0, sizeof(all), &all), 0);
  CPU_ZERO(&one);
  for (int cpu = CPU_SETSIZE - 1; cpu >= 0; --cpu) {
    if (CPU_ISSET(cpu, &all)) {
      CPU_SET(cpu, &one);
      break;
    }
  }
  ASSERT_EQ(sched_setaffinity(0, sizeof(one), &one), 0);
  const bool started = d.Start();
  ASSERT_EQ(sched_setaffinity(0, sizeof(all), &all), 0);
  ASSERT_TRUE(started);
  ASSERT_TRUE(d.WaitForLine("ready: sensor", 10000)) << d.log();
  ASSERT_TRUE(d.WaitForLine("web: listening on", 10000)) << d.log();
  const int port = PortFromLog(d.log());
  ASSERT_GT(port, 0) << d.log();
  ASSERT_GT(Press(d, 1), 0.0) << d.log();  // warm: buffers, caches

  // Idle and loaded presses in turn, so a change in the machine's other load falls on both.
  constexpr int kRounds = 3, kClients = 16;
  std::vector<double> idle, loaded;
  ThumbnailLoad load;
  int photo = 2;
  for (int round = 0; round < kRounds; ++round) {
    d.WaitForLine("no such line", 500);
    idle.push_back(Press(d, photo++));
    load.Start(port, kClients);
    d.WaitForLine("no such line", 1500);  // the thumbnails under way
    loaded.push_back(Press(d, photo++));
    d.WaitForLine("no such line", 500);
    load.Join();
    ASSERT_GT(idle.back(), 0.0) << d.log().substr(d.log().size() > 3000 ? d.log().size() - 3000
                                                                        : 0);
    ASSERT_GT(loaded.back(), 0.0) << d.log().substr(d.log().size() > 3000 ? d.log().size() - 3000
                                                                          : 0);
  }
  std::sort(idle.begin(), idle.end());
  std::sort(loaded.begin(), loaded.end());
  const double ratio = loaded[kRounds / 2] / idle[kRounds / 2];
  printf(
      "press to saved, idle: %.2f %.2f %.2f s; under thumbnail load: %.2f %.2f %.2f s; "
      "median ratio %.2f; thumbnails %d served, %d 503, %d other\n",
      idle[0], idle[1], idle[2], loaded[0], loaded[1], loaded[2], ratio, load.ok.load(),
      load.busy.load(), load.other.load());
  EXPECT_GT(load.ok.load(), kClients) << "thumbnails were served between the photos";
  EXPECT_LT(ratio, kMaxRatio) << "the page's thumbnails slowed the camera";
  d.Signal(SIGTERM);
  EXPECT_EQ(d.Wait(30000), 0);
}

}  // namespace
}  // namespace lb::test
