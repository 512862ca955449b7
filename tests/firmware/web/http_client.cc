#include "tests/firmware/web/http_client.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <strings.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>

namespace lb::test {
namespace {

int64_t NowMs() {
  timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<int64_t>(t.tv_sec) * 1000 + t.tv_nsec / 1000000;
}

}  // namespace

std::string HttpResponse::Header(const std::string& name) const {
  size_t pos = 0;
  while (pos < headers.size()) {
    size_t end = headers.find("\r\n", pos);
    if (end == std::string::npos) end = headers.size();
    const std::string line = headers.substr(pos, end - pos);
    pos = end + 2;
    const size_t colon = line.find(':');
    if (colon == name.size() && strncasecmp(line.c_str(), name.c_str(), colon) == 0) {
      size_t v = colon + 1;
      while (v < line.size() && line[v] == ' ') ++v;
      return line.substr(v);
    }
  }
  return "";
}

int ConnectLoopback(int port) { return ConnectLoopbackFrom(nullptr, port); }

int ConnectLoopbackFrom(const char* source, int port) {
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  if (source != nullptr) {
    sockaddr_in from{};
    from.sin_family = AF_INET;
    if (inet_pton(AF_INET, source, &from.sin_addr) != 1 ||
        bind(fd, reinterpret_cast<sockaddr*>(&from), sizeof(from)) != 0) {
      close(fd);
      return -1;
    }
  }
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0) {
    close(fd);
    return -1;
  }
  return fd;
}

namespace {

HttpResponse Exchange(int fd, const std::string& request, int timeout_ms) {
  HttpResponse out;
  // A server that answers early (413) may close before the whole body is sent: not an error.
  size_t sent = 0;
  while (sent < request.size()) {
    const ssize_t n = send(fd, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += static_cast<size_t>(n);
  }
  std::string raw;
  const int64_t deadline = NowMs() + timeout_ms;
  char buf[65536];
  for (;;) {
    const int64_t left = deadline - NowMs();
    if (left <= 0) break;
    pollfd p{fd, POLLIN, 0};
    if (poll(&p, 1, static_cast<int>(left)) <= 0) break;
    const ssize_t n = recv(fd, buf, sizeof(buf), 0);
    if (n <= 0) break;
    raw.append(buf, static_cast<size_t>(n));
  }
  close(fd);
  const size_t head_end = raw.find("\r\n\r\n");
  if (raw.compare(0, 9, "HTTP/1.1 ") != 0 || head_end == std::string::npos) return out;
  out.status = atoi(raw.c_str() + 9);
  const size_t first = raw.find("\r\n");
  out.headers = raw.substr(first + 2, head_end - first - 2);
  out.body = raw.substr(head_end + 4);
  return out;
}

}  // namespace

HttpResponse HttpOn(int fd, const std::string& method, const std::string& target,
                    const std::string& headers, const std::string& body, int timeout_ms) {
  std::string request = method + " " + target + " HTTP/1.1\r\nHost: 127.0.0.1\r\n" +
                        "Connection: close\r\n" + headers;
  if (!body.empty() || method == "POST") {
    request += "Content-Length: " + std::to_string(body.size()) + "\r\n";
  }
  return Exchange(fd, request + "\r\n" + body, timeout_ms);
}

HttpResponse SendRaw(int port, const std::string& bytes, int timeout_ms) {
  const int fd = ConnectLoopback(port);
  if (fd < 0) return HttpResponse();
  return Exchange(fd, bytes, timeout_ms);
}

HttpResponse Http(int port, const std::string& method, const std::string& target,
                  const std::string& headers, const std::string& body, int timeout_ms) {
  const int fd = ConnectLoopback(port);
  if (fd < 0) return HttpResponse();
  return HttpOn(fd, method, target, headers, body, timeout_ms);
}

}  // namespace lb::test
