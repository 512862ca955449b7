// The viewpoints' tree (view_tree.h): hops from the reference along a line, a cross and a
// scatter, the same whatever order the points are listed in.
#include "algo/motion/view_tree.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace lb {
namespace {

// Hops of each point, for the points listed in `order` (order[i]: which point is i-th).
std::vector<int32_t> HopsInOrder(const std::vector<double>& xy, int32_t root,
                                 const std::vector<int32_t>& order) {
  const int32_t n = static_cast<int32_t>(order.size());
  std::vector<double> listed(2 * n);
  int32_t listed_root = -1;
  for (int32_t i = 0; i < n; ++i) {
    listed[2 * i] = xy[2 * order[i]];
    listed[2 * i + 1] = xy[2 * order[i] + 1];
    if (order[i] == root) listed_root = i;
  }
  int32_t parent[kMaxTreePoints], hops[kMaxTreePoints];
  EXPECT_TRUE(ViewTree(listed.data(), n, 2, listed_root, parent, hops));
  std::vector<int32_t> out(n);
  for (int32_t i = 0; i < n; ++i) out[order[i]] = hops[i];
  return out;
}

TEST(ViewTree, HopsAlongALineFromTheReferenceWhereverItIsListed) {
  // A row of 6 at slightly uneven steps, the reference the second from the left.
  const std::vector<double> xy = {-1.02, 0, 0, 0, 0.98, 0.01, 2.03, 0, 3.0, -0.01, 4.04, 0};
  const std::vector<int32_t> want = {1, 0, 1, 2, 3, 4};
  std::vector<int32_t> order = {0, 1, 2, 3, 4, 5};
  do {
    EXPECT_EQ(HopsInOrder(xy, 1, order), want);
  } while (std::next_permutation(order.begin(), order.end()));
}

TEST(ViewTree, ACrossIsOneHopAndAScatterFollowsItsNearestViewpoints) {
  const std::vector<double> cross = {0, -1, -1, 0, 0, 0, 1, 0, 0, 1};
  EXPECT_EQ(HopsInOrder(cross, 2, {4, 3, 2, 1, 0}), (std::vector<int32_t>{1, 1, 0, 1, 1}));
  // A hand's frames: 3 near the reference, 4 beyond 3, 1 on the other side.
  const std::vector<double> scatter = {0, 0, -1.5, 0.4, 1.1, 0.3, 2.0, 1.2};
  EXPECT_EQ(HopsInOrder(scatter, 0, {2, 0, 3, 1}), (std::vector<int32_t>{0, 1, 1, 2}));
}

TEST(ViewTree, RejectsWhatItCannotHold) {
  double xy[2 * (kMaxTreePoints + 1)] = {};
  int32_t parent[kMaxTreePoints + 1], hops[kMaxTreePoints + 1];
  EXPECT_FALSE(ViewTree(xy, 1, 2, 0, parent, hops));
  EXPECT_FALSE(ViewTree(xy, kMaxTreePoints + 1, 2, 0, parent, hops));
  EXPECT_FALSE(ViewTree(xy, 3, 2, 3, parent, hops));
  EXPECT_FALSE(ViewTree(xy, 3, 4, 0, parent, hops));
  EXPECT_TRUE(ViewTree(xy, 3, 2, 1, parent, hops));  // three at one place: still a tree
  EXPECT_EQ(hops[1], 0);
  EXPECT_EQ(parent[1], -1);
}

}  // namespace
}  // namespace lb
