// The web side as refocusd runs it: off unless configured, refused at load without a token, and
// a port it cannot bind costs the page, never the camera.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "tests/firmware/codecs/jpeg_test_util.h"
#include "tests/firmware/daemon/refocusd_process.h"
#include "tests/firmware/web/http_client.h"

namespace lb::test {
namespace {

constexpr char kToken[] = "process-token-0123456789";

std::string WebRoot() {
  const char* src = getenv("LB_SOURCE_DIR");
  return std::string(src ? src : ".") + "/firmware/web/www";
}

TEST(WebProcessTest, WebWithoutATokenStopsAtTheConfiguration) {
  ScratchDir dir;
  RefocusdProcess d(dir.dir(), "web = 127.0.0.1:0\n");
  ASSERT_TRUE(d.Start());
  EXPECT_EQ(d.Wait(10000), 1);
  EXPECT_NE(d.log().find("web is on but web_token is not set"), std::string::npos) << d.log();
}

TEST(WebProcessTest, OffByDefault) {
  ScratchDir dir;
  RefocusdProcess d(dir.dir(), "");
  ASSERT_TRUE(d.Start());
  ASSERT_TRUE(d.WaitForLine("ready: sensor", 10000)) << d.log();
  EXPECT_EQ(d.Count("web:"), 0) << d.log();
  d.Signal(SIGTERM);
  EXPECT_EQ(d.Wait(10000), 0);
}

TEST(WebProcessTest, APortInUseCostsThePageNotTheCamera) {
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

  ScratchDir dir;
  RefocusdProcess d(dir.dir(), "web = 127.0.0.1:" + std::to_string(port) +
                                   "\nweb_token = " + kToken + "\nweb_root = " + WebRoot() + "\n");
  ASSERT_TRUE(d.Start());
  ASSERT_TRUE(d.WaitForLine("the camera runs without the web page", 10000)) << d.log();
  EXPECT_EQ(d.Count("web: cannot listen on 127.0.0.1:" + std::to_string(port)), 1) << d.log();
  d.Press();
  EXPECT_TRUE(d.WaitForLine("photo 1: saved", 30000)) << d.log();
  d.Signal(SIGTERM);
  EXPECT_EQ(d.Wait(10000), 0);
  close(holder);
}

TEST(WebProcessTest, ThePageAndAPhotoThroughTheRealDaemon) {
  ScratchDir dir;
  RefocusdProcess d(dir.dir(), std::string("web = 127.0.0.1:0\nweb_token = ") + kToken +
                                   "\nweb_root = " + WebRoot() + "\n");
  ASSERT_TRUE(d.Start());
  ASSERT_TRUE(d.WaitForLine("web: listening on 127.0.0.1:", 10000)) << d.log();
  const std::string key = "web: listening on 127.0.0.1:";
  const int port = atoi(d.log().c_str() + d.log().find(key) + key.size());
  d.Press();
  ASSERT_TRUE(d.WaitForLine("photo 1: saved", 30000)) << d.log();
  std::vector<std::string> photos, temps;
  ListPhotos(d.out_dir(), &photos, &temps);
  ASSERT_EQ(photos.size(), 1u);
  const std::string auth = std::string("Authorization: Bearer ") + kToken + "\r\n";
  HttpResponse page = Http(port, "GET", "/");
  EXPECT_EQ(page.status, 200);
  EXPECT_NE(page.body.find("<html"), std::string::npos);
  HttpResponse list = Http(port, "GET", "/api/photos", auth);
  EXPECT_EQ(list.status, 200);
  EXPECT_NE(list.body.find("\"name\":\"" + photos[0] + "\""), std::string::npos) << list.body;
  HttpResponse photo = Http(port, "GET", "/photos/" + photos[0], auth);
  EXPECT_EQ(photo.status, 200);
  EXPECT_EQ(photo.body.size(), ReadFile(d.out_dir() + "/" + photos[0]).size());
  EXPECT_EQ(Http(port, "GET", "/api/photos").status, 401);
  d.WaitForLine("no such line", 500);
  EXPECT_EQ(d.Count("web: 127.0.0.1 GET /api/photos 401"), 1) << d.log();
  d.Signal(SIGTERM);
  EXPECT_EQ(d.Wait(10000), 0);
  EXPECT_EQ(d.Count("web: stopped after 4 request(s)"), 1) << d.log();
}

}  // namespace
}  // namespace lb::test
