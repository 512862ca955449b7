// A TaskRunner for the tests of stages that split their work: it runs a Run's tasks on the
// caller, last to first, each on another worker than a pool would pick. A stage whose tasks
// read what another task writes, or whose results depend on the order of its tasks or on a
// worker's scratch history, gives other bits here than on one worker.
#pragma once

#include <cstdint>

#include "algo/core/task_runner.h"

namespace lb::testing {

class BackwardsRunner final : public TaskRunner {
 public:
  explicit BackwardsRunner(int32_t workers) : workers_(workers) {}
  int32_t workers() const override { return workers_; }
  void Run(int32_t tasks, TaskFn fn, void* context) override {
    for (int32_t t = tasks - 1; t >= 0; --t) fn(context, t, (t + runs_) % workers_);
    ++runs_;
  }

 private:
  int32_t workers_, runs_ = 0;
};

}  // namespace lb::testing
