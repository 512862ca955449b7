#include "firmware/web/web_deadline.h"

#include <sys/socket.h>

#include <cstdio>
#include <utility>

namespace lb {

struct RequestDeadlines::Entry {
  int fd = -1;
  char client[48] = "";
  Clock::time_point due;
  bool whole = false;  // being answered: no deadline
  bool cut = false;
};

RequestDeadlines::RequestDeadlines(int32_t deadline_ms,
                                   std::function<void(const char* client)> on_cut)
    : deadline_ms_(deadline_ms), on_cut_(std::move(on_cut)) {}

RequestDeadlines::~RequestDeadlines() { Stop(); }

void RequestDeadlines::Start() {
  if (thread_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = false;
  }
  thread_ = std::thread([this] { Loop(); });
}

void RequestDeadlines::Stop() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

RequestDeadlines::Entry* RequestDeadlines::Opened(int fd, const char* client) {
  Entry* e = new Entry;
  e->fd = fd;
  snprintf(e->client, sizeof(e->client), "%s", client);
  e->due = Clock::now() + std::chrono::milliseconds(deadline_ms_);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    open_.insert(e);
  }
  wake_.notify_all();
  return e;
}

void RequestDeadlines::Closed(Entry* e) {
  if (e == nullptr) return;
  {
    // Under the lock: the thread never shuts down a socket number that may already be reused.
    std::lock_guard<std::mutex> lock(mutex_);
    open_.erase(e);
  }
  delete e;
}

void RequestDeadlines::Whole(Entry* e) {
  if (e == nullptr) return;
  std::lock_guard<std::mutex> lock(mutex_);
  e->whole = true;
}

void RequestDeadlines::Answered(Entry* e) {
  if (e == nullptr) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    e->whole = false;
    e->due = Clock::now() + std::chrono::milliseconds(deadline_ms_);
  }
  wake_.notify_all();
}

void RequestDeadlines::Loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_) {
    const Clock::time_point now = Clock::now();
    Clock::time_point next = Clock::time_point::max();
    for (Entry* e : open_) {
      if (e->whole || e->cut) continue;
      if (e->due <= now) {
        // The connection's thread sees the end of the stream and closes it the usual way.
        shutdown(e->fd, SHUT_RDWR);
        e->cut = true;
        if (on_cut_) on_cut_(e->client);
      } else if (e->due < next) {
        next = e->due;
      }
    }
    if (next == Clock::time_point::max()) {
      wake_.wait(lock);
    } else {
      wake_.wait_until(lock, next);
    }
  }
}

}  // namespace lb
