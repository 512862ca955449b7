// Splitting a stage's work over the board's cores. algo/ makes no OS calls, so the threads live
// in firmware/ (firmware/platform/worker_pool.h) and reach a stage through this interface; a
// stage given no runner uses InlineRunner, which runs everything on the caller.
//
// Determinism: a stage splits its work into tasks that write disjoint outputs and read nothing
// another task of the same Run writes, and keys scratch memory by `worker` (each worker runs one
// task at a time), so its output bits do not depend on how many workers there are or which one
// ran which task.
#pragma once

#include <cstdint>

namespace lb {

// Most workers a stage carves scratch for.
inline constexpr int32_t kMaxWorkers = 16;

// One task of a Run: `task` in [0, tasks), `worker` in [0, workers()).
using TaskFn = void (*)(void* context, int32_t task, int32_t worker);

class TaskRunner {
 public:
  virtual ~TaskRunner() = default;
  // How many tasks may run at once: per-worker scratch is sized by this.
  virtual int32_t workers() const = 0;
  // Calls fn(context, task, worker) once for every task and returns when all have returned.
  // Neither allocates nor starts a thread; the calling thread takes tasks too.
  virtual void Run(int32_t tasks, TaskFn fn, void* context) = 0;
};

class InlineRunner final : public TaskRunner {
 public:
  int32_t workers() const override { return 1; }
  void Run(int32_t tasks, TaskFn fn, void* context) override {
    for (int32_t t = 0; t < tasks; ++t) fn(context, t, 0);
  }
};

// Runs body(task, worker) for every task through `runner`. The body is borrowed by address, so
// no closure is copied or allocated.
template <typename Body>
void ParallelFor(TaskRunner& runner, int32_t tasks, Body&& body) {
  auto* ctx = &body;
  runner.Run(
      tasks,
      [](void* c, int32_t task, int32_t worker) { (*static_cast<decltype(ctx)>(c))(task, worker); },
      ctx);
}

}  // namespace lb
