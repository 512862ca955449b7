// Boykov-Kolmogorov max-flow on an implicit 4-connected grid: node p = y * width + x, arcs to the
// right, left, down and up neighbours found by arithmetic, so there are no adjacency lists. All
// node storage is carved once for the largest grid and reused by every expansion move (Begin).
// A zeroed row above and below the grid, and arcs across the left and right edges that stay 0
// (the last node of a row and the first of the next see each other through them), let every
// visit look at all four neighbours without a boundary test.
//
// A node is 16 bytes, so that a cache line holds four and the search's neighbour visits miss
// half as often: arcs are 16 bits, and an arc's capacity plus its sister's must stay within
// kMaxArc (a residual never exceeds that sum); terminal balances are int32 within kMaxCapacity;
// flow totals are int64.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "algo/core/arena.h"

namespace lb {

struct GridMaxflowRows;  // what InitRow reads (grid_maxflow_setup.h)
namespace gmf {
struct Kernels;  // the row kernel InitRow runs (grid_maxflow_setup.h)
}

class GridMaxflow {
 public:
  static constexpr int32_t kMaxCapacity = 1 << 28;
  static constexpr int32_t kMaxArc = 0xffff;
  // Arc directions; the sister of arc (p, d) is (neighbour(p, d), d ^ 1).
  enum Dir : uint8_t { kRight = 0, kLeft = 1, kDown = 2, kUp = 3 };

  // Carves node storage for grids of up to max_width x max_height nodes, and enough more that
  // graphs of at most spare_width x spare_height nodes leave spare_bytes of it Spare.
  void Carve(Arena& arena, int32_t max_width, int32_t max_height, size_t spare_bytes = 0,
             int32_t spare_width = 0, int32_t spare_height = 0);

  // Starts a new graph of width x height nodes whose every node the caller then sets once with
  // SetNode, row by row, calling RowDone after each row (no clearing pass).
  void Begin(int32_t width, int32_t height);
  // Sets node p (of the row after the last RowDone): its terminal balance (positive: source->p,
  // negative: p->sink) and its arcs to the right and down neighbours, which must be 0 in the
  // last column and the last row; the sister arcs from those neighbours are 0. The values go to
  // the row's staging block (three dense rows), not to the node: the passes before the search
  // read them densely and write each node once.
  void SetNode(int32_t p, int32_t balance, int32_t cap_right, int32_t cap_down) {
    int32_t* s = stage_ + p;
    s[0] = balance;
    s[stage_width_] = cap_right;
    s[2 * stage_width_] = cap_down;
  }
  // SetNode's three values of nodes p, p + 1, ... written by the caller straight into the
  // staging rows: node p + i's balance at [i], cap right at [i + *stride], cap down at
  // [i + 2 * *stride], within the row after the last RowDone.
  int32_t* Staged(int32_t p, ptrdiff_t* stride) const {
    *stride = stage_width_;
    return stage_ + p;
  }
  // A node with no balance and no arcs: what SetNode(p, 0, 0, 0) gives. Outside the columns
  // RowDone names, the passes before the search write it as the search's free node without
  // reading what was set.
  void SetIdle(int32_t p) { SetNode(p, 0, 0, 0); }
  // Every node of rows 0..y is set. With x0..x1: row y's nodes outside columns x0..x1-1 were set
  // with SetIdle, and the passes before the search skip them.
  void RowDone(int32_t y) { RowDone(y, 0, width_); }
  void RowDone(int32_t y, int32_t x0, int32_t x1) {
    live_[2 * y] = x0;
    live_[2 * y + 1] = x1;
    // Node p = y' * width + x of the next row y' = y + 1 is staged at 4 * width * y' + x.
    stage_ = stage_base_ + 3 * stage_width_ * (y + 1);
  }

  // Ends the graph after its first `height` rows (all RowDone), as if it had been begun so.
  void Truncate(int32_t height);

  // Computes the maximum flow.
  int64_t Solve();

  // After Solve: true when p is on the source side of the minimum cut.
  bool InSource(int32_t p) const { return TreeOf(nodes_[p]) == kSourceTree; }

  // Node storage that graphs of at most width x height nodes never touch, lent to the caller
  // until a larger graph begins: its size in bytes, and where it starts (nullptr when none).
  uint8_t* Spare(int32_t width, int32_t height, size_t* bytes) const;

  int32_t width() const { return width_; }
  int32_t height() const { return height_; }

 private:
  friend struct GridMaxflowProbe;
  static constexpr uint8_t kFree = 0, kSourceTree = 1, kSinkTree = 2;
  static constexpr uint8_t kTerminal = 4, kOrphan = 5;  // parent values besides a Dir
  static constexpr int32_t kNotActive = -1;
  static constexpr int32_t kQueueSlack = 8;  // entries past max_nodes_ (InitRow's whole stores)

  struct Node {
    uint16_t cap[4] = {};  // residual capacity of the arc to each neighbour
    int32_t tcap = 0;      // residual terminal capacity: > 0 from the source, < 0 to the sink
    uint16_t ts = 0;       // time stamp of the last verified distance to a terminal
    uint8_t dist = 1;      // distance to the terminal (saturating; only a heuristic)
    // Parent (bits 0-2: a Dir, kTerminal or kOrphan), tree (3-4), queued (5).
    uint8_t bits = kOrphan;
  };
  static_assert(sizeof(Node) == 16);
  static constexpr uint8_t kQueuedBit = 0x20;  // in bits: in the active queue
  static uint8_t ParentOf(const Node& n) { return n.bits & 7; }
  static uint8_t TreeOf(const Node& n) { return (n.bits >> 3) & 3; }
  static void SetParent(Node& n, uint8_t parent) {
    n.bits = static_cast<uint8_t>((n.bits & ~7) | parent);
  }

  void Start(int32_t width, int32_t height);
  int32_t* StageRow(int32_t y) const {
    return stage_base_ + 4 * static_cast<ptrdiff_t>(width_) * y;
  }
  int64_t ChainRow(int32_t* tcap, int32_t* cap_right, int32_t* flow, int32_t n);
  void InitRow(int32_t y, const GridMaxflowRows& in);
  void InitNodeRow(int32_t y);
  void Common(int32_t y, int32_t* lo, int32_t* hi) const;
  void ColumnDemands();
  int64_t PushDown(int32_t y);
  void Prepare();
  void Activate(int32_t p);
  int32_t NextActive();
  template <bool kSource>
  bool Grow(int32_t p, int32_t* s_node, int* dir);
  void Augment(int32_t s_node, int dir);
  template <bool kSource>
  void Adopt(int32_t p);
  void PushOrphan(int32_t p);

  Node* storage_ = nullptr;
  Node* nodes_ = nullptr;       // storage_ + width_: the first grid node
  int32_t* orphans_ = nullptr;  // ring buffer of max_nodes_ entries (the chains scratch before)
  // FIFO of active nodes, max_nodes_ entries (a node is queued at most once): unlike a linked
  // list, it shows the nodes to come, which are prefetched.
  int32_t* queue_ = nullptr;
  int32_t* live_ = nullptr;  // per row, the columns x0, x1 Prepare looks at (RowDone)
  // Until Prepare, a graph's nodes are staged as 4 dense rows of width int32 per node row:
  // balance, cap right, cap down, and the column pass's demand (then the flow it sent down), as
  // many bytes as its node row. They lie in the graph's own node storage three rows on, from
  // byte 48 * width: node row y ends at byte 16 * width * (y + 2), the start of staged row
  // y - 1, the first one Prepare still reads when it writes node row y. So a graph takes its
  // nodes and three rows more; Spare starts after them.
  int32_t* stage_base_ = nullptr;
  int32_t* stage_ = nullptr;  // stage_base_ shifted so that stage_[p] is node p's balance
  // width_ again, in a type the staging stores cannot alias: SetNode's callers keep it in a
  // register instead of reloading it after every store.
  ptrdiff_t stage_width_ = 0;
  bool staged_ = false;  // false for GridMaxflowProbe's graphs, set on the nodes directly
  const gmf::Kernels* kernels_ = nullptr;  // picked once, at Carve
  // Augment's record of the two paths' first nodes (each kPath, and a slot that takes the rest).
  static constexpr int32_t kPath = 255;
  int32_t path_[2 * (kPath + 1)] = {};
  int32_t max_nodes_ = 0, max_width_ = 0;
  size_t storage_nodes_ = 0;  // what Carve allocated, in nodes
  int32_t width_ = 0, height_ = 0, count_ = 0;
  int32_t offset_[4] = {};  // node index step in each direction
  int32_t queue_head_ = 0, queue_count_ = 0;
  int32_t orphan_head_ = 0, orphan_count_ = 0;
  int32_t time_ = 0;
  int32_t first_time_ = 0;  // what time_ starts from (GridMaxflowProbe::StartTime)
  int64_t flow_ = 0;
};

// Graphs the depth stage never builds, for the solver's tests (tests/algo/depth/maxflow_test.cc):
// arcs in both directions of a pair (together within kMaxArc) and terminal capacities on both
// sides of a node, set in any order. Reset starts a graph of width x height nodes, all capacities
// 0; AddTerminal adds source->p and p->sink (both >= 0, their common part routed at once and
// counted by Solve); AddEdge adds to the arc p->q and its sister q->p, q the neighbour of p in
// direction `dir` (inside the grid).
struct GridMaxflowProbe {
  static void Reset(GridMaxflow& mf, int32_t width, int32_t height);
  static void AddTerminal(GridMaxflow& mf, int32_t p, int32_t cap_source, int32_t cap_sink) {
    mf.flow_ += cap_source < cap_sink ? cap_source : cap_sink;
    mf.nodes_[p].tcap += cap_source - cap_sink;
  }
  static void AddEdge(GridMaxflow& mf, int32_t p, GridMaxflow::Dir dir, int32_t cap_pq,
                      int32_t cap_qp) {
    uint16_t& pq = mf.nodes_[p].cap[dir];
    uint16_t& qp = mf.nodes_[p + mf.offset_[dir]].cap[dir ^ 1];
    pq = static_cast<uint16_t>(pq + cap_pq);
    qp = static_cast<uint16_t>(qp + cap_qp);
  }
  // After Solve: the residual capacity of the arc from p in direction `dir`.
  static int32_t Residual(const GridMaxflow& mf, int32_t p, GridMaxflow::Dir dir) {
    return mf.nodes_[p].cap[dir];
  }
  // The time stamp the next Solve starts from (0 in the product): near 0xffff, the stamps wrap
  // within a small graph's search.
  static void StartTime(GridMaxflow& mf, int32_t time) { mf.first_time_ = time; }
  static int32_t Time(const GridMaxflow& mf) { return mf.time_; }
  // Whether the passes before the search may use the SIMD twin of their row kernel that the CPU
  // runs (grid_maxflow_setup.h; Carve turns it on): off, they take the C reference, which must
  // give the same nodes.
  static void UseSimd(GridMaxflow& mf, bool on);
  // Fills all node storage with `byte`, as if another graph had left garbage everywhere: a caller
  // that sets only the nodes its graph can reach must then still get the same cut.
  static void Poison(GridMaxflow& mf, uint8_t byte) {
    memset(static_cast<void*>(mf.storage_), byte, sizeof(GridMaxflow::Node) * mf.storage_nodes_);
  }
};

}  // namespace lb
