#include "algo/motion/view_tree.h"

namespace lb {

bool ViewTree(const double* p, int32_t count, int32_t dims, int32_t root, int32_t* parent,
              int32_t* hops) {
  if (count < 2 || count > kMaxTreePoints || dims < 1 || dims > 3 || root < 0 || root >= count) {
    return false;
  }
  auto distance2 = [&](int32_t i, int32_t j) {
    double d2 = 0;
    for (int32_t k = 0; k < dims; ++k) {
      const double d = p[i * dims + k] - p[j * dims + k];
      d2 += d * d;
    }
    return d2;
  };
  bool joined[kMaxTreePoints] = {};
  double reach[kMaxTreePoints];  // squared distance to the tree, for the points outside it
  for (int32_t i = 0; i < count; ++i) {
    parent[i] = i == root ? -1 : root;
    hops[i] = 0;
    reach[i] = distance2(root, i);
  }
  joined[root] = true;
  for (int32_t edge = 1; edge < count; ++edge) {
    int32_t next = -1;
    for (int32_t i = 0; i < count; ++i) {
      if (!joined[i] && (next < 0 || reach[i] < reach[next])) next = i;
    }
    joined[next] = true;
    hops[next] = hops[parent[next]] + 1;
    for (int32_t i = 0; i < count; ++i) {
      const double d2 = distance2(next, i);
      if (!joined[i] && d2 < reach[i]) {
        reach[i] = d2;
        parent[i] = next;
      }
    }
  }
  return true;
}

}  // namespace lb
