// The allocation counter counts: one allocation of each kind it claims to see moves it by exactly
// one. Without this, a test that finds zero allocations could be watching a counter that never
// counts. The calls go through volatile function pointers and their results are stored and
// used, so the compiler cannot elide them.
#include "tests/support/alloc_counter.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>

namespace lb::testing {
namespace {

using Alloc = void* (*)(size_t);
void* (*volatile g_malloc)(size_t) = &malloc;
void* (*volatile g_calloc)(size_t, size_t) = &calloc;
void* (*volatile g_realloc)(void*, size_t) = &realloc;
volatile Alloc g_new = static_cast<Alloc>(&::operator new);
volatile Alloc g_new_array = static_cast<Alloc>(&::operator new[]);
void* volatile g_sink = nullptr;

// Allocations counted while `f` runs.
template <typename F>
size_t Counted(F f) {
  const size_t before = AllocationCount();
  f();
  return AllocationCount() - before;
}

TEST(AllocationCounter, CountsEachKindOnce) {
  void* p = nullptr;
  EXPECT_EQ(Counted([&] { p = g_malloc(24); }), 1u) << "malloc";
  ASSERT_NE(p, nullptr);
  memset(p, 1, 24);
  EXPECT_EQ(Counted([&] { p = g_realloc(p, 4096); }), 1u) << "realloc";
  ASSERT_NE(p, nullptr);
  g_sink = p;
  free(p);
  EXPECT_EQ(Counted([&] { p = g_calloc(3, 8); }), 1u) << "calloc";
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(static_cast<unsigned char*>(p)[5], 0);
  free(p);
  EXPECT_EQ(Counted([&] { p = g_new(16); }), 1u) << "operator new";
  g_sink = p;
  ::operator delete(p);
  EXPECT_EQ(Counted([&] { p = g_new_array(16); }), 1u) << "operator new[]";
  g_sink = p;
  ::operator delete[](p);
}

TEST(AllocationCounter, CountsNewExpressions) {
  int* one = nullptr;
  int* many = nullptr;
  EXPECT_EQ(Counted([&] { one = new int(7); }), 1u);
  EXPECT_EQ(Counted([&] { many = new int[9]; }), 1u);
  struct alignas(64) Line {
    char bytes[64];
  };
  Line* line = nullptr;
  EXPECT_EQ(Counted([&] { line = new Line; }), 1u) << "aligned new";
  g_sink = one;
  g_sink = many;
  g_sink = line;
  EXPECT_EQ(*one, 7);
  EXPECT_EQ(reinterpret_cast<uintptr_t>(line) % 64, 0u);
  delete one;
  delete[] many;
  delete line;
}

TEST(AllocationCounter, FreeingCountsNothing) {
  void* p = g_malloc(8);
  int* q = new int(1);
  g_sink = q;
  EXPECT_EQ(Counted([&] {
              free(p);
              delete q;
            }),
            0u);
}

}  // namespace
}  // namespace lb::testing
