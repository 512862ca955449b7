// Boykov-Kolmogorov max-flow ("An experimental comparison of min-cut/max-flow algorithms", PAMI
// 2004) written for an implicit grid: two search trees grow from the terminals, an s-t path is
// augmented as soon as they touch, and the nodes cut off by saturated arcs look for a new parent
// in their own tree before they are freed. Time stamps and distances keep the trees shallow.
//
// The passes before the search, which set the nodes up, are in grid_maxflow_setup.cc.
//
// The padding rows and the edge arcs hold 0 forever: flow only moves along arcs with residual
// capacity, and a parent is only ever linked through one, so neither can become a tree link.
#include "algo/depth/grid_maxflow.h"

#include <cstddef>
#include <cstring>

#include "algo/depth/grid_maxflow_setup.h"

namespace lb {

void GridMaxflow::Carve(Arena& arena, int32_t max_width, int32_t max_height, size_t spare_bytes,
                        int32_t spare_width, int32_t spare_height) {
  max_nodes_ = max_width * max_height;
  max_width_ = max_width;
  // A graph takes its nodes and three rows (Begin: the padding rows and the staged rows' lead).
  const size_t own = static_cast<size_t>(max_nodes_) + 3 * static_cast<size_t>(max_width);
  const size_t lent = static_cast<size_t>(spare_width) * spare_height +
                      3 * static_cast<size_t>(spare_width) +
                      (spare_bytes + sizeof(Node) - 1) / sizeof(Node);
  storage_nodes_ = spare_bytes > 0 && lent > own ? lent : own;
  storage_ = arena.Allocate<Node>(storage_nodes_);
  orphans_ = arena.Allocate<int32_t>(static_cast<size_t>(max_nodes_));
  queue_ = arena.Allocate<int32_t>(static_cast<size_t>(max_nodes_) + kQueueSlack);
  live_ = arena.Allocate<int32_t>(2 * static_cast<size_t>(max_height));
  // The row kernel of the passes before the search, for this CPU (algo/core/cpu.h).
  const gmf::Kernels* simd = gmf::SimdKernels();
  kernels_ = simd != nullptr ? simd : &gmf::kReference;
}

uint8_t* GridMaxflow::Spare(int32_t width, int32_t height, size_t* bytes) const {
  const int64_t used = int64_t{width} * height + 3 * int64_t{width};
  const int64_t total = static_cast<int64_t>(storage_nodes_);
  *bytes =
      storage_ != nullptr && used < total ? sizeof(Node) * static_cast<size_t>(total - used) : 0;
  return *bytes > 0 ? reinterpret_cast<uint8_t*>(storage_ + used) : nullptr;
}

void GridMaxflow::Start(int32_t width, int32_t height) {
  width_ = width;
  height_ = height;
  count_ = width * height;
  nodes_ = storage_ + width;
  offset_[kRight] = 1;
  offset_[kLeft] = -1;
  offset_[kDown] = width;
  offset_[kUp] = -width;
  flow_ = 0;
  queue_head_ = queue_count_ = 0;
}

void GridMaxflow::Begin(int32_t width, int32_t height) {
  Start(width, height);
  // The padding row above; the one below is written when the staged rows are spent (Prepare).
  memset(static_cast<void*>(storage_), 0, sizeof(Node) * static_cast<size_t>(width));
  const size_t stage_at = 48 * static_cast<size_t>(width);
  stage_base_ = reinterpret_cast<int32_t*>(reinterpret_cast<uint8_t*>(storage_) + stage_at);
  stage_ = stage_base_;
  stage_width_ = width;
  staged_ = true;
}

void GridMaxflow::Truncate(int32_t height) {
  height_ = height;
  count_ = width_ * height;
}

void GridMaxflowProbe::Reset(GridMaxflow& mf, int32_t width, int32_t height) {
  mf.Start(width, height);
  mf.staged_ = false;
  memset(static_cast<void*>(mf.storage_), 0,
         sizeof(GridMaxflow::Node) * static_cast<size_t>(mf.count_ + 2 * width));
  for (int32_t y = 0; y < height; ++y) {
    mf.live_[2 * y] = 0;
    mf.live_[2 * y + 1] = width;
  }
}

void GridMaxflow::Activate(int32_t p) {
  Node& n = nodes_[p];
  if (n.bits & kQueuedBit) return;
  n.bits |= kQueuedBit;
  int32_t slot = queue_head_ + queue_count_;
  if (slot >= max_nodes_) slot -= max_nodes_;
  queue_[slot] = p;
  ++queue_count_;
}

int32_t GridMaxflow::NextActive() {
  // Far enough ahead to hide a miss, near enough that the lines are still cached when used.
  constexpr int32_t kAhead = 8;
  while (queue_count_ > 0) {
    const int32_t p = queue_[queue_head_];
    if (queue_count_ > kAhead) {
      int32_t slot = queue_head_ + kAhead;
      if (slot >= max_nodes_) slot -= max_nodes_;
      const Node* ahead = nodes_ + queue_[slot];
      __builtin_prefetch(ahead);
      __builtin_prefetch(ahead - width_);
      __builtin_prefetch(ahead + width_);
    }
    queue_head_ = queue_head_ + 1 == max_nodes_ ? 0 : queue_head_ + 1;
    --queue_count_;
    Node& n = nodes_[p];
    n.bits &= static_cast<uint8_t>(~kQueuedBit);
    if (TreeOf(n) != kFree) return p;
  }
  return kNotActive;
}

void GridMaxflow::PushOrphan(int32_t p) {
  SetParent(nodes_[p], kOrphan);
  int32_t slot = orphan_head_ + orphan_count_;
  if (slot >= max_nodes_) slot -= max_nodes_;
  orphans_[slot] = p;
  ++orphan_count_;
}

// s_node is in the source tree, its neighbour in direction `dir` in the sink tree. The walks
// to the roots that find the bottleneck record the paths' first nodes, so the updates that follow
// are independent steps instead of another chain of dependent loads.
void GridMaxflow::Augment(int32_t s_node, int dir) {
  const int32_t t_node = s_node + offset_[dir];
  int32_t bottleneck = nodes_[s_node].cap[dir];
  // Source side: arcs parent -> child, up to the root's source capacity.
  int32_t s_len = 0, p = s_node;
  for (;;) {
    const Node& n = nodes_[p];
    const uint8_t np = ParentOf(n);
    if (np == kTerminal) break;
    path_[s_len < kPath ? s_len : kPath] = p;
    ++s_len;
    const int32_t parent = p + offset_[np];
    const int32_t c = nodes_[parent].cap[np ^ 1];
    bottleneck = c < bottleneck ? c : bottleneck;
    p = parent;
  }
  const int32_t s_root = p;
  bottleneck = nodes_[s_root].tcap < bottleneck ? nodes_[s_root].tcap : bottleneck;
  // Sink side: arcs child -> parent, down to the root's sink capacity.
  int32_t* const t_path = path_ + kPath + 1;
  int32_t t_len = 0;
  for (p = t_node;;) {
    const Node& n = nodes_[p];
    const uint8_t np = ParentOf(n);
    if (np == kTerminal) break;
    t_path[t_len < kPath ? t_len : kPath] = p;
    ++t_len;
    const int32_t c = n.cap[np];
    bottleneck = c < bottleneck ? c : bottleneck;
    p += offset_[np];
  }
  const int32_t t_root = p;
  bottleneck = -nodes_[t_root].tcap < bottleneck ? -nodes_[t_root].tcap : bottleneck;

  nodes_[s_node].cap[dir] = static_cast<uint16_t>(nodes_[s_node].cap[dir] - bottleneck);
  nodes_[t_node].cap[dir ^ 1] = static_cast<uint16_t>(nodes_[t_node].cap[dir ^ 1] + bottleneck);
  // Paths longer than the record go on by walking.
  auto source_step = [&](int32_t q) {
    Node& n = nodes_[q];
    const int d = ParentOf(n);
    const int32_t parent = q + offset_[d];
    n.cap[d] = static_cast<uint16_t>(n.cap[d] + bottleneck);
    if ((nodes_[parent].cap[d ^ 1] -= bottleneck) == 0) PushOrphan(q);
    return parent;
  };
  p = s_root;
  for (int32_t i = 0; i < s_len && i < kPath; ++i) p = source_step(path_[i]);
  while (p != s_root) p = source_step(p);
  if ((nodes_[s_root].tcap -= bottleneck) == 0) PushOrphan(s_root);
  auto sink_step = [&](int32_t q) {
    Node& n = nodes_[q];
    const int d = ParentOf(n);
    const int32_t parent = q + offset_[d];
    nodes_[parent].cap[d ^ 1] = static_cast<uint16_t>(nodes_[parent].cap[d ^ 1] + bottleneck);
    if ((n.cap[d] -= bottleneck) == 0) PushOrphan(q);
    return parent;
  };
  p = t_root;
  for (int32_t i = 0; i < t_len && i < kPath; ++i) p = sink_step(t_path[i]);
  while (p != t_root) p = sink_step(p);
  if ((nodes_[t_root].tcap += bottleneck) == 0) PushOrphan(t_root);
  flow_ += bottleneck;
}

// Finds a new parent for orphan p in its own tree, or frees it and orphans its children.
template <bool kSource>
void GridMaxflow::Adopt(int32_t p) {
  Node& n = nodes_[p];
  const uint8_t tree = kSource ? kSourceTree : kSinkTree;
  int best_dir = -1;
  uint32_t best_dist = UINT32_MAX;
  for (int dir = 0; dir < 4; ++dir) {
    const int32_t q = p + offset_[dir];
    Node& first = nodes_[q];
    if (TreeOf(first) != tree) continue;
    // The arc that would carry flow from the new parent: q->p in the source tree, p->q in the sink.
    const int32_t c = kSource ? first.cap[dir ^ 1] : n.cap[dir];
    if (c <= 0) continue;
    // Walk up from q: does it reach the terminal without passing through an orphan?
    uint32_t d = 0;
    bool valid = false;
    const uint16_t now = static_cast<uint16_t>(time_);
    for (int32_t j = q;;) {
      Node& m = nodes_[j];
      if (m.ts == now) {
        d += m.dist;
        valid = true;
        break;
      }
      ++d;
      const uint8_t mp = ParentOf(m);
      if (mp == kTerminal) {
        m.ts = now;
        m.dist = 1;
        valid = true;
        break;
      }
      if (mp == kOrphan) break;
      j += offset_[mp];
    }
    if (!valid) continue;
    if (d < best_dist) {
      best_dist = d;
      best_dir = dir;
    }
    // Record the verified distances along the path so later walks stop early.
    for (int32_t j = q; nodes_[j].ts != now;) {
      Node& m = nodes_[j];
      m.ts = now;
      m.dist = static_cast<uint8_t>(d > 0xff ? 0xff : d);
      --d;
      j += offset_[ParentOf(m)];
    }
  }
  if (best_dir >= 0) {
    SetParent(n, static_cast<uint8_t>(best_dir));
    n.ts = static_cast<uint16_t>(time_);
    n.dist = static_cast<uint8_t>(best_dist + 1 > 0xff ? 0xff : best_dist + 1);
    return;
  }
  // No parent: p leaves its tree. Neighbours that could feed it become active again, and its
  // children become orphans.
  for (int dir = 0; dir < 4; ++dir) {
    const int32_t q = p + offset_[dir];
    Node& m = nodes_[q];
    if (TreeOf(m) != tree) continue;
    const int32_t c = kSource ? m.cap[dir ^ 1] : n.cap[dir];
    if (c > 0) Activate(q);
    if (ParentOf(m) == (dir ^ 1)) PushOrphan(q);
  }
  n.bits = static_cast<uint8_t>(n.bits & ~0x18);
}

// Scans p's arcs out of its tree: claims free neighbours, and on touching the other tree returns
// true with the touching arc as (source-side node, direction).
template <bool kSource>
bool GridMaxflow::Grow(int32_t p, int32_t* s_node, int* s_dir) {
  Node& n = nodes_[p];
  const uint8_t tree = kSource ? kSourceTree : kSinkTree;
  for (int dir = 0; dir < 4; ++dir) {
    const int32_t q = p + offset_[dir];
    Node& m = nodes_[q];
    const int32_t c = kSource ? n.cap[dir] : m.cap[dir ^ 1];
    if (c <= 0) continue;
    const uint8_t mt = TreeOf(m);
    if (mt == kFree) {
      m.bits = static_cast<uint8_t>((m.bits & kQueuedBit) | (tree << 3) | (dir ^ 1));
      m.ts = n.ts;
      m.dist = static_cast<uint8_t>(n.dist == 0xff ? 0xff : n.dist + 1);
      Activate(q);
    } else if (mt != tree) {
      *s_node = kSource ? p : q;
      *s_dir = kSource ? dir : (dir ^ 1);
      return true;
    }
    // (A node of p's own tree keeps its parent even when p is closer to the terminal: on the
    // depth stage's graphs, moving it under p cost more than the shorter paths saved.)
  }
  return false;
}

int64_t GridMaxflow::Solve() {
  Prepare();
  orphan_head_ = orphan_count_ = 0;
  time_ = first_time_;

  int32_t current = kNotActive;
  for (;;) {
    if (current == kNotActive || TreeOf(nodes_[current]) == kFree) current = NextActive();
    if (current == kNotActive) break;
    const int32_t p = current;
    int32_t touch_s = 0;
    int touch_dir = 0;
    const bool touched = TreeOf(nodes_[p]) == kSourceTree ? Grow<true>(p, &touch_s, &touch_dir)
                                                          : Grow<false>(p, &touch_s, &touch_dir);
    if (!touched) {
      current = kNotActive;
      continue;
    }
    if (++time_ == 0x10000) {
      // The stamps are 16 bits: none may match a new time by chance.
      for (int32_t i = 0; i < count_; ++i) nodes_[i].ts = 0;
      time_ = 1;
    }
    Augment(touch_s, touch_dir);
    while (orphan_count_ > 0) {
      const int32_t o = orphans_[orphan_head_];
      orphan_head_ = orphan_head_ + 1 == max_nodes_ ? 0 : orphan_head_ + 1;
      --orphan_count_;
      if (TreeOf(nodes_[o]) == kSourceTree) {
        Adopt<true>(o);
      } else {
        Adopt<false>(o);
      }
    }
    // Keep growing from p while it is still in a tree: it may touch the other tree again.
  }
  return flow_;
}

}  // namespace lb
