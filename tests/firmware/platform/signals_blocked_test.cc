// The guard the product starts its helper threads in: every signal blocked inside it, the
// caller's own mask (not an empty one) back after it, and a thread started inside it keeps the
// signals blocked after the guard is gone.
#include "firmware/platform/signals_blocked.h"

#include <gtest/gtest.h>
#include <pthread.h>

namespace lb {
namespace {

bool Blocked(int sig) {
  sigset_t now;
  pthread_sigmask(SIG_SETMASK, nullptr, &now);
  return sigismember(&now, sig) == 1;
}

TEST(SignalsBlocked, BlocksEverySignalInItsScopeAndRestoresTheCallersMask) {
  sigset_t usr1, before;
  sigemptyset(&usr1);
  sigaddset(&usr1, SIGUSR1);
  pthread_sigmask(SIG_BLOCK, &usr1, &before);  // a mask of the caller's own, to be kept
  ASSERT_FALSE(Blocked(SIGTERM));
  {
    const SignalsBlocked blocked;
    EXPECT_TRUE(Blocked(SIGTERM));
    EXPECT_TRUE(Blocked(SIGINT));
    EXPECT_TRUE(Blocked(SIGHUP));
    EXPECT_TRUE(Blocked(SIGUSR1));
  }
  EXPECT_FALSE(Blocked(SIGTERM));
  EXPECT_FALSE(Blocked(SIGINT));
  EXPECT_TRUE(Blocked(SIGUSR1));
  pthread_sigmask(SIG_SETMASK, &before, nullptr);
}

void* ReportTerm(void* out) {
  *static_cast<bool*>(out) = Blocked(SIGTERM);
  return nullptr;
}

TEST(SignalsBlocked, AThreadStartedInsideKeepsThemBlocked) {
  bool inside = false, outside = true;
  pthread_t t;
  {
    const SignalsBlocked blocked;
    ASSERT_EQ(pthread_create(&t, nullptr, &ReportTerm, &inside), 0);
  }
  pthread_join(t, nullptr);
  ASSERT_EQ(pthread_create(&t, nullptr, &ReportTerm, &outside), 0);
  pthread_join(t, nullptr);
  EXPECT_TRUE(inside);
  EXPECT_FALSE(outside);
}

}  // namespace
}  // namespace lb
