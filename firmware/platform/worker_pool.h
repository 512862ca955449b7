// The board's cores as a TaskRunner (algo/core/task_runner.h): a fixed set of threads started
// once, at configure time, and parked between runs. Run hands out tasks through one atomic
// counter; the mutex and condition variable are touched twice per Run (to wake the workers and
// to wait for the last task), never per task, and nothing is allocated after Start.
#pragma once

#include <pthread.h>

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>

#include "algo/core/status.h"
#include "algo/core/task_runner.h"

namespace lb {

class WorkerPool final : public TaskRunner {
 public:
  WorkerPool() = default;
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;
  ~WorkerPool() override;

  // Starts `workers` - 1 threads (the caller of Run is the first worker). 1 starts none.
  Status Start(int32_t workers);
  // Joins the threads; Start may be called again.
  void Stop();

  int32_t workers() const override { return workers_; }
  // One Run at a time: a pool serves one pipeline.
  void Run(int32_t tasks, TaskFn fn, void* context) override;

  // The cores this process may run on (its affinity mask), at least 1.
  static int32_t AvailableCores();
  // The workers for a `threads` setting: itself when positive, else one per available core,
  // at most kMaxWorkers.
  static int32_t CountFor(int32_t threads);

 private:
  static void* Entry(void* thread);
  void Loop(int32_t worker);
  void TakeTasks(int32_t worker);

  int32_t workers_ = 1;
  // pthreads rather than std::thread: a failed start is a Status here, not an exception.
  struct Thread {
    WorkerPool* pool = nullptr;
    int32_t worker = 0;
    pthread_t id = {};
  };
  Thread threads_[kMaxWorkers - 1];
  int32_t started_ = 0;  // threads running

  std::mutex mutex_;
  std::condition_variable wake_;  // a new run, or stop
  std::condition_variable done_;  // the last task of a run returned
  uint64_t generation_ = 0;       // runs started; guarded by mutex_
  int32_t busy_ = 0;              // workers still inside the current run; guarded by mutex_
  bool stopping_ = false;         // guarded by mutex_

  // The current run, written before the wake-up and read by the workers after it.
  TaskFn fn_ = nullptr;
  void* context_ = nullptr;
  int32_t tasks_ = 0;
  std::atomic<int32_t> next_{0};
};

}  // namespace lb
