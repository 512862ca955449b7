// The pool a stage's work is split over: every task runs exactly once whatever the thread count,
// each worker runs one task at a time, results do not depend on the count, and a run neither
// allocates nor starts a thread.
#include "firmware/platform/worker_pool.h"

#include <dirent.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <vector>

#include "tests/support/alloc_counter.h"

namespace lb {
namespace {

// Threads of this process, from /proc/self/task.
int32_t ThreadCount() {
  DIR* dir = opendir("/proc/self/task");
  if (dir == nullptr) return -1;
  int32_t n = 0;
  while (dirent* e = readdir(dir)) n += e->d_name[0] != '.';
  closedir(dir);
  return n;
}

TEST(WorkerPool, EveryTaskRunsOnceOnAWorkerInRange) {
  for (int32_t workers : {1, 2, 3, 4, 7}) {
    WorkerPool pool;
    ASSERT_TRUE(pool.Start(workers).ok());
    EXPECT_EQ(pool.workers(), workers);
    for (int32_t tasks : {0, 1, 2, 5, 64, 1000}) {
      std::vector<std::atomic<int32_t>> runs(static_cast<size_t>(tasks));
      std::atomic<int32_t> bad_worker{0};
      ParallelFor(pool, tasks, [&](int32_t task, int32_t worker) {
        runs[static_cast<size_t>(task)].fetch_add(1);
        if (worker < 0 || worker >= workers) bad_worker.fetch_add(1);
      });
      for (int32_t t = 0; t < tasks; ++t) {
        ASSERT_EQ(runs[static_cast<size_t>(t)].load(), 1) << workers << " workers, task " << t;
      }
      EXPECT_EQ(bad_worker.load(), 0);
    }
  }
}

TEST(WorkerPool, AWorkerRunsOneTaskAtATime) {
  // Per-worker scratch is only safe if no two tasks hold the same worker index at once.
  WorkerPool pool;
  ASSERT_TRUE(pool.Start(4).ok());
  std::atomic<int32_t> inside[4] = {};
  std::atomic<int32_t> overlaps{0};
  for (int32_t round = 0; round < 50; ++round) {
    ParallelFor(pool, 200, [&](int32_t task, int32_t worker) {
      if (inside[worker].fetch_add(1) != 0) overlaps.fetch_add(1);
      volatile uint32_t spin = static_cast<uint32_t>(task);
      for (int32_t i = 0; i < 200; ++i) spin = spin * 1664525u + 1013904223u;
      inside[worker].fetch_sub(1);
    });
  }
  EXPECT_EQ(overlaps.load(), 0);
}

TEST(WorkerPool, ResultsDoNotDependOnTheThreadCount) {
  // Disjoint outputs per task, the split the pipeline's stages use.
  constexpr int32_t kRows = 97, kWidth = 333;
  auto compute = [&](TaskRunner& runner) {
    std::vector<uint32_t> out(static_cast<size_t>(kRows) * kWidth);
    ParallelFor(runner, kRows, [&](int32_t y, int32_t) {
      uint32_t h = static_cast<uint32_t>(y) * 2654435761u;
      for (int32_t x = 0; x < kWidth; ++x) {
        h = (h ^ static_cast<uint32_t>(x)) * 16777619u;
        out[static_cast<size_t>(y) * kWidth + static_cast<size_t>(x)] = h;
      }
    });
    return out;
  };
  InlineRunner inline_runner;
  const std::vector<uint32_t> reference = compute(inline_runner);
  for (int32_t workers = 1; workers <= 4; ++workers) {
    WorkerPool pool;
    ASSERT_TRUE(pool.Start(workers).ok());
    EXPECT_EQ(compute(pool), reference) << workers << " workers";
  }
}

TEST(WorkerPool, ARunAllocatesNothingAndStartsNoThread) {
  WorkerPool pool;
  ASSERT_TRUE(pool.Start(3).ok());
  const int32_t threads = ThreadCount();
  ASSERT_GT(threads, 0);
  std::atomic<int64_t> sum{0};
  const size_t before = testing::AllocationCount();
  for (int32_t round = 0; round < 100; ++round) {
    ParallelFor(pool, 16, [&](int32_t task, int32_t) { sum.fetch_add(task); });
  }
  const size_t after = testing::AllocationCount();
  EXPECT_EQ(after - before, 0u);
  EXPECT_EQ(sum.load(), 100 * (15 * 16 / 2));
  EXPECT_EQ(ThreadCount(), threads);
}

// The process's thread count once it settles at `expected` (within 2 s): under qemu-user a
// joined thread can stay listed a moment longer.
int32_t SettledThreadCount(int32_t expected) {
  int32_t n = ThreadCount();
  for (int32_t i = 0; i < 200 && n != expected; ++i) {
    usleep(10000);
    n = ThreadCount();
  }
  return n;
}

TEST(WorkerPool, StartsTheThreadsItIsAskedForAndStopsThem) {
  const int32_t alone = ThreadCount();
  WorkerPool pool;
  ASSERT_TRUE(pool.Start(4).ok());
  EXPECT_EQ(SettledThreadCount(alone + 3), alone + 3) << "the caller is the first worker";
  ASSERT_TRUE(pool.Start(2).ok());
  EXPECT_EQ(SettledThreadCount(alone + 1), alone + 1);
  pool.Stop();
  EXPECT_EQ(SettledThreadCount(alone), alone);
  EXPECT_EQ(pool.workers(), 1);
  // A stopped pool still runs, on the caller.
  int32_t ran = 0;
  ParallelFor(pool, 3, [&](int32_t, int32_t worker) { ran += worker == 0; });
  EXPECT_EQ(ran, 3);
}

TEST(WorkerPool, WorkersTakeNoSignalAndTheCallerKeepsItsMask) {
  // A signal's handler must run on the thread that commits the command's file
  // (temp_registry.h), so the workers hold every signal blocked; starting them leaves the
  // caller's mask as it was.
  WorkerPool pool;
  ASSERT_TRUE(pool.Start(3).ok());
  sigset_t mask;
  pthread_sigmask(SIG_SETMASK, nullptr, &mask);
  EXPECT_EQ(sigismember(&mask, SIGTERM), 0);
  std::atomic<int32_t> open_workers{0}, worker_tasks{0};
  for (int32_t round = 0; round < 20; ++round) {
    ParallelFor(pool, 64, [&](int32_t, int32_t worker) {
      if (worker == 0) {  // leaves tasks to the workers, however late they wake
        const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(50);
        while (worker_tasks.load() == 0 && std::chrono::steady_clock::now() < end) {
        }
        return;
      }
      worker_tasks.fetch_add(1);
      sigset_t now;
      pthread_sigmask(SIG_SETMASK, nullptr, &now);
      if (sigismember(&now, SIGTERM) != 1 || sigismember(&now, SIGINT) != 1)
        open_workers.fetch_add(1);
    });
  }
  EXPECT_GT(worker_tasks.load(), 0);
  EXPECT_EQ(open_workers.load(), 0);
}

TEST(WorkerPool, ACountOutsideTheRangeIsRefused) {
  WorkerPool pool;
  for (int32_t bad : {0, -1, kMaxWorkers + 1}) {
    const Status s = pool.Start(bad);
    EXPECT_EQ(s.code(), Code::kInvalidArgument) << bad;
    EXPECT_NE(strstr(s.message(), "threads"), nullptr) << s.message();
  }
  EXPECT_GE(WorkerPool::AvailableCores(), 1);
}

}  // namespace
}  // namespace lb
