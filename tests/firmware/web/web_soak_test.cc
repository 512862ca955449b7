// Soak: the real refocusd with its web page on, many loopback clients for a few seconds (the
// gallery's requests, downloads, thumbnails, previews of taps, and refusals), and a shutter press
// in the middle.
// The photo is saved while the page is busy, and resident memory and open descriptors are back
// where they were once the clients stop.
#include <gtest/gtest.h>
#include <signal.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "tests/firmware/codecs/jpeg_test_util.h"
#include "tests/firmware/daemon/refocusd_process.h"
#include "tests/firmware/web/http_client.h"

namespace lb::test {
namespace {

constexpr char kToken[] = "soak-token-0123456789";

// Runs `clients` threads of mixed requests until `stop`; counts answers by class.
struct Load {
  std::atomic<bool> stop{false};
  std::atomic<int> ok{0}, refused{0}, unanswered{0}, previews{0};
  std::vector<std::thread> threads;

  void Start(int port, const std::string& photo, int clients) {
    stop = false;
    const std::string auth = std::string("Authorization: Bearer ") + kToken + "\r\n";
    for (int t = 0; t < clients; ++t) {
      threads.emplace_back([=, this] {
        const std::string targets[] = {"/api/photos",
                                       "/thumbs/" + photo,
                                       "/photos/" + photo,
                                       "/",
                                       "/photos/..%2f..%2fetc%2fpasswd.jpg",
                                       "/api/info/" + photo};
        const std::string form = auth + "Content-Type: application/x-www-form-urlencoded\r\n";
        for (int i = t; !stop.load(); ++i) {
          const std::string& target = targets[i % 6];
          HttpResponse r;
          if (i % 5 == 4) {
            // A tap somewhere: the renderer queues a few and answers the rest 503.
            char body[160];
            snprintf(body, sizeof(body), "name=%s&x0=0.%d&y0=0.%d&f=2", photo.c_str(), i % 10,
                     (i / 10) % 10);
            r = Http(port, "POST", "/api/preview", form, body, 10000);
            if (r.status == 200 && r.Header("Content-Type") == "image/jpeg") ++previews;
          } else {
            // Every seventh request comes without the token.
            r = Http(port, "GET", target, i % 7 == 0 ? "" : auth, "", 10000);
          }
          if (r.status == 200) {
            ++ok;
          } else if (r.status != 0) {
            ++refused;
          } else {
            ++unanswered;
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

TEST(WebSoakTest, ManyClientsAndAPressMemoryAndFilesStayFlat) {
  // Allocator noise and the thread stacks' cache; a per-request leak of even 100 bytes over
  // the thousands of requests shows above it.
  constexpr long kSlackKib = 1024;
  ScratchDir dir;
  const char* src = getenv("LB_SOURCE_DIR");
  RefocusdProcess d(dir.dir(), std::string("resolution = 128x96\nlabels = 8\n") +
                                   "web = 127.0.0.1:0\nweb_token = " + kToken +
                                   "\nweb_root = " + (src ? src : ".") + "/firmware/web/www\n");
  ASSERT_TRUE(d.Start());
  ASSERT_TRUE(d.WaitForLine("ready: sensor", 10000)) << d.log();
  ASSERT_TRUE(d.WaitForLine("web: listening on", 10000)) << d.log();
  const int port = PortFromLog(d.log());
  ASSERT_GT(port, 0) << d.log();
  d.Press();
  ASSERT_TRUE(d.WaitForLine("photo 1: saved", 30000)) << d.log();
  std::vector<std::string> photos, temps;
  ListPhotos(d.out_dir(), &photos, &temps);
  ASSERT_EQ(photos.size(), 1u);
  const std::string photo = photos[0];

  // Warm up at the same concurrency (thread stacks, allocator arenas), then measure.
  constexpr int kClients = 12;
  Load warm;
  warm.Start(port, photo, kClients);
  d.WaitForLine("no such line", 2000);  // reads the log meanwhile, so the pipe never fills
  warm.Join();
  d.WaitForLine("no such line", 1000);
  const long rss_before = d.ResidentKib();
  const int fds_before = d.OpenFds();

  Load load;
  load.Start(port, photo, kClients);
  d.WaitForLine("no such line", 2000);
  const auto pressed = std::chrono::steady_clock::now();
  d.Press();
  const bool saved = d.WaitForLine("photo 2: saved", 30000);
  const double press_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - pressed).count();
  d.WaitForLine("no such line", 2000);
  load.Join();
  ASSERT_TRUE(saved) << d.log().substr(d.log().size() > 3000 ? d.log().size() - 3000 : 0);
  d.WaitForLine("no such line", 1000);  // connections closed, threads gone
  const long rss_after = d.ResidentKib();
  const int fds_after = d.OpenFds();
  printf(
      "load: %d answered 200 (%d previews), %d refused (401/400/503), %d unanswered; press to "
      "saved %.2f s under load; before %ld KiB %d fds, after %ld KiB %d fds\n",
      load.ok.load(), load.previews.load(), load.refused.load(), load.unanswered.load(), press_s,
      rss_before, fds_before, rss_after, fds_after);
  EXPECT_GT(load.ok.load(), 100);
  EXPECT_GT(load.previews.load(), 5) << "the renderer answered the taps";
  EXPECT_GT(load.refused.load(), 20);
  EXPECT_LT(press_s, 10.0) << "a press is never held up by the page";
  ASSERT_GT(rss_before, 0);
  EXPECT_LE(rss_after, rss_before + kSlackKib);
  EXPECT_LE(fds_after, fds_before + 1);
  EXPECT_EQ(
      Http(port, "GET", "/api/photos", std::string("Authorization: Bearer ") + kToken + "\r\n")
          .status,
      200)
      << "still answering";
  d.Signal(SIGTERM);
  EXPECT_EQ(d.Wait(30000), 0);
  EXPECT_EQ(d.Count("web: stopped after"), 1);
  EXPECT_EQ(d.Count("stopped: 2 photo(s) saved, 0 failed"), 1);
}

}  // namespace
}  // namespace lb::test
