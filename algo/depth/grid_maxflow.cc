// Boykov-Kolmogorov max-flow ("An experimental comparison of min-cut/max-flow algorithms", PAMI
// 2004) written for an implicit grid: two search trees grow from the terminals, an s-t path is
// augmented as soon as they touch, and the nodes cut off by saturated arcs look for a new parent
// in their own tree before they are freed. Time stamps and distances keep the trees shallow.
//
// The padding rows and the edge arcs hold 0 forever: flow only moves along arcs with residual
// capacity, and a parent is only ever linked through one, so neither can become a tree link.
#include "algo/depth/grid_maxflow.h"

#include <cstddef>
#include <cstring>

// The passes before the search in two copies, AVX2 and the baseline, chosen by the loader (the
// vector code of one C source; either gives the same nodes).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define LB_CLONES_AVX2 __attribute__((target_clones("avx2", "default")))
#else
#define LB_CLONES_AVX2
#endif

namespace lb {

void GridMaxflow::Carve(Arena& arena, int32_t max_width, int32_t max_height) {
  max_nodes_ = max_width * max_height;
  max_width_ = max_width;
  storage_ =
      arena.Allocate<Node>(static_cast<size_t>(max_nodes_) + 2 * static_cast<size_t>(max_width));
  orphans_ = arena.Allocate<int32_t>(static_cast<size_t>(max_nodes_));
  queue_ = arena.Allocate<int32_t>(static_cast<size_t>(max_nodes_));
  live_ = arena.Allocate<int32_t>(2 * static_cast<size_t>(max_height));
}

uint8_t* GridMaxflow::Spare(int32_t width, int32_t height, size_t* bytes) const {
  const int64_t used = int64_t{width} * height + 2 * int64_t{width};
  const int64_t total = int64_t{max_nodes_} + 2 * int64_t{max_width_};
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
  const size_t stage_at = 16 * static_cast<size_t>(count_) + 64 * static_cast<size_t>(width);
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
  if (n.queued) return;
  n.queued = 1;
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
    n.queued = 0;
    if (n.tree != kFree) return p;
  }
  return kNotActive;
}

void GridMaxflow::PushOrphan(int32_t p) {
  nodes_[p].parent = kOrphan;
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
    if (n.parent == kTerminal) break;
    path_[s_len < kPath ? s_len : kPath] = p;
    ++s_len;
    const int32_t parent = p + offset_[n.parent];
    const int32_t c = nodes_[parent].cap[n.parent ^ 1];
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
    if (n.parent == kTerminal) break;
    t_path[t_len < kPath ? t_len : kPath] = p;
    ++t_len;
    const int32_t c = n.cap[n.parent];
    bottleneck = c < bottleneck ? c : bottleneck;
    p += offset_[n.parent];
  }
  const int32_t t_root = p;
  bottleneck = -nodes_[t_root].tcap < bottleneck ? -nodes_[t_root].tcap : bottleneck;

  nodes_[s_node].cap[dir] -= bottleneck;
  nodes_[t_node].cap[dir ^ 1] += bottleneck;
  // Paths longer than the record go on by walking.
  auto source_step = [&](int32_t q) {
    Node& n = nodes_[q];
    const int d = n.parent;
    const int32_t parent = q + offset_[d];
    n.cap[d] += bottleneck;
    if ((nodes_[parent].cap[d ^ 1] -= bottleneck) == 0) PushOrphan(q);
    return parent;
  };
  p = s_root;
  for (int32_t i = 0; i < s_len && i < kPath; ++i) p = source_step(path_[i]);
  while (p != s_root) p = source_step(p);
  if ((nodes_[s_root].tcap -= bottleneck) == 0) PushOrphan(s_root);
  auto sink_step = [&](int32_t q) {
    Node& n = nodes_[q];
    const int d = n.parent;
    const int32_t parent = q + offset_[d];
    nodes_[parent].cap[d ^ 1] += bottleneck;
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
    if (first.tree != tree) continue;
    // The arc that would carry flow from the new parent: q->p in the source tree, p->q in the sink.
    const int32_t c = kSource ? first.cap[dir ^ 1] : n.cap[dir];
    if (c <= 0) continue;
    // Walk up from q: does it reach the terminal without passing through an orphan?
    uint32_t d = 0;
    bool valid = false;
    for (int32_t j = q;;) {
      Node& m = nodes_[j];
      if (m.ts == time_) {
        d += m.dist;
        valid = true;
        break;
      }
      ++d;
      if (m.parent == kTerminal) {
        m.ts = time_;
        m.dist = 1;
        valid = true;
        break;
      }
      if (m.parent == kOrphan) break;
      j += offset_[m.parent];
    }
    if (!valid) continue;
    if (d < best_dist) {
      best_dist = d;
      best_dir = dir;
    }
    // Record the verified distances along the path so later walks stop early.
    for (int32_t j = q; nodes_[j].ts != time_;) {
      Node& m = nodes_[j];
      m.ts = time_;
      m.dist = static_cast<uint16_t>(d > 0xffff ? 0xffff : d);
      --d;
      j += offset_[m.parent];
    }
  }
  if (best_dir >= 0) {
    n.parent = static_cast<uint8_t>(best_dir);
    n.ts = time_;
    n.dist = static_cast<uint16_t>(best_dist + 1 > 0xffff ? 0xffff : best_dist + 1);
    return;
  }
  // No parent: p leaves its tree. Neighbours that could feed it become active again, and its
  // children become orphans.
  for (int dir = 0; dir < 4; ++dir) {
    const int32_t q = p + offset_[dir];
    Node& m = nodes_[q];
    if (m.tree != tree) continue;
    const int32_t c = kSource ? m.cap[dir ^ 1] : n.cap[dir];
    if (c > 0) Activate(q);
    if (m.parent == (dir ^ 1)) PushOrphan(q);
  }
  n.tree = kFree;
}

namespace {

// The part of `want` that an arc of residual `cap` can carry: 0 when nothing is wanted.
inline int32_t Carry(int32_t want, int32_t cap) {
  return want <= 0 ? 0 : (want < cap ? want : cap);
}

}  // namespace

// Four int32 lanes (GCC's and Clang's vector extension: SSE2 on x86-64, NEON on ARM, plain
// code elsewhere); comparisons give -1 or 0 per lane.
typedef int32_t Lanes __attribute__((vector_size(16)));
typedef uint32_t ULanes __attribute__((vector_size(16)));

namespace {

Lanes Load(const int32_t* p) {
  Lanes v;
  memcpy(&v, p, sizeof(v));
  return v;
}

}  // namespace

// Moves excess rightward along a row of n staged nodes toward the deficits it can reach, and
// leaves in flow[x] what went from x to x + 1 (the residual of the arc back, which was 0).
// Moving excess d from a node to its neighbour over an arc of residual at least d leaves every
// cut's capacity as it was, so the minimum cuts are the same; returns what met a deficit.
// (Moving leftward as well cost more than it saved the tree search on the depth stage's graphs.)
// The caller passes the columns from the first excess to the last deficit: nothing moves
// outside them.
int64_t GridMaxflow::ChainRow(int32_t* tcap, int32_t* cap_right, int32_t* flow, int32_t n) {
  // First what the nodes right of x still lack that the arc x -> x + 1 can carry.
  flow[n - 1] = 0;
  for (int32_t x = n - 2; x >= 0; --x) flow[x] = Carry(flow[x + 1] - tcap[x + 1], cap_right[x]);
  int64_t met_total = 0;
  for (int32_t x = 0; x + 1 < n; ++x) {
    const int32_t d = tcap[x] < flow[x] ? tcap[x] : flow[x];
    if (d <= 0) {
      flow[x] = 0;
      continue;
    }
    const int32_t met = -tcap[x + 1] < d ? -tcap[x + 1] : d;
    met_total += met > 0 ? met : 0;
    tcap[x] -= d;
    tcap[x + 1] += d;
    cap_right[x] -= d;
    flow[x] = d;
  }
  return met_total;
}

// The first x in x0..x1-1 with tcap[x] > 0 (x1 when none), four at a time.
static int32_t FirstExcess(const int32_t* tcap, int32_t x0, int32_t x1) {
  int32_t x = x0;
  for (; x + 4 <= x1; x += 4) {
    const Lanes positive = Load(tcap + x) > 0;
    const Lanes any = positive | __builtin_shufflevector(positive, positive, 2, 3, 0, 1);
    if ((any[0] | any[1]) != 0) break;
  }
  while (x < x1 && tcap[x] <= 0) ++x;
  return x;
}

// One past the last x in x0..x1-1 with tcap[x] < 0 (x0 when none), four at a time.
static int32_t EndOfDeficits(const int32_t* tcap, int32_t x0, int32_t x1) {
  int32_t x = x1;
  for (; x - 4 >= x0; x -= 4) {
    const Lanes negative = Load(tcap + x - 4) < 0;
    const Lanes any = negative | __builtin_shufflevector(negative, negative, 2, 3, 0, 1);
    if ((any[0] | any[1]) != 0) break;
  }
  while (x > x0 && tcap[x - 1] >= 0) --x;
  return x;
}

// What InitRow reads besides row y's own staged rows: the final balances of rows y - 1 and
// y + 1, the residual arcs down from row y - 1 and the flows down into rows y and y + 1 (zeros
// for the padding rows), and row y's flows to the right (ChainRow).
struct GridMaxflow::RowInit {
  const int32_t* up_tcap;
  const int32_t* up_cap_down;
  const int32_t* flow_in;   // from row y - 1: the residual of row y's arcs up
  const int32_t* flow_out;  // to row y + 1: the residual of row y + 1's arcs up
  const int32_t* down_tcap;
  const int32_t* flow_right;  // the residual of the arc left of x + 1 (0 at the last live x)
};

// Node words as InitRow writes them: cap[4], then tcap, queued, ts and (little-endian) dist,
// parent, tree in one word.
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__);

// Writes node row y whole, from its staged rows: roots where the balance is not 0, free nodes
// elsewhere (and outside the live columns, whatever was staged there). Only a root with a
// residual arc into another tree (or to a free node) can grow and is queued; the rest become
// active later if a neighbour leaves their tree (Adopt activates them). Four nodes at a time,
// the first live node alone (its left neighbour is not live: no arc carries anything there).
LB_CLONES_AVX2 void GridMaxflow::InitRow(int32_t y, const RowInit& in) {
  static_assert(sizeof(Node) == 8 * sizeof(int32_t) && offsetof(Node, tcap) == 16 &&
                offsetof(Node, queued) == 20 && offsetof(Node, ts) == 24 &&
                offsetof(Node, dist) == 28 && offsetof(Node, parent) == 30 &&
                offsetof(Node, tree) == 31);
  const int32_t w = width_;
  const int32_t x0 = live_[2 * y], x1 = live_[2 * y + 1];
  const int32_t* const stage = StageRow(y);
  const int32_t* const tcap = stage;
  const int32_t* const cap_right = stage + w;
  const int32_t* const cap_down = stage + 2 * w;
  Node* const row = nodes_ + y * w;
  for (int32_t x = 0; x < x0; ++x) row[x] = Node{};
  for (int32_t x = x1 > x0 ? x1 : x0; x < w; ++x) row[x] = Node{};
  if (x1 <= x0) return;
  auto one = [&](int32_t x, int32_t left_tcap, int32_t left_right, int32_t left_flow) {
    Node& n = row[x];
    const int32_t t = tcap[x], right = cap_right[x], down = cap_down[x], up = in.flow_in[x];
    n.cap[kRight] = right;
    n.cap[kLeft] = left_flow;
    n.cap[kDown] = down;
    n.cap[kUp] = up;
    n.tcap = t;
    n.queued = 0;
    n.ts = 0;
    n.dist = 1;
    if (t == 0) {
      n.tree = kFree;
      n.parent = kOrphan;
      return;
    }
    n.parent = kTerminal;
    bool grows;
    if (t > 0) {
      n.tree = kSourceTree;
      grows = (right > 0 && tcap[x + 1] <= 0) || (left_flow > 0 && left_tcap <= 0) ||
              (down > 0 && in.down_tcap[x] <= 0) || (up > 0 && in.up_tcap[x] <= 0);
    } else {
      n.tree = kSinkTree;
      grows = (in.flow_right[x] > 0 && tcap[x + 1] >= 0) || (left_right > 0 && left_tcap >= 0) ||
              (in.flow_out[x] > 0 && in.down_tcap[x] >= 0) ||
              (in.up_cap_down[x] > 0 && in.up_tcap[x] >= 0);
    }
    if (grows) {
      n.queued = 1;
      queue_[queue_count_++] = y * w + x;  // the queue is empty before the search: no wrap
    }
  };
  one(x0, 0, 0, 0);
  int32_t x = x0 + 1;
  // Locals: the node stores below may alias `in` as far as the compiler knows.
  const int32_t *const flow_in = in.flow_in, *const flow_out = in.flow_out;
  const int32_t *const flow_right = in.flow_right, *const up_cap_down = in.up_cap_down;
  const int32_t *const down_tcap = in.down_tcap, *const up_tcap = in.up_tcap;
  uint8_t* out = reinterpret_cast<uint8_t*>(row + x);
  const Lanes zero = {0, 0, 0, 0};
  auto store = [&](int k, Lanes v) { memcpy(out + 16 * k, &v, sizeof(v)); };
  for (; x + 4 <= x1; x += 4, out += 4 * sizeof(Node)) {
    const Lanes t = Load(tcap + x), right = Load(cap_right + x), down = Load(cap_down + x);
    const Lanes up = Load(flow_in + x), left = Load(flow_right + x - 1);
    // The tests on signs are on the top bit of unsigned lanes (no overflow: every value is
    // within +-2^30): a > 0 is the top bit of 0 - a, b <= 0 that of b - 1, b >= 0 that of ~b.
    const ULanes ut = ULanes(t), t_left = ULanes(Load(tcap + x - 1));
    const ULanes t_right = ULanes(Load(tcap + x + 1)), t_down = ULanes(Load(down_tcap + x));
    const ULanes t_up = ULanes(Load(up_tcap + x));
    // A source root grows over an arc with residual into a node that is not a source root, a
    // sink root over an arc with residual from a node that is not a sink root.
    const ULanes source_grows =
        ((0u - ULanes(right)) & (t_right - 1u)) | ((0u - ULanes(left)) & (t_left - 1u)) |
        ((0u - ULanes(down)) & (t_down - 1u)) | ((0u - ULanes(up)) & (t_up - 1u));
    const ULanes sink_grows = ((0u - ULanes(Load(flow_right + x))) & ~t_right) |
                              ((0u - ULanes(Load(cap_right + x - 1))) & ~t_left) |
                              ((0u - ULanes(Load(flow_out + x))) & ~t_down) |
                              ((0u - ULanes(Load(up_cap_down + x))) & ~t_up);
    const Lanes queued = Lanes((((0u - ut) & source_grows) | (ut & sink_grows)) >> 31);
    const Lanes source = t > 0, sink = t < 0;
    // dist 1; parent kTerminal (4) on a root, else kOrphan (5); tree 1 or 2 on a root, else 0.
    const Lanes last = (1 | (kOrphan << 16)) + ((source | sink) << 16) +
                       ((source & (kSourceTree << 24)) | (sink & (kSinkTree << 24)));
    // Transposed to nodes: (right, left, down, up) and (tcap, queued, ts = 0, last) per node.
    const Lanes a0 = __builtin_shufflevector(right, left, 0, 4, 1, 5);
    const Lanes a1 = __builtin_shufflevector(right, left, 2, 6, 3, 7);
    const Lanes b0 = __builtin_shufflevector(down, up, 0, 4, 1, 5);
    const Lanes b1 = __builtin_shufflevector(down, up, 2, 6, 3, 7);
    const Lanes c0 = __builtin_shufflevector(t, queued, 0, 4, 1, 5);
    const Lanes c1 = __builtin_shufflevector(t, queued, 2, 6, 3, 7);
    const Lanes d0 = __builtin_shufflevector(zero, last, 0, 4, 1, 5);
    const Lanes d1 = __builtin_shufflevector(zero, last, 2, 6, 3, 7);
    store(0, __builtin_shufflevector(a0, b0, 0, 1, 4, 5));
    store(1, __builtin_shufflevector(c0, d0, 0, 1, 4, 5));
    store(2, __builtin_shufflevector(a0, b0, 2, 3, 6, 7));
    store(3, __builtin_shufflevector(c0, d0, 2, 3, 6, 7));
    store(4, __builtin_shufflevector(a1, b1, 0, 1, 4, 5));
    store(5, __builtin_shufflevector(c1, d1, 0, 1, 4, 5));
    store(6, __builtin_shufflevector(a1, b1, 2, 3, 6, 7));
    store(7, __builtin_shufflevector(c1, d1, 2, 3, 6, 7));
    const Lanes any = queued | __builtin_shufflevector(queued, queued, 2, 3, 0, 1);
    if ((any[0] | any[1]) != 0) {
      for (int32_t i = 0; i < 4; ++i) {
        if (queued[i] != 0) queue_[queue_count_++] = y * w + x + i;
      }
    }
  }
  for (; x < x1; ++x) one(x, tcap[x - 1], cap_right[x - 1], in.flow_right[x - 1]);
}

// The roots of a graph set on its nodes (GridMaxflowProbe), without the passes.
void GridMaxflow::InitNodeRow(int32_t y) {
  const int32_t w = width_;
  Node* row = nodes_ + y * w;
  for (int32_t x = 0; x < w; ++x) {
    Node& n = row[x];
    n.queued = 0;
    n.ts = 0;
    n.dist = 1;
    n.parent = n.tcap == 0 ? kOrphan : kTerminal;
    n.tree = n.tcap == 0 ? kFree : (n.tcap > 0 ? kSourceTree : kSinkTree);
    if (n.tcap != 0) Activate(y * w + x);
  }
}

// Before any tree search, over the staged rows: excess moves down the columns toward the
// deficits it can reach (the demands bottom up, then the pushes top down), then along each row
// (ChainRow), and each node row is written once, a row behind. On the depth stage's graphs, the
// column chain before the row chain leaves the search far less to do: on teddy, 0.66x the time
// of the row chain alone (the same transformation as ChainRow's, over arcs down; an arc down has
// capacity only where both rows are live, so each row pair looks at the columns common to both).
// The column passes are independent across x: plain loops the compiler vectorizes.
void GridMaxflow::Prepare() {
  const int32_t w = width_, h = height_;
  if (!staged_) {
    for (int32_t y = 0; y < h; ++y) InitNodeRow(y);
    return;
  }
  // The padding row above is zeros, and so is any row of it read as int32.
  const int32_t* const zeros = reinterpret_cast<const int32_t*>(storage_);
  auto common = [&](int32_t y, int32_t* lo, int32_t* hi) {
    *lo = live_[2 * y] > live_[2 * y + 2] ? live_[2 * y] : live_[2 * y + 2];
    *hi = live_[2 * y + 1] < live_[2 * y + 3] ? live_[2 * y + 1] : live_[2 * y + 3];
    *hi = *hi > *lo ? *hi : *lo;
  };
  // Row y's demands (its 4th staged row), over the columns lo..hi-1 common to rows y and y + 1:
  // what row y + 1 lacks, plus what the column below it lacks where that pair has columns.
  int32_t below_lo = 0, below_hi = 0;
  for (int32_t y = h - 2; y >= 0; --y) {
    int32_t lo, hi;
    common(y, &lo, &hi);
    const int32_t* const tcap_below = StageRow(y + 1);
    const int32_t* const demand_below = tcap_below + 3 * w;
    const int32_t* const cap_down = StageRow(y) + 2 * w;
    int32_t* const demand = StageRow(y) + 3 * w;
    const int32_t a = below_lo < lo ? lo : (below_lo > hi ? hi : below_lo);
    const int32_t b = below_hi < a ? a : (below_hi > hi ? hi : below_hi);
    for (int32_t x = lo; x < a; ++x) demand[x] = Carry(-tcap_below[x], cap_down[x]);
    for (int32_t x = a; x < b; ++x) {
      demand[x] = Carry(demand_below[x] - tcap_below[x], cap_down[x]);
    }
    for (int32_t x = b; x < hi; ++x) demand[x] = Carry(-tcap_below[x], cap_down[x]);
    below_lo = lo;
    below_hi = hi;
  }
  int64_t met = 0;
  RowInit in{};
  for (int32_t y = 0; y < h; ++y) {
    int32_t* const tcap = StageRow(y);
    int32_t* const cap_right = tcap + w;
    int32_t* const cap_down = tcap + 2 * w;
    int32_t* const down_flow = tcap + 3 * w;
    if (y + 1 < h) {
      int32_t lo, hi;
      common(y, &lo, &hi);
      int32_t* const tcap_below = StageRow(y + 1);
      int64_t row_met = 0;
      for (int32_t x = lo; x < hi; ++x) {
        const int32_t t = tcap[x], t_below = tcap_below[x];
        int32_t d = t < down_flow[x] ? t : down_flow[x];
        d = d > 0 ? d : 0;
        const int32_t m = -t_below < d ? -t_below : d;
        row_met += m > 0 ? m : 0;
        tcap[x] = t - d;
        tcap_below[x] = t_below + d;
        cap_down[x] -= d;
        down_flow[x] = d;
      }
      met += row_met;
      // Elsewhere in either row's live columns nothing went down.
      const int32_t u0 = live_[2 * y] < live_[2 * y + 2] ? live_[2 * y] : live_[2 * y + 2];
      const int32_t u1 = live_[2 * y + 1] > live_[2 * y + 3] ? live_[2 * y + 1] : live_[2 * y + 3];
      const int32_t a = lo < hi ? lo : u0, b = lo < hi ? hi : u0;
      for (int32_t x = u0; x < a; ++x) down_flow[x] = 0;
      for (int32_t x = b; x < u1; ++x) down_flow[x] = 0;
    }
    // Row y's balances are final after its row chain; row y - 1's nodes can be written.
    const int32_t x0 = live_[2 * y], x1 = live_[2 * y + 1];
    int32_t* const flow_right = orphans_ + static_cast<ptrdiff_t>(y) * w;  // free until the search
    // The row chain from the first excess to the last deficit; nothing moves elsewhere.
    const int32_t a = FirstExcess(tcap, x0, x1);
    int32_t b = a < x1 ? EndOfDeficits(tcap, a, x1) : a;
    if (b - a >= 2) {
      met += ChainRow(tcap + a, cap_right + a, flow_right + a, b - a);
    } else {
      b = a;
    }
    for (int32_t x = x0; x < a; ++x) flow_right[x] = 0;
    for (int32_t x = b; x < x1; ++x) flow_right[x] = 0;
    if (y >= 1) {
      in.flow_out = tcap - w;  // row y - 1's flows down
      in.down_tcap = tcap;
      in.flow_right = flow_right - w;
      InitRow(y - 1, in);
      in.up_tcap = tcap - 4 * w;
      in.up_cap_down = tcap - 2 * w;
      in.flow_in = tcap - w;
    } else {
      in.up_tcap = in.up_cap_down = in.flow_in = zeros;
    }
  }
  in.flow_out = in.down_tcap = zeros;
  in.flow_right = orphans_ + static_cast<ptrdiff_t>(h - 1) * w;
  InitRow(h - 1, in);
  flow_ += met;
  // The padding row below, over the staged rows now spent.
  memset(static_cast<void*>(nodes_ + count_), 0, sizeof(Node) * static_cast<size_t>(w));
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
    if (m.tree == kFree) {
      m.tree = tree;
      m.parent = static_cast<uint8_t>(dir ^ 1);
      m.ts = n.ts;
      m.dist = static_cast<uint16_t>(n.dist == 0xffff ? 0xffff : n.dist + 1);
      Activate(q);
    } else if (m.tree != tree) {
      *s_node = kSource ? p : q;
      *s_dir = kSource ? dir : (dir ^ 1);
      return true;
    }
    // (A node of p's own tree keeps its parent even when p is closer to the terminal: moving it
    // under p cost more than the shorter paths saved, on teddy's graphs 0.71x against 0.78x.)
  }
  return false;
}

int64_t GridMaxflow::Solve() {
  Prepare();
  orphan_head_ = orphan_count_ = 0;
  time_ = 0;

  int32_t current = kNotActive;
  for (;;) {
    if (current == kNotActive || nodes_[current].tree == kFree) current = NextActive();
    if (current == kNotActive) break;
    const int32_t p = current;
    int32_t touch_s = 0;
    int touch_dir = 0;
    const bool touched = nodes_[p].tree == kSourceTree ? Grow<true>(p, &touch_s, &touch_dir)
                                                       : Grow<false>(p, &touch_s, &touch_dir);
    if (!touched) {
      current = kNotActive;
      continue;
    }
    ++time_;
    Augment(touch_s, touch_dir);
    while (orphan_count_ > 0) {
      const int32_t o = orphans_[orphan_head_];
      orphan_head_ = orphan_head_ + 1 == max_nodes_ ? 0 : orphan_head_ + 1;
      --orphan_count_;
      if (nodes_[o].tree == kSourceTree) {
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
