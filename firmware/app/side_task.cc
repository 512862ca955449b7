#include "firmware/app/side_task.h"

#include <cstring>

#include "firmware/platform/signals_blocked.h"

namespace lb {

SideTask::~SideTask() { Stop(); }

Status SideTask::Start() {
  if (started_) return Status::Ok();
  stopping_ = false;
  int err = 0;
  {
    const SignalsBlocked blocked;
    // Default attributes inherit the caller's policy: under a real-time caller the task competes
    // with the workers as an equal.
    err = pthread_create(&thread_, nullptr, &SideTask::Entry, this);
  }
  if (err != 0) {
    return Status(Code::kUnsupported, "threads: cannot start the side thread: %s", strerror(err));
  }
  started_ = true;
  return Status::Ok();
}

void SideTask::Stop() {
  if (!started_) return;
  Wait();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  pthread_join(thread_, nullptr);
  started_ = false;
}

void* SideTask::Entry(void* self) {
  static_cast<SideTask*>(self)->Loop();
  return nullptr;
}

void SideTask::Loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return stopping_ || fn_ != nullptr; });
    if (fn_ == nullptr) return;  // stopping, nothing posted
    const Fn fn = fn_;
    void* context = context_;
    lock.unlock();
    fn(context);
    lock.lock();
    fn_ = nullptr;
    done_.notify_all();
  }
}

void SideTask::Post(Fn fn, void* context) {
  if (!started_) {
    fn(context);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    fn_ = fn;
    context_ = context;
  }
  wake_.notify_one();
}

bool SideTask::Done() {
  std::lock_guard<std::mutex> lock(mutex_);
  return fn_ == nullptr;
}

void SideTask::Wait() {
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [&] { return fn_ == nullptr; });
}

}  // namespace lb
