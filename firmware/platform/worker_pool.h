// The board's cores as a TaskRunner (algo/core/task_runner.h): a fixed set of threads started
// once, at configure time. Run hands out tasks through one atomic word (the run's number and the
// next task), so a worker that wakes late can take no task of a later run, and returns when every
// task has returned, not when every worker has woken: a run whose tasks the caller finished
// alone does not wait for a sleeping worker. Between runs a worker spins a few tens of
// microseconds before it parks on the condition variable (the stages run many short runs back
// to back, and waking a parked thread costs more than a short run); the caller spins as long for
// the last task before it parks. Nothing is allocated after Start.
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
  // Takes and runs tasks of run `run` until none is left.
  void TakeTasks(uint32_t run, TaskFn fn, void* context, int32_t tasks, int32_t worker);

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
  bool stopping_ = false;         // guarded by mutex_
  // Mirrors of generation_ (its low 32 bits) and stopping_ that a spinning worker reads.
  std::atomic<uint32_t> posted_{0};
  std::atomic<bool> stop_{false};

  // The current run, written under mutex_ before it is posted; a worker copies them under
  // mutex_ with the run's number.
  TaskFn fn_ = nullptr;
  void* context_ = nullptr;
  int32_t tasks_ = 0;
  // The run's number (high 32 bits) and its next task (low 32 bits): a task is taken by a
  // compare-and-swap that also checks the number.
  std::atomic<uint64_t> claim_{0};
  std::atomic<int32_t> finished_{0};  // tasks of the current run that returned
};

}  // namespace lb
