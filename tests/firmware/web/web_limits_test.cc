// What keeps the page usable for its owner when other clients misbehave or the camera works:
// slow clients from a few addresses cannot hold every connection, and a request that trickles
// in is cut at its deadline; thumbnails wait while the camera takes a photo.
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "firmware/codecs/jpeg_writer.h"
#include "firmware/web/web_server.h"
#include "tests/firmware/codecs/jpeg_test_util.h"
#include "tests/firmware/web/http_client.h"

namespace lb {
namespace {

using test::Http;
using test::HttpResponse;
using Clock = std::chrono::steady_clock;

constexpr char kToken[] = "test-token-0123456789";
const std::string kAuth = std::string("Authorization: Bearer ") + kToken + "\r\n";
constexpr char kPhoto[] = "IMG_1.jpg";

class Lines final : public LogSink {
 public:
  void Write(LogLevel, const char* text) override {
    std::lock_guard<std::mutex> lock(mutex_);
    all_ += std::string(text) + "\n";
  }
  std::string all() {
    std::lock_guard<std::mutex> lock(mutex_);
    return all_;
  }

 private:
  std::mutex mutex_;
  std::string all_;
};

// Renders nothing; says the camera is busy while `camera` is set.
class CameraBackend final : public RefocusBackend {
 public:
  Status Describe(const char*, PhotoInfo*) override { return Status(Code::kUnsupported, "none"); }
  Status Render(const char*, const RefocusParams&, bool, ByteSink*) override {
    return Status(Code::kUnsupported, "none");
  }
  Status Save(const char*, const RefocusParams&, const char*) override {
    return Status(Code::kUnsupported, "none");
  }
  bool CameraBusy() const override { return camera.load(); }
  std::atomic<bool> camera{false};
};

// True once the server has closed `fd` (end of stream or reset).
bool Closed(int fd) {
  pollfd p{fd, POLLIN, 0};
  if (poll(&p, 1, 0) <= 0) return false;
  char buf[256];
  return recv(fd, buf, sizeof(buf), MSG_DONTWAIT) <= 0;
}

class WebLimitsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::vector<uint8_t> jpeg;
    ASSERT_TRUE(EncodeYCbCr420(test::MakeTexture(1024, 768).View(), 85, &jpeg).ok());
    std::ofstream(photos_.Path(kPhoto), std::ios::binary)
        .write(reinterpret_cast<const char*>(jpeg.data()),
               static_cast<std::streamsize>(jpeg.size()));
    options_.token = kToken;
    options_.web_root = photos_.dir();
    options_.photo_dir = photos_.dir();
  }
  void Start() {
    server_ = std::make_unique<WebServer>(options_, &backend_, &log_);
    ASSERT_TRUE(server_->Start().ok());
    port_ = server_->port();
  }

  test::ScratchDir photos_;
  Lines lines_;
  Log log_{&lines_, LogLevel::kDebug};
  CameraBackend backend_;
  WebServerOptions options_;
  std::unique_ptr<WebServer> server_;
  int port_ = 0;
};

// Two addresses open all the connections they can and send one header line at a time, well
// inside the idle timeout: the owner's phone is still served, and the trickles are cut once the
// whole request's deadline passes.
TEST_F(WebLimitsTest, SlowClientsLeaveRoomAndAreCutAtTheDeadline) {
  options_.request_deadline_ms = 1000;  // the limits themselves as shipped
  Start();
  std::vector<int> slow;
  for (const char* source : {"127.0.0.2", "127.0.0.3"}) {
    for (int i = 0; i < options_.max_connections; ++i) {
      const int fd = test::ConnectLoopbackFrom(source, port_);
      ASSERT_GE(fd, 0) << source;
      const std::string line = "GET /api/photos HTTP/1.1\r\nHost: camera\r\n";
      send(fd, line.data(), line.size(), MSG_NOSIGNAL);
      slow.push_back(fd);
    }
  }
  const auto opened = Clock::now();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  std::vector<int> held;  // the ones the server took (the others it closed at once)
  for (int fd : slow) {
    if (Closed(fd)) {
      close(fd);
    } else {
      held.push_back(fd);
    }
  }
  EXPECT_GE(held.size(), 2u);
  EXPECT_LT(held.size(), static_cast<size_t>(options_.max_connections));
  const HttpResponse owner = Http(port_, "GET", "/api/photos", kAuth, "", 5000);
  EXPECT_EQ(owner.status, 200) << "the owner was locked out by " << held.size() << " slow ones";

  // Trickle on (a header line every 200 ms) for at most 3 s, noting when each is cut.
  std::vector<double> cut_s(held.size(), -1.0);
  for (int round = 0; round < 15; ++round) {
    for (size_t i = 0; i < held.size(); ++i) {
      if (cut_s[i] >= 0) continue;
      if (Closed(held[i])) {
        cut_s[i] = std::chrono::duration<double>(Clock::now() - opened).count();
        continue;
      }
      const std::string header = "X-Slow-" + std::to_string(round) + ": 1\r\n";
      send(held[i], header.data(), header.size(), MSG_NOSIGNAL);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  for (size_t i = 0; i < held.size(); ++i) {
    close(held[i]);
    EXPECT_GE(cut_s[i], 0.8) << "connection " << i << " cut before its deadline";
    EXPECT_GE(cut_s[i], 0.0) << "connection " << i << " still open after 3 s";
    EXPECT_LE(cut_s[i], 2.0) << "connection " << i;
  }
  EXPECT_NE(lines_.all().find("no whole request within"), std::string::npos) << lines_.all();
  EXPECT_EQ(Http(port_, "GET", "/api/photos", kAuth).status, 200) << "still answering";
}

// A request that arrives whole in time is not cut while its answer takes longer.
TEST_F(WebLimitsTest, TheDeadlineDoesNotCutAnAnswerInProgress) {
  options_.request_deadline_ms = 300;
  Start();
  backend_.camera = true;
  std::thread release([this] {
    std::this_thread::sleep_for(std::chrono::milliseconds(800));
    backend_.camera = false;
  });
  const HttpResponse r = Http(port_, "GET", std::string("/thumbs/") + kPhoto, kAuth);
  release.join();
  EXPECT_EQ(r.status, 200);
}

// Thumbnails wait while the camera takes a photo, and give up with 503 + Retry-After when it
// takes longer than they may wait.
TEST_F(WebLimitsTest, ThumbnailsWaitForTheCamera) {
  options_.camera_wait_ms = 400;
  Start();
  backend_.camera = true;
  auto t0 = Clock::now();
  HttpResponse r = Http(port_, "GET", std::string("/thumbs/") + kPhoto, kAuth);
  const double waited = std::chrono::duration<double>(Clock::now() - t0).count();
  EXPECT_EQ(r.status, 503);
  EXPECT_NE(r.Header("Retry-After"), "");
  EXPECT_GE(waited, 0.35);
  std::thread release([this] {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    backend_.camera = false;
  });
  t0 = Clock::now();
  r = Http(port_, "GET", std::string("/thumbs/") + kPhoto, kAuth);
  release.join();
  EXPECT_EQ(r.status, 200);
  EXPECT_GE(std::chrono::duration<double>(Clock::now() - t0).count(), 0.15);
}

}  // namespace
}  // namespace lb
