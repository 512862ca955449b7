#include "firmware/storage/temp_registry.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstring>

namespace lb::temp_registry {
namespace {

// 0 free, 1 being written, 2 registered: the handler reads only fully written paths.
struct Slot {
  std::atomic<int> state{0};
  char path[kMaxPath] = {};
};
Slot g_slots[kSlots];
std::atomic<bool> g_committed{false};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler reads these");
static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler reads this");

}  // namespace

bool Add(const char* path) {
  if (strlen(path) >= static_cast<size_t>(kMaxPath)) return false;
  for (Slot& s : g_slots) {
    int expected = 0;
    if (!s.state.compare_exchange_strong(expected, 1)) continue;
    strcpy(s.path, path);
    s.state.store(2);
    return true;
  }
  return false;
}

void Remove(const char* path) {
  for (Slot& s : g_slots) {
    if (s.state.load() == 2 && strcmp(s.path, path) == 0) {
      s.state.store(0);
      return;
    }
  }
}

void MarkCommitted() { g_committed.store(true); }

void UnlinkAll() {
  for (Slot& s : g_slots) {
    if (s.state.load() == 2) unlink(s.path);
  }
}

}  // namespace lb::temp_registry

namespace lb {
namespace {

extern "C" void OnFatalSignal(int sig) {
  if (temp_registry::g_committed.load()) return;  // SA_RESTART: a call it interrupted goes on
  temp_registry::UnlinkAll();
  signal(sig, SIG_DFL);
  raise(sig);
}

}  // namespace

void RemoveTemporariesOnSignals() {
  temp_registry::g_committed.store(false);  // each command starts unmarked
  struct sigaction sa;
  memset(&sa, 0, sizeof(sa));
  sa.sa_handler = OnFatalSignal;
  sa.sa_flags = SA_RESTART;
  sigemptyset(&sa.sa_mask);
  for (int sig : temp_registry::kStopSignals) sigaction(sig, &sa, nullptr);
}

}  // namespace lb
