// One thread beside the worker pool, started once at configure and parked between tasks, that
// runs one task at a time while its caller goes on. The job builds the refocusable XMP there (the
// all-in-focus original's JPEG, the 16-bit depth PNG, base64 and MD5: about a tenth of a photo's
// time, and serial) while the render's strips are rendered and encoded.
#pragma once

#include <pthread.h>

#include <condition_variable>
#include <mutex>

#include "algo/core/status.h"

namespace lb {

class SideTask {
 public:
  using Fn = void (*)(void* context);

  SideTask() = default;
  SideTask(const SideTask&) = delete;
  SideTask& operator=(const SideTask&) = delete;
  ~SideTask();

  // Starts the thread (with the caller's scheduling policy and priority); a no-op when running.
  Status Start();
  // Waits for a posted task, then joins the thread.
  void Stop();
  bool started() const { return started_; }

  // Runs fn(context) on the thread. One task at a time: the previous one must have been waited
  // for. Without a thread the task runs here, before Post returns.
  void Post(Fn fn, void* context);
  // Whether the posted task has returned (never blocks); true when none was posted.
  bool Done();
  // Returns once the posted task has returned.
  void Wait();

 private:
  static void* Entry(void* self);
  void Loop();

  pthread_t thread_ = {};
  bool started_ = false;
  std::mutex mutex_;
  std::condition_variable wake_;  // a task was posted, or stop
  std::condition_variable done_;  // the task returned
  Fn fn_ = nullptr;               // the posted task, until it returns; guarded by mutex_
  void* context_ = nullptr;
  bool stopping_ = false;
};

// Waits for the task posted to `side` when it leaves scope, so a task that reads the caller's
// locals never outlives them, whichever way the caller returns.
class SideTaskGuard {
 public:
  explicit SideTaskGuard(SideTask* side) : side_(side) {}
  ~SideTaskGuard() { side_->Wait(); }
  SideTaskGuard(const SideTaskGuard&) = delete;
  SideTaskGuard& operator=(const SideTaskGuard&) = delete;

 private:
  SideTask* side_;
};

}  // namespace lb
