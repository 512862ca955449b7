// A tiny HTTP/1.1 client over POSIX sockets for the web tests. Written here rather than running
// curl so the tests send exactly the bytes they mean ("/photos/../x" and "%2e%2e%2f" unchanged,
// no client-side normalisation), can hold connections open to reach the server's limits, and
// run in-process under the sanitizers. One request per connection (Connection: close).
#pragma once

#include <cstdint>
#include <string>

namespace lb::test {

struct HttpResponse {
  int status = 0;       // 0: no answer (the connection was closed or refused)
  std::string headers;  // raw header lines, "\r\n" separated
  std::string body;
  // The value of `name` (case-insensitive), "" when absent.
  std::string Header(const std::string& name) const;
};

// Connects to 127.0.0.1:port; -1 on failure.
int ConnectLoopback(int port);
// The same from `source`, another loopback address ("127.0.0.2": Linux answers all of 127/8), so
// one test can be several clients to the server's per-address limit.
int ConnectLoopbackFrom(const char* source, int port);

// Sends `method target` with `headers` (each "Name: value\r\n") and `body`, and reads the answer
// to the end of the connection (at most `timeout_ms`).
HttpResponse Http(int port, const std::string& method, const std::string& target,
                  const std::string& headers = "", const std::string& body = "",
                  int timeout_ms = 10000);
// The same over an already connected socket (closed afterwards).
HttpResponse HttpOn(int fd, const std::string& method, const std::string& target,
                    const std::string& headers, const std::string& body, int timeout_ms);

// Sends `bytes` as they are (a request the helpers above would not make) and reads the answer.
HttpResponse SendRaw(int port, const std::string& bytes, int timeout_ms);

}  // namespace lb::test
