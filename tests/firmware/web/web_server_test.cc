// The web server through a real socket: the routes against a fake renderer, and the refusals a
// device on someone's network needs (tokens, traversal, links, sizes, connection counts), with
// the server still answering afterwards.
#include "firmware/web/web_server.h"

#include <dirent.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "firmware/codecs/jpeg_writer.h"
#include "firmware/storage/atomic_file.h"
#include "tests/firmware/codecs/jpeg_test_util.h"
#include "tests/firmware/web/http_client.h"

namespace lb {
namespace {

using test::Http;
using test::HttpResponse;

constexpr char kToken[] = "test-token-0123456789";
const std::string kAuth = std::string("Authorization: Bearer ") + kToken + "\r\n";

class CaptureSink : public LogSink {
 public:
  void Write(LogLevel, const char* text) override {
    std::lock_guard<std::mutex> lock(mutex_);
    lines_.push_back(text);
  }
  int Count(const std::string& part) {
    std::lock_guard<std::mutex> lock(mutex_);
    int n = 0;
    for (const std::string& l : lines_) n += l.find(part) != std::string::npos ? 1 : 0;
    return n;
  }
  std::string All() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::string all;
    for (const std::string& l : lines_) all += l + "\n";
    return all;
  }

 private:
  std::mutex mutex_;
  std::vector<std::string> lines_;
};

class FakeBackend : public RefocusBackend {
 public:
  Status Describe(const char* path, PhotoInfo* info) override {
    last_path = path;
    if (strstr(path, "flat") != nullptr) return Status(Code::kUnsupported, "no depth in it");
    info->width = 1280;
    info->height = 960;
    info->refocusable = true;
    info->current.x0 = info->current.x1 = 0.25f;
    info->current.y0 = info->current.y1 = 0.75f;
    info->current.f_number = 4.0f;
    info->current.aperture.blades = 6;
    info->depth_guess = strstr(path, "wall") != nullptr;
    return Status::Ok();
  }
  Status Render(const char* path, const RefocusParams& p, bool preview, ByteSink* out) override {
    if (busy) return Status(Code::kBusy, "the camera is taking a photo");
    last_path = path;
    last = p;
    last_preview = preview;
    const std::string bytes = preview ? "preview-jpeg" : "full-jpeg";
    out->Append(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
    return Status::Ok();
  }
  Status Save(const char* path, const RefocusParams& p, const char* out_path) override {
    last = p;
    struct stat st;
    if (lstat(out_path, &st) == 0) return Status(Code::kInternal, "asked to overwrite");
    const std::vector<uint8_t> bytes = test::ReadFile(path);
    AtomicFile out;
    Status s = out.Open(out_path);
    if (s.ok()) s = out.Write(bytes.data(), bytes.size());
    if (s.ok()) s = out.Commit();
    return s;
  }
  bool busy = false;
  std::string last_path;
  RefocusParams last;
  bool last_preview = false;
};

void WriteFile(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

void SetMtime(const std::string& path, time_t seconds) {
  timespec t[2] = {{seconds, 0}, {seconds, 0}};
  ASSERT_EQ(utimensat(AT_FDCWD, path.c_str(), t, 0), 0);
}

std::vector<uint8_t> Jpeg(int32_t w, int32_t h) {
  std::vector<uint8_t> jpeg;
  EXPECT_TRUE(EncodeYCbCr420(test::MakeTexture(w, h).View(), 85, &jpeg).ok());
  return jpeg;
}

class WebServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    WriteFile(www_.Path("index.html"), "<!doctype html><title>t</title>");
    WriteFile(www_.Path("app.js"), "// app");
    WriteFile(www_.Path("style.css"), "body{}");
    WriteFile(www_.Path("secret.txt"), "not served");
    const std::vector<uint8_t> jpeg = Jpeg(1280, 960);
    photo_ = std::string(jpeg.begin(), jpeg.end());
    WriteFile(photos_.Path(kPhoto), photo_);
    WriteFile(outside_.Path("outside.jpg"), "OUTSIDE-SECRET");
    options_.token = kToken;
    options_.web_root = www_.dir();
    options_.photo_dir = photos_.dir();
    options_.failed_login_delay_ms = 10;
  }
  void Start() {
    server_ = std::make_unique<WebServer>(options_, &backend_, &log_);
    Status s = server_->Start();
    ASSERT_TRUE(s.ok()) << s.message();
    port_ = server_->port();
  }
  HttpResponse Get(const std::string& target, const std::string& headers = kAuth) {
    return Http(port_, "GET", target, headers);
  }
  HttpResponse Post(const std::string& target, const std::string& body,
                    const std::string& headers = kAuth) {
    return Http(port_, "POST", target,
                headers + "Content-Type: application/x-www-form-urlencoded\r\n", body);
  }

  static constexpr char kPhoto[] = "IMG_20260101_120000_0001.jpg";
  test::ScratchDir www_, photos_, outside_;
  std::string photo_;
  CaptureSink sink_;
  Log log_{&sink_, LogLevel::kDebug};
  FakeBackend backend_;
  WebServerOptions options_;
  std::unique_ptr<WebServer> server_;
  int port_ = 0;
};

TEST_F(WebServerTest, PageFilesNeedNoTokenAndNothingElseOfTheFolderIsServed) {
  Start();
  HttpResponse r = Get("/", "");
  EXPECT_EQ(r.status, 200);
  EXPECT_EQ(r.body, "<!doctype html><title>t</title>");
  EXPECT_EQ(r.Header("Content-Type"), "text/html; charset=utf-8");
  EXPECT_NE(r.Header("Content-Security-Policy").find("default-src 'self'"), std::string::npos);
  EXPECT_EQ(Get("/app.js", "").body, "// app");
  EXPECT_EQ(Get("/style.css", "").Header("Content-Type"), "text/css; charset=utf-8");
  EXPECT_EQ(Get("/secret.txt", "").status, 401);
  EXPECT_EQ(Get("/secret.txt").status, 404);
  EXPECT_EQ(Get("/index.html/../secret.txt").status, 404);
  EXPECT_EQ(Post("/", "").status, 405);
}

TEST_F(WebServerTest, LoginGivesASessionCookieAndWrongTokensAreRefused) {
  Start();
  HttpResponse bad = Post("/api/login", "token=wrong-token-0123456789", "");
  EXPECT_EQ(bad.status, 401);
  EXPECT_EQ(bad.Header("Set-Cookie"), "");
  EXPECT_EQ(Post("/api/login", "", "").status, 401);
  HttpResponse good = Post("/api/login", std::string("token=") + kToken, "");
  ASSERT_EQ(good.status, 204) << good.body;
  const std::string cookie = good.Header("Set-Cookie");
  EXPECT_NE(cookie.find("HttpOnly"), std::string::npos) << cookie;
  EXPECT_NE(cookie.find("SameSite=Strict"), std::string::npos) << cookie;
  const std::string value = cookie.substr(0, cookie.find(';'));  // refocusd=...
  EXPECT_EQ(value.size(), strlen("refocusd=") + 64);
  EXPECT_EQ(value.find(kToken), std::string::npos) << "the cookie is not the token";
  EXPECT_EQ(Get("/api/photos", "Cookie: " + value + "\r\n").status, 200);
  EXPECT_EQ(Get("/api/photos", "Cookie: refocusd=0000\r\n").status, 401);
  std::string wrong = value;
  wrong.back() = wrong.back() == '0' ? '1' : '0';
  EXPECT_EQ(Get("/api/photos", "Cookie: " + wrong + "\r\n").status, 401);
  EXPECT_EQ(sink_.Count("POST /api/login 401: wrong token"), 2) << sink_.All();
}

TEST_F(WebServerTest, EveryDataRouteNeedsTheToken) {
  Start();
  const std::string name = kPhoto;
  for (const std::string& target : std::vector<std::string>{
           "/api/photos", "/photos/" + name, "/thumbs/" + name, "/api/info/" + name, "/nothing"}) {
    EXPECT_EQ(Get(target, "").status, 401) << target;
    EXPECT_EQ(Get(target, "Authorization: Bearer test-token-012345678\r\n").status, 401) << target;
    EXPECT_EQ(Get(target, "Authorization: Bearer test-token-01234567890\r\n").status, 401)
        << target;
    EXPECT_EQ(Get(target, "Authorization: Basic dGVzdA==\r\n").status, 401) << target;
  }
  for (const char* action : {"/api/preview", "/api/render", "/api/save"}) {
    EXPECT_EQ(Post(action, "name=" + name + "&x0=0.5&y0=0.5", "").status, 401) << action;
  }
  EXPECT_EQ(test::ReadFile(photos_.Path(kPhoto)).size(), photo_.size());
  EXPECT_EQ(photos_.Entries().size(), 1u) << "nothing was saved";
}

TEST_F(WebServerTest, ListingIsNewestFirstAndOnlyRegularPhotoFiles) {
  WriteFile(photos_.Path("a.jpg"), "a");
  WriteFile(photos_.Path("b.jpg"), "bb");
  WriteFile(photos_.Path("c.JPEG"), "ccc");
  WriteFile(photos_.Path("d.jpg"), "dddd");
  WriteFile(photos_.Path("notes.txt"), "x");
  WriteFile(photos_.Path(".IMG_20260101_120000_0002.jpg.Ab12Cd"), "temporary");
  ASSERT_EQ(mkdir(photos_.Path("folder.jpg").c_str(), 0755), 0);
  ASSERT_EQ(symlink(outside_.Path("outside.jpg").c_str(), photos_.Path("link.jpg").c_str()), 0);
  SetMtime(photos_.Path(kPhoto), 500);
  SetMtime(photos_.Path("a.jpg"), 1000);
  SetMtime(photos_.Path("b.jpg"), 3000);
  SetMtime(photos_.Path("c.JPEG"), 2000);
  SetMtime(photos_.Path("d.jpg"), 3000);
  Start();
  HttpResponse r = Get("/api/photos");
  ASSERT_EQ(r.status, 200);
  EXPECT_EQ(r.Header("Content-Type"), "application/json");
  EXPECT_EQ(r.body,
            "{\"photos\":[{\"name\":\"d.jpg\",\"mtime\":3000,\"size\":4},"
            "{\"name\":\"b.jpg\",\"mtime\":3000,\"size\":2},"
            "{\"name\":\"c.JPEG\",\"mtime\":2000,\"size\":3},"
            "{\"name\":\"a.jpg\",\"mtime\":1000,\"size\":1},"
            "{\"name\":\"IMG_20260101_120000_0001.jpg\",\"mtime\":500,\"size\":" +
                std::to_string(photo_.size()) + "}]}");
}

TEST_F(WebServerTest, PhotoDownloadAndThumbnail) {
  Start();
  HttpResponse r = Get(std::string("/photos/") + kPhoto);
  ASSERT_EQ(r.status, 200);
  EXPECT_EQ(r.body, photo_);
  EXPECT_EQ(r.Header("Content-Type"), "image/jpeg");
  EXPECT_EQ(r.Header("Content-Disposition"), "");
  r = Get(std::string("/photos/") + kPhoto + "?download=1");
  EXPECT_EQ(r.body, photo_);
  EXPECT_EQ(r.Header("Content-Disposition"),
            std::string("attachment; filename=\"") + kPhoto + "\"");
  r = Get(std::string("/thumbs/") + kPhoto);
  ASSERT_EQ(r.status, 200);
  const std::vector<uint8_t> thumb(r.body.begin(), r.body.end());
  int32_t w = 0, h = 0;
  std::vector<uint8_t> ycc;
  std::string error;
  ASSERT_TRUE(test::DecodeYcc(thumb, &w, &h, &ycc, &error)) << error;
  EXPECT_EQ(w, 320);
  EXPECT_EQ(h, 240);
  EXPECT_LT(r.body.size(), photo_.size() / 4);
  EXPECT_EQ(Get("/photos/none.jpg").status, 404);
  WriteFile(photos_.Path("broken.jpg"), "not a jpeg");
  EXPECT_EQ(Get("/thumbs/broken.jpg").status, 422);
}

TEST_F(WebServerTest, InfoPreviewRenderAndSaveReachTheRenderer) {
  WriteFile(photos_.Path("flat.jpg"), "x");
  Start();
  HttpResponse r = Get(std::string("/api/info/") + kPhoto);
  ASSERT_EQ(r.status, 200) << r.body;
  EXPECT_EQ(r.body,
            "{\"width\":1280,\"height\":960,\"refocusable\":true,\"current\":{\"x0\":0.2500,"
            "\"y0\":0.7500,\"x1\":0.2500,\"y1\":0.7500,\"f\":4.00,\"blades\":6},"
            "\"depthGuess\":false}");
  EXPECT_EQ(backend_.last_path, photos_.Path(kPhoto));
  WriteFile(photos_.Path("wall.jpg"), photo_);
  r = Get("/api/info/wall.jpg");
  ASSERT_EQ(r.status, 200) << r.body;
  EXPECT_NE(r.body.find("\"depthGuess\":true"), std::string::npos) << r.body;
  r = Get("/api/info/flat.jpg");
  EXPECT_EQ(r.status, 422);
  EXPECT_EQ(r.body, "{\"error\":\"no depth in it\"}");

  r = Post("/api/preview", std::string("name=") + kPhoto + "&x0=0.1&y0=0.2&f=1.8&blades=5");
  ASSERT_EQ(r.status, 200) << r.body;
  EXPECT_EQ(r.body, "preview-jpeg");
  EXPECT_EQ(r.Header("Content-Type"), "image/jpeg");
  EXPECT_TRUE(backend_.last_preview);
  EXPECT_FLOAT_EQ(backend_.last.x0, 0.1f);
  EXPECT_FLOAT_EQ(backend_.last.x1, 0.1f) << "a tap is a zero-size rectangle";
  EXPECT_FLOAT_EQ(backend_.last.y1, 0.2f);
  EXPECT_FLOAT_EQ(backend_.last.f_number, 1.8f);
  EXPECT_EQ(backend_.last.aperture.blades, 5);

  // Only form bodies, parsed by the library: JSON is refused, not guessed at.
  r = Http(port_, "POST", "/api/render", kAuth + "Content-Type: application/json\r\n",
           std::string("{\"name\": \"") + kPhoto + "\", \"x0\": 0.6, \"y0\": 0.5}");
  EXPECT_EQ(r.status, 400) << r.body;
  // A value split by percent-escapes and '+' still arrives whole.
  r = Post("/api/render", std::string("name=") + kPhoto + "&x0=0%2e6&y0=0.5&x1=0.2&y1=0.9&f=8");
  ASSERT_EQ(r.status, 200) << r.body;
  EXPECT_EQ(r.body, "full-jpeg");
  EXPECT_FALSE(backend_.last_preview);
  EXPECT_FLOAT_EQ(backend_.last.x0, 0.2f);
  EXPECT_FLOAT_EQ(backend_.last.x1, 0.6f);
  EXPECT_FLOAT_EQ(backend_.last.y1, 0.9f);
  EXPECT_EQ(backend_.last.aperture.blades, 0);
  // The page takes the f-numbers the settings take, f/1 .. f/22.
  for (const char* f : {"1", "22"}) {
    r = Post("/api/preview", std::string("name=") + kPhoto + "&x0=0.5&y0=0.5&f=" + f);
    EXPECT_EQ(r.status, 200) << f << ": " << r.body;
    EXPECT_FLOAT_EQ(backend_.last.f_number, std::stof(f));
  }

  for (const char* body : {"x0=0.5&y0=0.5", "name=a.jpg", "name=a.jpg&x0=2&y0=0.5",
                           "name=a.jpg&x0=0.5&y0=0.5&f=0.5", "name=a.jpg&x0=0.5&y0=0.5&f=22.5",
                           "name=a.jpg&x0=0.5&y0=0.5&blades=2", "name=a.jpg&x0=nan&y0=0.5"}) {
    EXPECT_EQ(Post("/api/preview", body).status, 400) << body;
  }
  EXPECT_EQ(Http(port_, "POST", "/api/render", kAuth + "Content-Type: application/json\r\n",
                 "{\"name\": {\"x\": 1}}")
                .status,
            400);

  backend_.busy = true;
  r = Post("/api/preview", std::string("name=") + kPhoto + "&x0=0.5&y0=0.5");
  EXPECT_EQ(r.status, 503);
  EXPECT_EQ(r.Header("Retry-After"), "1");
  backend_.busy = false;

  const std::string save = std::string("name=") + kPhoto + "&x0=0.3&y0=0.3&f=2";
  r = Post("/api/save", save);
  ASSERT_EQ(r.status, 200) << r.body;
  EXPECT_EQ(r.body, "{\"name\":\"IMG_20260101_120000_0001_r1.jpg\"}");
  r = Post("/api/save", save);
  EXPECT_EQ(r.body, "{\"name\":\"IMG_20260101_120000_0001_r2.jpg\"}");
  r = Post("/api/save", "name=IMG_20260101_120000_0001_r1.jpg&x0=0.3&y0=0.3");
  EXPECT_EQ(r.body, "{\"name\":\"IMG_20260101_120000_0001_r3.jpg\"}");
  EXPECT_EQ(test::ReadFile(photos_.Path(kPhoto)).size(), photo_.size()) << "original untouched";
  EXPECT_EQ(test::ReadFile(photos_.Path("IMG_20260101_120000_0001_r3.jpg")).size(), photo_.size());
  EXPECT_EQ(sink_.Count("POST /api/save 200: saved IMG_20260101_120000_0001_r2.jpg"), 1);
}

// Absent, an optional field takes its default; present but empty, it is a mistake like any
// other bad value.
TEST_F(WebServerTest, EmptyFieldsAre400) {
  Start();
  const std::string tap = std::string("name=") + kPhoto + "&x0=0.5&y0=0.5";
  EXPECT_EQ(Post("/api/preview", tap).status, 200);
  for (const char* empty : {"&f=", "&blades=", "&x1=", "&y1=", "&f", "&x1=&y1=0.5"}) {
    HttpResponse r = Post("/api/preview", tap + empty);
    EXPECT_EQ(r.status, 400) << empty << ": " << r.body;
    EXPECT_NE(r.body.find("empty"), std::string::npos) << empty << ": " << r.body;
  }
  EXPECT_EQ(Post("/api/preview", std::string("name=") + kPhoto + "&x0=&y0=0.5").status, 400);
}

// A method a path does not take is 405 with the ones it does.
TEST_F(WebServerTest, MethodNotAllowedSaysWhichAre) {
  Start();
  const struct {
    const char *method, *target, *allow;
  } kCases[] = {
      {"POST", "/", "GET, HEAD"},
      {"DELETE", "/app.js", "GET, HEAD"},
      {"GET", "/api/login", "POST"},
      {"PUT", "/api/photos", "GET, HEAD"},
      {"POST", "/thumbs/a.jpg", "GET, HEAD"},
      {"GET", "/api/save", "POST"},
      {"DELETE", "/api/info/a.jpg", "GET, HEAD"},
  };
  for (const auto& c : kCases) {
    HttpResponse r = Http(port_, c.method, c.target, kAuth);
    EXPECT_EQ(r.status, 405) << c.method << " " << c.target;
    EXPECT_EQ(r.Header("Allow"), c.allow) << c.method << " " << c.target;
  }
}

// Every re-render name taken: no retry can help, so not 503 but 409 saying what to do.
TEST_F(WebServerTest, NoFreeRerenderNameIs409) {
  for (int k = 1; k <= 99; ++k) {
    WriteFile(photos_.Path("IMG_20260101_120000_0001_r" + std::to_string(k) + ".jpg"), "x");
  }
  Start();
  HttpResponse r = Post("/api/save", std::string("name=") + kPhoto + "&x0=0.3&y0=0.3");
  EXPECT_EQ(r.status, 409) << r.body;
  EXPECT_EQ(r.Header("Retry-After"), "");
  EXPECT_NE(r.body.find("_r99"), std::string::npos) << r.body;
}

TEST_F(WebServerTest, TraversalAbsolutePathsAndLinksAreRefused) {
  ASSERT_EQ(symlink(outside_.Path("outside.jpg").c_str(), photos_.Path("link.jpg").c_str()), 0);
  Start();
  const std::string out_abs = outside_.Path("outside.jpg");
  for (const std::string& target : std::vector<std::string>{
           std::string("/photos/../outside.jpg"), std::string("/photos/..%2foutside.jpg"),
           std::string("/photos/%2e%2e%2foutside.jpg"), std::string("/photos/%2E%2E/outside.jpg"),
           std::string("/photos/%2f") + out_abs.substr(1), "/photos/" + out_abs,
           "/thumbs/%2e%2e%2f%2e%2e%2f" + out_abs, "/api/info/..%2F..%2Fetc%2Fpasswd",
           std::string("/photos/link.jpg"), std::string("/thumbs/link.jpg"),
           std::string("/photos/.hidden.jpg"), std::string("/photos/a%00.jpg")}) {
    HttpResponse r = Get(target);
    EXPECT_EQ(r.status, 400) << target << " " << r.body;
    EXPECT_EQ(r.body.find("OUTSIDE-SECRET"), std::string::npos) << target;
  }
  for (const std::string& name :
       std::vector<std::string>{"../outside.jpg", out_abs, "link.jpg", "%2e%2e%2foutside.jpg"}) {
    EXPECT_EQ(Post("/api/preview", "name=" + name + "&x0=0.5&y0=0.5").status, 400) << name;
    EXPECT_EQ(Post("/api/save", "name=" + name + "&x0=0.5&y0=0.5").status, 400) << name;
  }
  EXPECT_EQ(backend_.last_path, "") << "the renderer never saw a bad name";
  EXPECT_EQ(Get("/api/photos").body.find("link.jpg"), std::string::npos);
  // Each refusal is logged once, with the path as decoded (four spellings of ../outside.jpg).
  EXPECT_EQ(sink_.Count("GET /photos/../outside.jpg 400"), 4) << sink_.All();
  EXPECT_EQ(Get(std::string("/photos/") + kPhoto).status, 200) << "still answering";
}

TEST_F(WebServerTest, OversizedBodiesAre413) {
  Start();
  const std::string big(20 * 1024, 'a');
  HttpResponse r = Post("/api/preview", "name=" + big);
  EXPECT_EQ(r.status, 413);
  r = Post("/api/login", "token=" + big, "");
  EXPECT_EQ(r.status, 413);
  // Without a length up front (chunked): refused once the body passes the limit.
  std::string chunked;
  for (int i = 0; i < 5; ++i) chunked += "1000\r\n" + std::string(4096, 'b') + "\r\n";
  chunked += "0\r\n\r\n";
  r = test::SendRaw(port_,
                    "POST /api/render HTTP/1.1\r\nHost: x\r\nConnection: close\r\n" + kAuth +
                        "Transfer-Encoding: chunked\r\n\r\n" + chunked,
                    10000);
  EXPECT_EQ(r.status, 413);
  EXPECT_EQ(sink_.Count("POST /api/render 413"), 1) << sink_.All();
  EXPECT_EQ(Get("/api/photos").status, 200) << "still answering";
}

TEST_F(WebServerTest, ConnectionsOverTheLimitAreRefusedAndTheServerRecovers) {
  options_.max_connections = 4;
  options_.max_per_client = 4;
  Start();
  std::vector<int> held;
  for (int i = 0; i < 4; ++i) {
    const int fd = test::ConnectLoopback(port_);
    ASSERT_GE(fd, 0);
    held.push_back(fd);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // all accepted
  HttpResponse over = Get("/api/photos");
  EXPECT_EQ(over.status, 0) << "the fifth connection is closed unanswered";
  EXPECT_GE(sink_.Count("libmicrohttpd"), 1) << sink_.All();
  for (int fd : held) close(fd);
  HttpResponse after;
  for (int i = 0; i < 50 && after.status != 200; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    after = Get("/api/photos");
  }
  EXPECT_EQ(after.status, 200);
}

// The camera comes first: every thread the server made runs at the web's lower priority.
TEST_F(WebServerTest, WebThreadsRunBelowTheCamera) {
  auto threads = [] {
    std::set<std::string> ids;
    DIR* d = opendir("/proc/self/task");
    while (dirent* e = readdir(d)) {
      if (e->d_name[0] != '.') ids.insert(e->d_name);
    }
    closedir(d);
    return ids;
  };
  const std::set<std::string> before = threads();
  Start();
  const int fd = test::ConnectLoopback(port_);  // a connection thread too
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  int web_threads = 0;
  for (const std::string& id : threads()) {
    if (before.count(id) != 0) continue;
    std::ifstream stat("/proc/self/task/" + id + "/stat");
    std::string text((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
    // Field 19 (nice) counts from after the ")" that ends the name.
    std::string rest = text.substr(text.rfind(')') + 2);
    std::vector<std::string> fields;
    for (size_t p = 0; p < rest.size();) {
      size_t q = rest.find(' ', p);
      if (q == std::string::npos) q = rest.size();
      fields.push_back(rest.substr(p, q - p));
      p = q + 1;
    }
    ASSERT_GT(fields.size(), 16u);
    EXPECT_EQ(fields[16], "10") << "thread " << id;  // field 19 is the 17th after the name
    ++web_threads;
  }
  close(fd);
  EXPECT_GE(web_threads, 2);
  EXPECT_EQ(Get("/api/photos").status, 200);
}

int OpenFds() {
  int n = 0;
  DIR* d = opendir("/proc/self/fd");
  while (dirent* e = readdir(d)) n += e->d_name[0] != '.' ? 1 : 0;
  closedir(d);
  return n;
}

TEST_F(WebServerTest, StopReleasesEveryDescriptorAndEveryThread) {
  const int fds = OpenFds();
  Start();
  EXPECT_EQ(Get(std::string("/photos/") + kPhoto).status, 200);
  EXPECT_EQ(Get(std::string("/thumbs/") + kPhoto).status, 200);
  server_->Stop();
  EXPECT_EQ(OpenFds(), fds);
  EXPECT_EQ(sink_.Count("web: stopped after 2 request(s)"), 1) << sink_.All();
  Start();  // again, on a fresh port
  EXPECT_EQ(Get("/api/photos").status, 200);
  server_.reset();
  EXPECT_EQ(OpenFds(), fds);
}

TEST_F(WebServerTest, ABusyPortIsAClearError) {
  Start();
  WebServerOptions same = options_;
  same.port = port_;
  WebServer second(same, &backend_, &log_);
  Status s = second.Start();
  EXPECT_EQ(s.code(), Code::kIoError);
  EXPECT_NE(std::string(s.message()).find("cannot listen on 127.0.0.1:" + std::to_string(port_)),
            std::string::npos)
      << s.message();
  WebServerOptions no_token = options_;
  no_token.token = "short";
  EXPECT_EQ(WebServer(no_token, &backend_, &log_).Start().code(), Code::kInvalidArgument);
}

}  // namespace
}  // namespace lb
