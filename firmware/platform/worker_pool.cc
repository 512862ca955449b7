#include "firmware/platform/worker_pool.h"

#include <sched.h>

#include <cstring>

namespace lb {

WorkerPool::~WorkerPool() { Stop(); }

Status WorkerPool::Start(int32_t workers) {
  if (workers < 1 || workers > kMaxWorkers) {
    return Status(Code::kInvalidArgument, "threads: %d is outside 1..%d", workers, kMaxWorkers);
  }
  Stop();
  stopping_ = false;
  for (int32_t i = 0; i + 1 < workers; ++i) {
    Thread& t = threads_[i];
    t.pool = this;
    t.worker = i + 1;
    const int err = pthread_create(&t.id, nullptr, &WorkerPool::Entry, &t);
    if (err != 0) {
      Stop();
      return Status(Code::kUnsupported, "threads: cannot start worker %d of %d: %s", i + 2, workers,
                    strerror(err));
    }
    ++started_;
  }
  workers_ = workers;
  return Status::Ok();
}

void WorkerPool::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (int32_t i = 0; i < started_; ++i) pthread_join(threads_[i].id, nullptr);
  started_ = 0;
  workers_ = 1;
  generation_ = 0;  // a thread started later waits for the next run, not a stale one
  busy_ = 0;
}

void* WorkerPool::Entry(void* thread) {
  const Thread* t = static_cast<const Thread*>(thread);
  t->pool->Loop(t->worker);
  return nullptr;
}

void WorkerPool::Loop(int32_t worker) {
  uint64_t seen = 0;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stopping_ || generation_ != seen; });
      if (stopping_) return;
      seen = generation_;
    }
    TakeTasks(worker);
    std::lock_guard<std::mutex> lock(mutex_);
    if (--busy_ == 0) done_.notify_one();
  }
}

void WorkerPool::TakeTasks(int32_t worker) {
  for (int32_t t = next_.fetch_add(1, std::memory_order_relaxed); t < tasks_;
       t = next_.fetch_add(1, std::memory_order_relaxed)) {
    fn_(context_, t, worker);
  }
}

void WorkerPool::Run(int32_t tasks, TaskFn fn, void* context) {
  if (started_ == 0 || tasks <= 1) {
    for (int32_t t = 0; t < tasks; ++t) fn(context, t, 0);
    return;
  }
  // Published to the workers by the mutex below: each reads them after taking it.
  fn_ = fn;
  context_ = context;
  tasks_ = tasks;
  next_.store(0, std::memory_order_relaxed);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    busy_ = started_;
    ++generation_;
  }
  wake_.notify_all();
  TakeTasks(0);
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [&] { return busy_ == 0; });
}

int32_t WorkerPool::AvailableCores() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) != 0) return 1;
  const int n = CPU_COUNT(&set);
  return n < 1 ? 1 : n;
}

int32_t WorkerPool::CountFor(int32_t threads) {
  if (threads > 0) return threads;
  const int32_t cores = AvailableCores();
  return cores < kMaxWorkers ? cores : kMaxWorkers;
}

}  // namespace lb
