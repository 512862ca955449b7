// refocusd's web page server: the page's files and a small JSON API over the photo
// folder and the renderer (refocus_backend.h), for a phone or laptop on the same network.
//
// HTTP comes from GNU libmicrohttpd (Debian libmicrohttpd12, C, made for embedded devices): it
// parses requests (no HTTP parsing here), percent-decodes the path, bounds each connection's
// memory pool (headers and the body buffer), the number of connections, the connections per
// client address, and drops idle connections after a timeout; a request that has not arrived
// whole by its deadline is cut here (web_deadline.h). One thread per connection, all
// created from a thread started at a lower priority (nice), so every web thread runs below the
// camera's and a blocking render waits in its own connection only.
//
// Routes (every answer and refusal is logged once: client, method, path without the query,
// status and why):
//   GET  /, /index.html, /app.js, /style.css   the page's files from web_root (no token: they
//                                              hold no data); nothing else there is reachable
//   POST /api/login      body token=TOKEN (form)  204 + cookie refocusd=SESSION (HttpOnly,
//                                              SameSite=Strict), a wrong token 401
// The rest need the cookie or `Authorization: Bearer TOKEN` (compared in constant time), else
// 401:
//   GET  /api/photos     {"photos":[{"name":"IMG_....jpg","mtime":SECONDS,"size":BYTES},...]}
//                        newest first (modification time, then name)
//   GET  /photos/NAME    the file (image/jpeg); ?download=1 adds Content-Disposition attachment
//   GET  /thumbs/NAME    a JPEG about 320 px wide from the photo's main image (thumbnail.h)
//   GET  /api/info/NAME  {"width":W,"height":H,"refocusable":B,"current":{"x0":..,"y0":..,
//                        "x1":..,"y1":..,"f":..,"blades":N}}
//   POST /api/preview, /api/render   form body (application/x-www-form-urlencoded, decoded by
//                                    libmicrohttpd; any other body is 400) name, x0, y0, x1, y1
//                        (0..1 of the displayed photo; x1, y1 default to x0, y0: a tap), f
//                        (f-number 1..22), blades (0 disc, 3..12) -> image/jpeg
//   POST /api/save       the same body -> {"name":"IMG_..._r1.jpg"}, a new photo beside the
//                        original (_r1, _r2, ...: the first absent), never over a file
// NAME is one path component checked by photo_folder.h and opened without following links.
// Errors are JSON {"error":"..."} naming photos, never a folder's path (the log has the paths):
// 400 bad name or body (a field sent empty included), 401, 404, 405 with Allow, 409 every
// re-render name taken, 413 body over 16 KiB, 422 a photo that cannot be refocused, 503 +
// Retry-After when the renderer is busy or a thumbnail waited too long for the camera.
#pragma once

#include <sys/stat.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

#include "algo/core/status.h"
#include "firmware/platform/log.h"
#include "firmware/web/refocus_backend.h"

struct MHD_Daemon;
struct MHD_Connection;
struct MHD_Response;

namespace lb {

class RequestDeadlines;

struct WebServerOptions {
  std::string address = "127.0.0.1";  // numeric IPv4 or IPv6
  int32_t port = 0;                   // 0: any free port (see WebServer::port)
  std::string token;                  // required, at least 16 characters
  std::string web_root;               // index.html, app.js, style.css
  std::string photo_dir;
  // A browser opens up to 6 connections to a host; a few addresses cannot take every slot.
  int32_t max_connections = 24;
  int32_t max_per_client = 6;
  size_t connection_memory = 32 * 1024;  // per connection: request line, headers, body buffer
  int32_t timeout_s = 15;                // an idle connection is closed
  // A whole request (headers and body) must arrive within this of the connection opening or of
  // its previous answer, however steadily it trickles in.
  int32_t request_deadline_ms = 10000;
  size_t max_body = 16 * 1024;  // larger request bodies: 413
  int32_t nice = 10;            // of every web thread (the camera's stay at 0)
  size_t max_listed = 5000;     // newest photos listed
  int32_t thumb_width = 320;
  // A thumbnail waits at most this long for the camera to finish a photo, then gets 503.
  int32_t camera_wait_ms = 30000;
  int32_t failed_login_delay_ms = 500;  // slows guessing down
};

class WebServer {
 public:
  // `backend` and `log` are borrowed and must outlive the server.
  WebServer(const WebServerOptions& options, RefocusBackend* backend, Log* log);
  ~WebServer();  // Stop
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  // Binds and starts serving; kIoError naming the address when it cannot bind.
  Status Start();
  // Closes the listening socket and every connection; waits for handlers in progress.
  void Stop();
  // The bound port (the chosen one when the options asked for 0), once started.
  int32_t port() const { return port_; }

  // libmicrohttpd's callbacks (web_server.cc) enter here; false closes the connection.
  struct Request;
  bool Handle(MHD_Connection* c, const char* url, const char* method, const char* upload,
              size_t* upload_size, Request** request);
  void LogLibraryMessage(const char* text);
  RequestDeadlines* deadlines() { return deadlines_.get(); }

  class Sinks;  // the render outputs, reused (web_server.cc)

 private:
  bool Route(MHD_Connection* c, const char* url, const char* method, Request* r);
  // `allow`: the Allow header of a 405.
  bool Reply(MHD_Connection* c, Request* r, int status, const char* type, const void* data,
             size_t size, const char* why, const char* allow = nullptr);
  // Queues `response` (and frees it) with `status`, marks the request answered and logs it.
  bool Send(MHD_Connection* c, Request* r, MHD_Response* response, int status, const char* why);
  // `why` is the client's; the log gets `log_why` when given (the same with paths).
  bool ReplyError(MHD_Connection* c, Request* r, int status, const char* why,
                  const char* log_why = nullptr, const char* allow = nullptr);
  bool ReplyStatus(MHD_Connection* c, Request* r, const Status& s);
  bool NotAllowed(MHD_Connection* c, Request* r, const char* allow);
  // `text` as a client may see it: the photo folder's path and any other absolute path cut down
  // to the last name in it.
  std::string PublicText(const char* text) const;
  // Returns once the camera takes no photo; kBusy when `deadline` (steady clock, ms) passes first.
  Status WaitForCamera(int64_t deadline_ms) const;
  bool Authorized(MHD_Connection* c) const;
  bool ServePage(MHD_Connection* c, Request* r, const char* file, const char* type);
  bool Login(MHD_Connection* c, Request* r);
  bool ListPhotos(MHD_Connection* c, Request* r);
  // Opens `name` in the photo folder as OpenPhoto does (checked, no link followed).
  Status OpenNamedPhoto(const char* name, int* fd, struct stat* st) const;
  bool ServePhoto(MHD_Connection* c, Request* r, const char* name, bool thumbnail);
  bool Info(MHD_Connection* c, Request* r, const char* name);
  bool Refocus(MHD_Connection* c, Request* r, const char* action);
  void LogRequest(MHD_Connection* c, const Request* r, int status, const char* why);

  WebServerOptions options_;
  RefocusBackend* backend_;
  Log* log_;
  std::string session_;  // the cookie's value: 64 hex digits from getrandom at Start
  MHD_Daemon* mhd_ = nullptr;
  int listen_fd_ = -1;
  int32_t port_ = 0;
  std::unique_ptr<Sinks> sinks_;
  std::unique_ptr<RequestDeadlines> deadlines_;
  std::mutex save_mutex_;  // one save at a time chooses its name and writes it (web path only)
  std::atomic<int64_t> requests_{0};
};

}  // namespace lb
