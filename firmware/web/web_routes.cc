// The server's answers, one member a route (web_server.h lists them): the page's files, login,
// the photo list, a photo or its thumbnail, its info, and the renders and saves.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "firmware/web/photo_folder.h"
#include "firmware/web/thumbnail.h"
#include "firmware/web/web_request.h"
#include "firmware/web/web_server.h"

namespace lb {
namespace {

constexpr int kCameraPollMs = 10;

int64_t NowMs() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// libmicrohttpd frees a render's response: its sink goes back for the next render.
void ReleaseSink(void* cls) {
  auto* sink = static_cast<WebServer::Sinks::Sink*>(cls);
  sink->owner->Release(sink);
}

}  // namespace

using web::AppendJsonString;
using web::CommonHeaders;
using web::SameSecret;

bool WebServer::ServePage(MHD_Connection* c, Request* r, const char* file, const char* type) {
  const std::string path = options_.web_root + "/" + file;
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  struct stat st;
  if (fd < 0 || fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    if (fd >= 0) close(fd);
    char why[160];
    snprintf(why, sizeof(why), "the page file %s is missing (web_root)", file);
    return ReplyError(c, r, MHD_HTTP_NOT_FOUND, why);
  }
  MHD_Response* response = MHD_create_response_from_fd(static_cast<size_t>(st.st_size), fd);
  if (response == nullptr) {
    close(fd);
    return false;
  }
  CommonHeaders(response);
  MHD_add_response_header(response, MHD_HTTP_HEADER_CONTENT_TYPE, type);
  MHD_add_response_header(response, MHD_HTTP_HEADER_CACHE_CONTROL, "no-cache");
  // The page loads only its own files and the photos; no inline script, nothing from outside.
  MHD_add_response_header(response, MHD_HTTP_HEADER_CONTENT_SECURITY_POLICY,
                          "default-src 'self'; img-src 'self' blob: data:; "
                          "frame-ancestors 'none'; base-uri 'none'; form-action 'self'");
  return Send(c, r, response, MHD_HTTP_OK, nullptr);
}

bool WebServer::Login(MHD_Connection* c, Request* r) {
  const char* token = r->fields.Get("token");
  if (token == nullptr || !SameSecret(token, options_.token)) {
    // Each wrong guess costs its connection a moment (and the per-client limit caps those).
    std::this_thread::sleep_for(std::chrono::milliseconds(options_.failed_login_delay_ms));
    return ReplyError(c, r, MHD_HTTP_UNAUTHORIZED, "wrong token");
  }
  MHD_Response* response = MHD_create_response_from_buffer(0, nullptr, MHD_RESPMEM_PERSISTENT);
  if (response == nullptr) return false;
  CommonHeaders(response);
  const std::string cookie = "refocusd=" + session_ + "; HttpOnly; SameSite=Strict; Path=/";
  MHD_add_response_header(response, MHD_HTTP_HEADER_SET_COOKIE, cookie.c_str());
  MHD_add_response_header(response, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
  return Send(c, r, response, MHD_HTTP_NO_CONTENT, "logged in");
}

bool WebServer::ListPhotos(MHD_Connection* c, Request* r) {
  int dir_fd = -1;
  Status s = OpenPhotoFolder(options_.photo_dir.c_str(), &dir_fd);
  std::vector<PhotoEntry> photos;
  if (s.ok()) {
    s = ListPhotoFolder(dir_fd, options_.max_listed, &photos);
    close(dir_fd);
  }
  if (!s.ok()) return ReplyStatus(c, r, s);
  std::string json = "{\"photos\":[";
  for (size_t i = 0; i < photos.size(); ++i) {
    if (i > 0) json += ",";
    json += "{\"name\":";
    AppendJsonString(&json, photos[i].name.c_str());
    char numbers[80];
    snprintf(numbers, sizeof(numbers), ",\"mtime\":%lld,\"size\":%lld}",
             static_cast<long long>(photos[i].mtime_ns / 1000000000),
             static_cast<long long>(photos[i].size));
    json += numbers;
  }
  json += "]}";
  return Reply(c, r, MHD_HTTP_OK, "application/json", json.data(), json.size(), nullptr);
}

Status WebServer::OpenNamedPhoto(const char* name, int* fd, struct stat* st) const {
  int dir_fd = -1;
  Status s = OpenPhotoFolder(options_.photo_dir.c_str(), &dir_fd);
  if (!s.ok()) return s;
  s = OpenPhoto(dir_fd, name, fd, st);
  close(dir_fd);
  return s;
}

Status WebServer::WaitForCamera(int64_t deadline_ms) const {
  while (backend_->CameraBusy()) {
    if (NowMs() >= deadline_ms) {
      return Status(Code::kBusy, "the camera is taking a photo; try again in a moment");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(kCameraPollMs));
  }
  return Status::Ok();
}

bool WebServer::ServePhoto(MHD_Connection* c, Request* r, const char* name, bool thumbnail) {
  // The camera comes first: a thumbnail (a 12 MP decode, even at 1/8 scale) waits while it takes
  // a photo, before it starts and between strips. The download of a photo is the kernel copying
  // a file, and goes on.
  const int64_t deadline = NowMs() + options_.camera_wait_ms;
  Status s = thumbnail ? WaitForCamera(deadline) : Status::Ok();
  if (!s.ok()) return ReplyStatus(c, r, s);
  int fd = -1;
  struct stat st;
  s = OpenNamedPhoto(name, &fd, &st);
  if (!s.ok()) return ReplyStatus(c, r, s);
  if (thumbnail) {
    std::vector<uint8_t> jpeg;
    s = MakeThumbnail(fd, options_.thumb_width, 80, &jpeg,
                      [this, deadline] { return WaitForCamera(deadline); });
    close(fd);
    if (!s.ok()) return ReplyStatus(c, r, s.Prefix("%s: ", name));
    return Reply(c, r, MHD_HTTP_OK, "image/jpeg", jpeg.data(), jpeg.size(), nullptr);
  }
  MHD_Response* response = MHD_create_response_from_fd(static_cast<size_t>(st.st_size), fd);
  if (response == nullptr) {
    close(fd);
    return false;
  }
  CommonHeaders(response);
  MHD_add_response_header(response, MHD_HTTP_HEADER_CONTENT_TYPE, "image/jpeg");
  MHD_add_response_header(response, MHD_HTTP_HEADER_CACHE_CONTROL, "private, no-cache");
  const char* download = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "download");
  if (download != nullptr && strcmp(download, "1") == 0) {
    // The name passed IsServablePhotoName: no quote, slash or control character to escape.
    const std::string disposition = std::string("attachment; filename=\"") + name + "\"";
    MHD_add_response_header(response, MHD_HTTP_HEADER_CONTENT_DISPOSITION, disposition.c_str());
  }
  return Send(c, r, response, MHD_HTTP_OK, nullptr);
}

bool WebServer::Info(MHD_Connection* c, Request* r, const char* name) {
  int fd = -1;
  struct stat st;
  Status s = OpenNamedPhoto(name, &fd, &st);
  if (!s.ok()) return ReplyStatus(c, r, s);
  close(fd);
  const std::string path = options_.photo_dir + "/" + name;
  PhotoInfo info;
  s = backend_->Describe(path.c_str(), &info);
  if (!s.ok()) return ReplyStatus(c, r, s);
  char json[400];
  const RefocusParams& p = info.current;
  snprintf(json, sizeof(json),
           "{\"width\":%d,\"height\":%d,\"refocusable\":%s,\"current\":{\"x0\":%.4f,\"y0\":%.4f,"
           "\"x1\":%.4f,\"y1\":%.4f,\"f\":%.2f,\"blades\":%d},\"depthGuess\":%s}",
           info.width, info.height, info.refocusable ? "true" : "false", p.x0, p.y0, p.x1, p.y1,
           p.f_number, p.aperture.blades, info.depth_guess ? "true" : "false");
  return Reply(c, r, MHD_HTTP_OK, "application/json", json, strlen(json), nullptr);
}

bool WebServer::Refocus(MHD_Connection* c, Request* r, const char* action) {
  std::string name;
  RefocusParams params;
  Status s = ParseRefocus(r->fields, &name, &params);
  int dir_fd = -1;
  if (s.ok()) s = OpenPhotoFolder(options_.photo_dir.c_str(), &dir_fd);
  if (s.ok()) {
    int fd = -1;
    struct stat st;
    s = OpenPhoto(dir_fd, name.c_str(), &fd, &st);
    if (fd >= 0) close(fd);
  }
  if (!s.ok()) {
    if (dir_fd >= 0) close(dir_fd);
    return ReplyStatus(c, r, s);
  }
  const std::string path = options_.photo_dir + "/" + name;
  if (strcmp(action, "save") == 0) {
    char out[kMaxPhotoName + 1];
    {
      // Two saves at once must not pick the same name.
      std::lock_guard<std::mutex> lock(save_mutex_);
      s = ChooseRerenderName(dir_fd, name.c_str(), out, sizeof(out));
      if (s.code() == Code::kBusy) {
        // Every name taken: no retry helps (not 503), only removing some re-renders.
        close(dir_fd);
        char why[Status::kMaxMessage + 64];
        snprintf(why, sizeof(why), "%s; delete or rename some to save another", s.message());
        return ReplyError(c, r, MHD_HTTP_CONFLICT, why);
      }
      if (s.ok()) {
        const std::string out_path = options_.photo_dir + "/" + out;
        s = backend_->Save(path.c_str(), params, out_path.c_str());
      }
    }
    close(dir_fd);
    if (!s.ok()) return ReplyStatus(c, r, s);
    std::string body = "{\"name\":";
    AppendJsonString(&body, out);
    body += "}";
    char why[200];
    snprintf(why, sizeof(why), "saved %s", out);
    return Reply(c, r, MHD_HTTP_OK, "application/json", body.data(), body.size(), why);
  }
  close(dir_fd);
  Sinks::Sink* sink = sinks_->Acquire();
  if (sink == nullptr) {
    return ReplyError(c, r, MHD_HTTP_SERVICE_UNAVAILABLE, "renders in progress; try again");
  }
  s = backend_->Render(path.c_str(), params, strcmp(action, "preview") == 0, sink);
  if (!s.ok()) {
    sinks_->Release(sink);
    return ReplyStatus(c, r, s);
  }
  MHD_Response* response = MHD_create_response_from_buffer_with_free_callback_cls(
      sink->bytes.size(), sink->bytes.data(), &ReleaseSink, sink);
  if (response == nullptr) {
    sinks_->Release(sink);
    return false;
  }
  CommonHeaders(response);
  MHD_add_response_header(response, MHD_HTTP_HEADER_CONTENT_TYPE, "image/jpeg");
  MHD_add_response_header(response, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
  return Send(c, r, response, MHD_HTTP_OK, nullptr);
}

}  // namespace lb
