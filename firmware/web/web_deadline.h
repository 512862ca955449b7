// Internal to firmware/web: the deadline of a whole request. libmicrohttpd's own timeout is an
// idle one (reset by every byte), so a client that sends one header line every few seconds could
// hold a connection for ever; here each connection has until `deadline` after it opened, or after
// its previous answer, to deliver a whole request (headers and body). One thread, made by the
// server at the web's priority, shuts an overdue connection's socket down; libmicrohttpd then
// sees the end of the stream and closes the connection itself. Time spent answering (a render, a
// thumbnail waiting for the camera, sending a photo) does not count.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <set>
#include <thread>

namespace lb {

class RequestDeadlines {
 public:
  struct Entry;

  // `on_cut` is told each client cut (for the log), on the deadlines' thread.
  RequestDeadlines(int32_t deadline_ms, std::function<void(const char* client)> on_cut);
  ~RequestDeadlines();  // Stop
  RequestDeadlines(const RequestDeadlines&) = delete;
  RequestDeadlines& operator=(const RequestDeadlines&) = delete;

  // Starts the thread (it takes the caller's priority).
  void Start();
  void Stop();

  // A connection opened on socket `fd` from `client` (text for the log). The entry lives until
  // Closed, which must come before the socket is closed (libmicrohttpd's order).
  Entry* Opened(int fd, const char* client);
  void Closed(Entry* e);
  // Its request has arrived whole: no deadline while it is answered.
  void Whole(Entry* e);
  // Its answer is done: the next request on the connection has a new deadline.
  void Answered(Entry* e);

 private:
  using Clock = std::chrono::steady_clock;
  void Loop();

  const int32_t deadline_ms_;
  const std::function<void(const char*)> on_cut_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::set<Entry*> open_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace lb
