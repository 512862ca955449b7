#include "firmware/web/web_server.h"

#include <arpa/inet.h>
#include <microhttpd.h>
#include <netinet/in.h>
#include <strings.h>
#include <sys/random.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <thread>

#include "firmware/storage/errno_text.h"
#include "firmware/web/web_deadline.h"
#include "firmware/web/web_request.h"

namespace lb {
namespace {

struct ErrText {
  explicit ErrText(int err) { ErrnoText(err, text, sizeof(text)); }
  char text[96];
};

MHD_Result OnRequest(void* cls, MHD_Connection* c, const char* url, const char* method,
                     const char* /*version*/, const char* upload, size_t* upload_size,
                     void** request) {
  auto* self = static_cast<WebServer*>(cls);
  return self->Handle(c, url, method, upload, upload_size,
                      reinterpret_cast<WebServer::Request**>(request))
             ? MHD_YES
             : MHD_NO;
}

RequestDeadlines::Entry* DeadlineOf(MHD_Connection* c) {
  const MHD_ConnectionInfo* info = MHD_get_connection_info(c, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
  return info != nullptr ? static_cast<RequestDeadlines::Entry*>(info->socket_context) : nullptr;
}

void ClientText(MHD_Connection* c, char* out, size_t size) {
  snprintf(out, size, "?");
  const MHD_ConnectionInfo* info = MHD_get_connection_info(c, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
  if (info == nullptr || info->client_addr == nullptr) return;
  const sockaddr* sa = info->client_addr;
  if (sa->sa_family == AF_INET) {
    inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in*>(sa)->sin_addr, out,
              static_cast<socklen_t>(size));
  } else if (sa->sa_family == AF_INET6) {
    inet_ntop(AF_INET6, &reinterpret_cast<const sockaddr_in6*>(sa)->sin6_addr, out,
              static_cast<socklen_t>(size));
  }
}

void OnCompleted(void* cls, MHD_Connection* c, void** request, MHD_RequestTerminationCode /*why*/) {
  delete static_cast<WebServer::Request*>(*request);
  *request = nullptr;
  static_cast<WebServer*>(cls)->deadlines()->Answered(DeadlineOf(c));
}

void OnConnection(void* cls, MHD_Connection* c, void** socket_context,
                  MHD_ConnectionNotificationCode code) {
  RequestDeadlines* deadlines = static_cast<WebServer*>(cls)->deadlines();
  if (code == MHD_CONNECTION_NOTIFY_STARTED) {
    const MHD_ConnectionInfo* info = MHD_get_connection_info(c, MHD_CONNECTION_INFO_CONNECTION_FD);
    if (info == nullptr) return;
    char client[INET6_ADDRSTRLEN];
    ClientText(c, client, sizeof(client));
    *socket_context = deadlines->Opened(info->connect_fd, client);
  } else {
    deadlines->Closed(static_cast<RequestDeadlines::Entry*>(*socket_context));
    *socket_context = nullptr;
  }
}

void OnLibraryMessage(void* cls, const char* format, va_list args) {
  char text[Log::kMaxLine];
  vsnprintf(text, sizeof(text), format, args);
  static_cast<WebServer*>(cls)->LogLibraryMessage(text);
}

// A request path as the log shows it: printable ASCII, at most 160 characters (a decoded
// "%0a" cannot start a fake log line).
void LoggablePath(const char* url, char* out, size_t size) {
  size_t i = 0;
  for (; url[i] != '\0' && i + 1 < size && i < 160; ++i) {
    const unsigned char ch = static_cast<unsigned char>(url[i]);
    out[i] = ch >= 0x20 && ch < 0x7f ? static_cast<char>(ch) : '?';
  }
  out[i] = '\0';
}

MHD_Result OnFormField(void* cls, MHD_ValueKind /*kind*/, const char* key, const char* /*filename*/,
                       const char* /*type*/, const char* /*encoding*/, const char* data,
                       uint64_t offset, size_t size) {
  return static_cast<Fields*>(cls)->Add(key, data, offset, size) ? MHD_YES : MHD_NO;
}

int HttpStatusFor(Code code) {
  switch (code) {
    case Code::kInvalidArgument:
      return MHD_HTTP_BAD_REQUEST;
    case Code::kNotFound:
      return MHD_HTTP_NOT_FOUND;
    case Code::kUnsupported:
    case Code::kCorruptData:
    case Code::kDegenerate:
      return MHD_HTTP_UNPROCESSABLE_CONTENT;
    case Code::kBusy:
    case Code::kTimeout:
      return MHD_HTTP_SERVICE_UNAVAILABLE;
    default:
      return MHD_HTTP_INTERNAL_SERVER_ERROR;
  }
}

bool StartsWith(const char* s, const char* prefix, const char** rest) {
  const size_t n = strlen(prefix);
  if (strncmp(s, prefix, n) != 0) return false;
  *rest = s + n;
  return true;
}

int ThreadId() { return static_cast<int>(gettid()); }

}  // namespace

namespace web {

void CommonHeaders(MHD_Response* response) {
  MHD_add_response_header(response, "X-Content-Type-Options", "nosniff");
  MHD_add_response_header(response, "X-Frame-Options", "DENY");
  MHD_add_response_header(response, "Referrer-Policy", "no-referrer");
}

void AppendJsonString(std::string* out, const char* s) {
  out->push_back('"');
  for (; *s != '\0'; ++s) {
    const unsigned char ch = static_cast<unsigned char>(*s);
    if (ch == '"' || ch == '\\') {
      out->push_back('\\');
      out->push_back(static_cast<char>(ch));
    } else if (ch < 0x20 || ch == 0x7f) {
      char esc[8];
      snprintf(esc, sizeof(esc), "\\u%04x", ch);
      out->append(esc);
    } else {
      out->push_back(static_cast<char>(ch));
    }
  }
  out->push_back('"');
}

bool SameSecret(const char* given, const std::string& secret) {
  const size_t n = strnlen(given, 1024);
  unsigned diff = n != secret.size() ? 1u : 0u;
  for (size_t i = 0; i < secret.size(); ++i) {
    const unsigned char g = i < n ? static_cast<unsigned char>(given[i]) : 0;
    diff |= g ^ static_cast<unsigned char>(secret[i]);
  }
  return diff == 0;
}

}  // namespace web

using web::AppendJsonString;
using web::CommonHeaders;
using web::SameSecret;

WebServer::WebServer(const WebServerOptions& options, RefocusBackend* backend, Log* log)
    : options_(options), backend_(backend), log_(log) {}

WebServer::~WebServer() { Stop(); }

Status WebServer::Start() {
  if (mhd_ != nullptr) return Status(Code::kBusy, "web: already started");
  if (options_.token.size() < 16) {
    return Status(Code::kInvalidArgument, "web: the token must have at least 16 characters");
  }
  uint8_t random[32];
  size_t got = 0;
  while (got < sizeof(random)) {
    const ssize_t n = getrandom(random + got, sizeof(random) - got, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return Status(Code::kIoError, "web: getrandom: %s", ErrText(errno).text);
    got += static_cast<size_t>(n);
  }
  session_.clear();
  for (uint8_t b : random) {
    static const char kHex[] = "0123456789abcdef";
    session_.push_back(kHex[b >> 4]);
    session_.push_back(kHex[b & 15]);
  }

  // The listening socket is made here so the address can be either family and port 0 can be
  // read back.
  sockaddr_storage addr{};
  socklen_t addr_len = 0;
  const bool v6 = options_.address.find(':') != std::string::npos;
  if (v6) {
    auto* a = reinterpret_cast<sockaddr_in6*>(&addr);
    a->sin6_family = AF_INET6;
    a->sin6_port = htons(static_cast<uint16_t>(options_.port));
    if (inet_pton(AF_INET6, options_.address.c_str(), &a->sin6_addr) != 1) addr_len = 1;
    addr_len = addr_len == 1 ? 0 : sizeof(*a);
  } else {
    auto* a = reinterpret_cast<sockaddr_in*>(&addr);
    a->sin_family = AF_INET;
    a->sin_port = htons(static_cast<uint16_t>(options_.port));
    addr_len = inet_pton(AF_INET, options_.address.c_str(), &a->sin_addr) == 1 ? sizeof(*a) : 0;
  }
  if (addr_len == 0) {
    return Status(Code::kInvalidArgument, "web: '%s' is not a numeric address",
                  options_.address.c_str());
  }
  const int fd = socket(addr.ss_family, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return Status(Code::kIoError, "web: socket: %s", ErrText(errno).text);
  const int one = 1, zero = 0;
  setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  if (v6) setsockopt(fd, IPPROTO_IPV6, IPV6_V6ONLY, &zero, sizeof(zero));
  if (bind(fd, reinterpret_cast<sockaddr*>(&addr), addr_len) != 0 ||
      listen(fd, options_.max_connections) != 0) {
    const int err = errno;
    close(fd);
    return Status(Code::kIoError, "web: cannot listen on %s%s%s:%d: %s", v6 ? "[" : "",
                  options_.address.c_str(), v6 ? "]" : "", options_.port, ErrText(err).text);
  }
  sockaddr_storage bound{};
  socklen_t bound_len = sizeof(bound);
  getsockname(fd, reinterpret_cast<sockaddr*>(&bound), &bound_len);
  port_ = ntohs(v6 ? reinterpret_cast<sockaddr_in6*>(&bound)->sin6_port
                   : reinterpret_cast<sockaddr_in*>(&bound)->sin_port);
  listen_fd_ = fd;
  sinks_ = std::make_unique<Sinks>();
  deadlines_ =
      std::make_unique<RequestDeadlines>(options_.request_deadline_ms, [this](const char* client) {
        log_->Printf(LogLevel::kWarning, "web: %s no whole request within %.1f s; closed", client,
                     options_.request_deadline_ms / 1000.0);
      });

  // Threads start with their creator's nice value: libmicrohttpd's listening thread is created
  // from one at the web's priority, and it creates every connection's thread.
  int nice_err = 0;
  std::thread starter([&] {
    if (setpriority(PRIO_PROCESS, static_cast<id_t>(ThreadId()), options_.nice) != 0) {
      nice_err = errno;
    }
    deadlines_->Start();
    const unsigned flags = MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_THREAD_PER_CONNECTION |
                           MHD_USE_POLL | MHD_USE_ERROR_LOG;
    mhd_ = MHD_start_daemon(
        flags, 0, nullptr, nullptr, &OnRequest, this, MHD_OPTION_EXTERNAL_LOGGER, &OnLibraryMessage,
        this, MHD_OPTION_LISTEN_SOCKET, static_cast<MHD_socket>(listen_fd_),
        MHD_OPTION_CONNECTION_LIMIT, static_cast<unsigned>(options_.max_connections),
        MHD_OPTION_PER_IP_CONNECTION_LIMIT, static_cast<unsigned>(options_.max_per_client),
        MHD_OPTION_CONNECTION_MEMORY_LIMIT, options_.connection_memory,
        MHD_OPTION_CONNECTION_TIMEOUT, static_cast<unsigned>(options_.timeout_s),
        MHD_OPTION_THREAD_STACK_SIZE, static_cast<size_t>(1u << 20), MHD_OPTION_NOTIFY_COMPLETED,
        &OnCompleted, this, MHD_OPTION_NOTIFY_CONNECTION, &OnConnection, this, MHD_OPTION_END);
  });
  starter.join();
  if (mhd_ == nullptr) {
    // Not closed here: whether libmicrohttpd already closed the socket it was given depends on
    // where it failed (a thread or memory it could not get), and closing a number another
    // thread may have reused since would be worse than one descriptor left open.
    listen_fd_ = -1;
    deadlines_.reset();
    return Status(Code::kIoError, "web: libmicrohttpd did not start");
  }
  if (nice_err != 0) {
    log_->Printf(LogLevel::kWarning, "web: cannot lower the web threads' priority: %s",
                 ErrText(nice_err).text);
  }
  log_->Printf(LogLevel::kInfo,
               "web: listening on %s%s%s:%d (page files from %s; at most %d connections, %d per "
               "client, a whole request within %.1f s)",
               v6 ? "[" : "", options_.address.c_str(), v6 ? "]" : "", port_,
               options_.web_root.c_str(), options_.max_connections, options_.max_per_client,
               options_.request_deadline_ms / 1000.0);
  return Status::Ok();
}

void WebServer::Stop() {
  if (mhd_ == nullptr) return;
  // Joins every thread, frees every response (the sinks come back) and closes the listening
  // socket it was given.
  MHD_stop_daemon(mhd_);
  mhd_ = nullptr;
  listen_fd_ = -1;
  deadlines_.reset();  // every connection has closed
  log_->Printf(LogLevel::kInfo, "web: stopped after %lld request(s)",
               static_cast<long long>(requests_.load()));
}

void WebServer::LogLibraryMessage(const char* text) {
  char line[Log::kMaxLine];
  LoggablePath(text, line, sizeof(line));
  size_t n = strlen(line);
  while (n > 0 && (line[n - 1] == '?' || line[n - 1] == ' ')) line[--n] = '\0';  // the newline
  log_->Printf(LogLevel::kWarning, "web: refused or failed (libmicrohttpd): %s", line);
}

bool WebServer::Handle(MHD_Connection* c, const char* url, const char* method, const char* upload,
                       size_t* upload_size, Request** request) {
  if (*request == nullptr) {
    Request* r = new (std::nothrow) Request;
    if (r == nullptr) return false;
    *request = r;
    requests_.fetch_add(1);
    LoggablePath(method, r->method, sizeof(r->method));
    LoggablePath(url, r->path, sizeof(r->path));
    const char* length =
        MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_LENGTH);
    if (length != nullptr && strtoull(length, nullptr, 10) > options_.max_body) {
      return ReplyError(c, r, MHD_HTTP_CONTENT_TOO_LARGE, "request body over the limit");
    }
    if (strcmp(method, "POST") == 0) {
      // Only form bodies, decoded by the library's own parser (NULL for any other type).
      const char* type =
          MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_TYPE);
      if (type != nullptr && strncasecmp(type, MHD_HTTP_POST_ENCODING_FORM_URLENCODED,
                                         strlen(MHD_HTTP_POST_ENCODING_FORM_URLENCODED)) == 0) {
        r->post = MHD_create_post_processor(c, 1024, &OnFormField, &r->fields);
      }
      return true;  // the body comes in the next calls
    }
  }
  Request* r = *request;
  if (r->replied) {
    *upload_size = 0;
    return true;
  }
  if (*upload_size != 0) {
    if (r->too_large || *upload_size > options_.max_body - r->body_bytes) {
      r->too_large = true;
    } else {
      r->body_bytes += *upload_size;
      r->body.append(upload, *upload_size);
      if (r->post == nullptr || MHD_post_process(r->post, upload, *upload_size) != MHD_YES) {
        r->bad_body = true;
      }
    }
    *upload_size = 0;
    return true;
  }
  deadlines_->Whole(DeadlineOf(c));
  // The library's form parser passes over a field sent without a value; it is still a field.
  if (r->post != nullptr && !r->bad_body && !r->fields.AddEmpty(r->body.data(), r->body.size())) {
    r->bad_body = true;
  }
  if (r->too_large) {
    return ReplyError(c, r, MHD_HTTP_CONTENT_TOO_LARGE, "request body over the limit");
  }
  if (r->bad_body) {
    return ReplyError(c, r, MHD_HTTP_BAD_REQUEST,
                      "the body is not a form (application/x-www-form-urlencoded)");
  }
  return Route(c, url, method, r);
}

bool WebServer::Route(MHD_Connection* c, const char* url, const char* method, Request* r) {
  const bool get = strcmp(method, "GET") == 0 || strcmp(method, "HEAD") == 0;
  const bool post = strcmp(method, "POST") == 0;
  static const struct {
    const char *url, *file, *type;
  } kPage[] = {
      {"/", "index.html", "text/html; charset=utf-8"},
      {"/index.html", "index.html", "text/html; charset=utf-8"},
      {"/app.js", "app.js", "text/javascript; charset=utf-8"},
      {"/style.css", "style.css", "text/css; charset=utf-8"},
  };
  for (const auto& page : kPage) {
    if (strcmp(url, page.url) == 0) {
      if (!get) return NotAllowed(c, r, "GET, HEAD");
      return ServePage(c, r, page.file, page.type);
    }
  }
  if (strcmp(url, "/api/login") == 0) {
    if (!post) return NotAllowed(c, r, "POST");
    return Login(c, r);
  }
  if (!Authorized(c)) {
    return ReplyError(c, r, MHD_HTTP_UNAUTHORIZED, "no valid session cookie or token");
  }
  const char* rest = nullptr;
  if (strcmp(url, "/api/photos") == 0) {
    if (!get) return NotAllowed(c, r, "GET, HEAD");
    return ListPhotos(c, r);
  }
  if (StartsWith(url, "/photos/", &rest) || StartsWith(url, "/thumbs/", &rest)) {
    if (!get) return NotAllowed(c, r, "GET, HEAD");
    return ServePhoto(c, r, rest, url[1] == 't');
  }
  if (StartsWith(url, "/api/info/", &rest)) {
    if (!get) return NotAllowed(c, r, "GET, HEAD");
    return Info(c, r, rest);
  }
  if (StartsWith(url, "/api/", &rest) &&
      (strcmp(rest, "preview") == 0 || strcmp(rest, "render") == 0 || strcmp(rest, "save") == 0)) {
    if (!post) return NotAllowed(c, r, "POST");
    return Refocus(c, r, rest);
  }
  return ReplyError(c, r, MHD_HTTP_NOT_FOUND, "no such page");
}

bool WebServer::Authorized(MHD_Connection* c) const {
  const char* cookie = MHD_lookup_connection_value(c, MHD_COOKIE_KIND, "refocusd");
  if (cookie != nullptr && SameSecret(cookie, session_)) return true;
  const char* auth = MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_AUTHORIZATION);
  if (auth == nullptr || strncasecmp(auth, "Bearer ", 7) != 0) return false;
  const char* token = auth + 7;
  while (*token == ' ') ++token;
  return SameSecret(token, options_.token);
}

void WebServer::LogRequest(MHD_Connection* c, const Request* r, int status, const char* why) {
  char client[INET6_ADDRSTRLEN];
  ClientText(c, client, sizeof(client));
  LogLevel level = LogLevel::kInfo;
  if (status >= 500 && status != MHD_HTTP_SERVICE_UNAVAILABLE) {
    level = LogLevel::kError;
  } else if (status >= 400) {
    level = LogLevel::kWarning;
  }
  log_->Printf(level, "web: %s %s %s %d%s%s", client, r->method, r->path, status,
               why != nullptr ? ": " : "", why != nullptr ? why : "");
}

bool WebServer::Reply(MHD_Connection* c, Request* r, int status, const char* type, const void* data,
                      size_t size, const char* why, const char* allow) {
  MHD_Response* response =
      MHD_create_response_from_buffer(size, const_cast<void*>(data), MHD_RESPMEM_MUST_COPY);
  if (response == nullptr) return false;
  CommonHeaders(response);
  if (type != nullptr) MHD_add_response_header(response, MHD_HTTP_HEADER_CONTENT_TYPE, type);
  MHD_add_response_header(response, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
  if (status == MHD_HTTP_SERVICE_UNAVAILABLE) {
    MHD_add_response_header(response, MHD_HTTP_HEADER_RETRY_AFTER, "1");
  }
  if (allow != nullptr) MHD_add_response_header(response, MHD_HTTP_HEADER_ALLOW, allow);
  return Send(c, r, response, status, why);
}

bool WebServer::Send(MHD_Connection* c, Request* r, MHD_Response* response, int status,
                     const char* why) {
  const bool ok = MHD_queue_response(c, static_cast<unsigned>(status), response) == MHD_YES;
  MHD_destroy_response(response);
  r->replied = true;
  LogRequest(c, r, status, why);
  return ok;
}

bool WebServer::ReplyError(MHD_Connection* c, Request* r, int status, const char* why,
                           const char* log_why, const char* allow) {
  std::string json = "{\"error\":";
  AppendJsonString(&json, why);
  json += "}";
  return Reply(c, r, status, "application/json", json.data(), json.size(),
               log_why != nullptr ? log_why : why, allow);
}

bool WebServer::ReplyStatus(MHD_Connection* c, Request* r, const Status& s) {
  return ReplyError(c, r, HttpStatusFor(s.code()), PublicText(s.message()).c_str(), s.message());
}

bool WebServer::NotAllowed(MHD_Connection* c, Request* r, const char* allow) {
  char why[64];
  snprintf(why, sizeof(why), "only %s", allow);
  return ReplyError(c, r, MHD_HTTP_METHOD_NOT_ALLOWED, why, nullptr, allow);
}

std::string WebServer::PublicText(const char* text) const {
  std::string out = text;
  // The folder itself first (its name may hold spaces): "photo folder /media/card: ..." reads
  // "photo folder: ...", "/media/card/IMG_1.jpg: ..." reads "IMG_1.jpg: ...".
  std::string dir = options_.photo_dir;
  while (dir.size() > 1 && dir.back() == '/') dir.pop_back();
  if (!dir.empty() && dir != "/") {
    for (size_t at; (at = out.find(dir)) != std::string::npos;) {
      size_t end = at + dir.size();
      while (end < out.size() && out[end] == '/') ++end;
      size_t begin = at;
      if (end == at + dir.size() && begin > 0 && out[begin - 1] == ' ') --begin;
      out.erase(begin, end - begin);
    }
  }
  // Any other absolute path: its last name.
  std::string cut;
  for (size_t i = 0; i < out.size();) {
    const bool starts_word = i == 0 || out[i - 1] == ' ' || out[i - 1] == '(' || out[i - 1] == '\'';
    if (out[i] != '/' || !starts_word) {
      cut.push_back(out[i++]);
      continue;
    }
    size_t end = i;
    while (end < out.size() && out[end] != ' ' && out[end] != ':' && out[end] != ',' &&
           out[end] != ')' && out[end] != '\'') {
      ++end;
    }
    const size_t slash = out.rfind('/', end - 1);
    cut.append(out, slash + 1, end - slash - 1);
    i = end;
  }
  return cut;
}

}  // namespace lb
