#include "firmware/platform/worker_pool.h"

#include <sched.h>

#include <chrono>
#include <cstring>

#include "firmware/platform/signals_blocked.h"

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
    int err = 0;
    {
      const SignalsBlocked blocked;
      err = pthread_create(&t.id, nullptr, &WorkerPool::Entry, &t);
    }
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
    stop_.store(true, std::memory_order_release);
  }
  wake_.notify_all();
  for (int32_t i = 0; i < started_; ++i) pthread_join(threads_[i].id, nullptr);
  started_ = 0;
  workers_ = 1;
  generation_ = 0;  // a thread started later waits for the next run, not a stale one
  posted_.store(0, std::memory_order_relaxed);
  claim_.store(0, std::memory_order_relaxed);
  stop_.store(false, std::memory_order_relaxed);
}

void* WorkerPool::Entry(void* thread) {
  const Thread* t = static_cast<const Thread*>(thread);
  t->pool->Loop(t->worker);
  return nullptr;
}

namespace {

// How long a worker waits for the next run, and the caller for the last task, before parking.
constexpr auto kSpin = std::chrono::microseconds(50);

inline void Pause() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__) || defined(__arm__)
  asm volatile("yield");
#endif
}

// Spins until `ready` or kSpin has passed (the clock read every 64 turns); returns ready().
template <typename Ready>
bool SpinUntil(Ready&& ready) {
  const auto start = std::chrono::steady_clock::now();
  for (int32_t turn = 1;; ++turn) {
    if (ready()) return true;
    Pause();
    if (turn % 64 == 0 && std::chrono::steady_clock::now() - start > kSpin) return ready();
  }
}

}  // namespace

void WorkerPool::Loop(int32_t worker) {
  uint64_t seen = 0;
  for (;;) {
    SpinUntil([&] {
      return posted_.load(std::memory_order_acquire) != static_cast<uint32_t>(seen) ||
             stop_.load(std::memory_order_acquire);
    });
    TaskFn fn = nullptr;
    void* context = nullptr;
    int32_t tasks = 0;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stopping_ || generation_ != seen; });
      if (stopping_) return;
      seen = generation_;
      fn = fn_;
      context = context_;
      tasks = tasks_;
    }
    TakeTasks(static_cast<uint32_t>(seen), fn, context, tasks, worker);
  }
}

void WorkerPool::TakeTasks(uint32_t run, TaskFn fn, void* context, int32_t tasks, int32_t worker) {
  for (;;) {
    uint64_t v = claim_.load(std::memory_order_relaxed);
    do {
      if (static_cast<uint32_t>(v >> 32) != run ||
          static_cast<int32_t>(static_cast<uint32_t>(v)) >= tasks) {
        return;
      }
    } while (!claim_.compare_exchange_weak(v, v + 1, std::memory_order_relaxed));
    fn(context, static_cast<int32_t>(static_cast<uint32_t>(v)), worker);
    // The last task's return wakes a parked caller; the release orders the task's writes
    // before the caller's acquire of the count.
    if (finished_.fetch_add(1, std::memory_order_acq_rel) + 1 == tasks) {
      std::lock_guard<std::mutex> lock(mutex_);
      done_.notify_one();
    }
  }
}

void WorkerPool::Run(int32_t tasks, TaskFn fn, void* context) {
  if (started_ == 0 || tasks <= 1) {
    for (int32_t t = 0; t < tasks; ++t) fn(context, t, 0);
    return;
  }
  uint32_t run = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    fn_ = fn;
    context_ = context;
    tasks_ = tasks;
    run = static_cast<uint32_t>(++generation_);
    finished_.store(0, std::memory_order_relaxed);
    claim_.store(uint64_t{run} << 32, std::memory_order_relaxed);
    posted_.store(run, std::memory_order_release);
  }
  wake_.notify_all();
  TakeTasks(run, fn, context, tasks, 0);
  auto all_returned = [&] { return finished_.load(std::memory_order_acquire) == tasks; };
  if (SpinUntil(all_returned)) return;
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, all_returned);
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
