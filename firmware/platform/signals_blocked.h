// Every signal blocked on the calling thread for the guard's scope, the old mask back after.
// A thread inherits its creator's mask, so the product starts its helper threads (the worker
// pool's, the side task's, the daemon's worker) inside one: a process-directed signal then runs
// its handler on the thread that owns the command and its commit (firmware/storage/
// temp_registry.h), never on a helper racing it.
#pragma once

#include <signal.h>

namespace lb {

class SignalsBlocked {
 public:
  SignalsBlocked() {
    sigset_t all;
    sigfillset(&all);
    pthread_sigmask(SIG_SETMASK, &all, &old_);
  }
  ~SignalsBlocked() { pthread_sigmask(SIG_SETMASK, &old_, nullptr); }
  SignalsBlocked(const SignalsBlocked&) = delete;
  SignalsBlocked& operator=(const SignalsBlocked&) = delete;

 private:
  sigset_t old_;
};

}  // namespace lb
