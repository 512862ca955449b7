// Internal to firmware/web: what the server's plumbing (web_server.cc) and its answers
// (web_routes.cc) share.
#pragma once

#include <microhttpd.h>

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "firmware/web/web_form.h"
#include "firmware/web/web_server.h"

namespace lb {

// One request's state between libmicrohttpd's calls: the form fields so far (its post processor
// decodes the body; at most max_body bytes), the body itself, and whether an answer was queued.
struct WebServer::Request {
  ~Request() {
    if (post != nullptr) MHD_destroy_post_processor(post);
  }
  char method[8] = "";
  char path[168] = "";  // as logged
  MHD_PostProcessor* post = nullptr;
  Fields fields;
  size_t body_bytes = 0;
  std::string body;  // as sent (at most max_body): the fields the form parser passes over
  bool too_large = false;
  bool bad_body = false;
  bool replied = false;
};

// The render outputs: a fixed number of sinks whose capacity stays between requests (so steady
// use does not grow memory), each lent to one render and returned when libmicrohttpd has sent
// and freed its response.
class WebServer::Sinks {
 public:
  static constexpr int kCount = 2;
  static constexpr size_t kMaxBytes = 48u << 20;  // a full-size JPEG of a 16 MP photo fits

  class Sink final : public ByteSink {
   public:
    bool Append(const uint8_t* data, size_t size) override {
      if (size > kMaxBytes - bytes.size()) return false;
      bytes.insert(bytes.end(), data, data + size);
      return true;
    }
    std::vector<uint8_t> bytes;
    Sinks* owner = nullptr;
    bool lent = false;
  };

  Sinks() {
    for (Sink& s : sinks_) s.owner = this;
  }
  Sink* Acquire() {
    std::lock_guard<std::mutex> lock(mutex_);
    for (Sink& s : sinks_) {
      if (!s.lent) {
        s.lent = true;
        s.bytes.clear();
        return &s;
      }
    }
    return nullptr;
  }
  void Release(Sink* s) {
    std::lock_guard<std::mutex> lock(mutex_);
    s->lent = false;
  }

 private:
  std::mutex mutex_;
  Sink sinks_[kCount];
};

namespace web {

// Headers every answer carries: nothing is sniffed, framed or sent on to another site.
void CommonHeaders(MHD_Response* response);
// `s` as a JSON string: quoted, with quotes, backslashes and control characters escaped.
void AppendJsonString(std::string* out, const char* s);
// Equal in a time that does not depend on where the first difference is.
bool SameSecret(const char* given, const std::string& secret);

}  // namespace web
}  // namespace lb
