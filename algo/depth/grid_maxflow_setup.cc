// GridMaxflow's passes before the search (grid_maxflow.h), over the staged rows: excess moves
// down the columns toward the deficits it can reach, then along each row, and each node row is
// written once, a row behind, by the row kernel of the table Carve picked (grid_maxflow_setup.h):
// the C reference here, its SIMD twins in grid_maxflow_setup_avx2.cc and _neon.cc.
#include "algo/depth/grid_maxflow_setup.h"

#include <cstddef>
#include <cstring>

#include "algo/core/clones.h"
#include "algo/core/cpu.h"
#include "algo/depth/grid_maxflow.h"

namespace lb {
namespace gmf {

void InitNodeC(const GridMaxflowRows& in, uint8_t* row, int32_t x, int32_t left_tcap,
               int32_t left_right, int32_t left_flow, int32_t base, int32_t* queue,
               int32_t* count) {
  const int32_t t = in.tcap[x], right = in.cap_right[x], down = in.cap_down[x];
  const int32_t up = in.flow_in[x];
  const uint32_t caps[2] = {static_cast<uint32_t>(right) | static_cast<uint32_t>(left_flow) << 16,
                            static_cast<uint32_t>(down) | static_cast<uint32_t>(up) << 16};
  uint32_t bits = kOrphan;
  if (t > 0) {
    bits = kTerminal | (kSourceTree << 3);
    if ((right > 0 && in.tcap[x + 1] <= 0) || (left_flow > 0 && left_tcap <= 0) ||
        (down > 0 && in.down_tcap[x] <= 0) || (up > 0 && in.up_tcap[x] <= 0)) {
      bits |= kQueuedBit;
    }
  } else if (t < 0) {
    bits = kTerminal | (kSinkTree << 3);
    if ((in.flow_right[x] > 0 && in.tcap[x + 1] >= 0) || (left_right > 0 && left_tcap >= 0) ||
        (in.flow_out[x] > 0 && in.down_tcap[x] >= 0) ||
        (in.up_cap_down[x] > 0 && in.up_tcap[x] >= 0)) {
      bits |= kQueuedBit;
    }
  }
  const uint32_t last = (1u << 16) | bits << 24;  // ts 0, dist 1
  uint8_t* const out = row + 16 * static_cast<ptrdiff_t>(x);
  memcpy(out, caps, sizeof(caps));
  memcpy(out + 8, &t, sizeof(t));
  memcpy(out + 12, &last, sizeof(last));
  if (bits & kQueuedBit) queue[(*count)++] = base + x;
}

namespace {

int32_t InitNodesC(const GridMaxflowRows& in, uint8_t* row, int32_t x, int32_t x1, int32_t base,
                   int32_t* queue, int32_t* count) {
  for (; x < x1; ++x) {
    InitNodeC(in, row, x, in.tcap[x - 1], in.cap_right[x - 1], in.flow_right[x - 1], base, queue,
              count);
  }
  return x;
}

}  // namespace

const Kernels kReference = {InitNodesC};

const Kernels* SimdKernels() {
  // What the firmware read of this processor (algo/core/cpu.h): armhf's NEON only when the
  // kernel says the core has it.
  const CpuFeatures cpu = CurrentCpu();
  if (const Kernels* k = cpu.avx2 ? Avx2Kernels() : nullptr) return k;
  return cpu.neon ? NeonKernels() : nullptr;
}

}  // namespace gmf

void GridMaxflowProbe::UseSimd(GridMaxflow& mf, bool on) {
  const gmf::Kernels* simd = on ? gmf::SimdKernels() : nullptr;
  mf.kernels_ = simd != nullptr ? simd : &gmf::kReference;
}

namespace {

// The part of `want` that an arc of residual `cap` can carry: 0 when nothing is wanted.
inline int32_t Carry(int32_t want, int32_t cap) {
  return want <= 0 ? 0 : (want < cap ? want : cap);
}

// Whether any of p[0..3] is negative, or not 0: two 64-bit words, no vector compare.
bool AnyNegative4(const int32_t* p) {
  uint64_t a, b;
  memcpy(&a, p, sizeof(a));
  memcpy(&b, p + 2, sizeof(b));
  return ((a | b) & 0x8000000080000000u) != 0;
}
bool AnyNonzero4(const int32_t* p) {
  uint64_t a, b;
  memcpy(&a, p, sizeof(a));
  memcpy(&b, p + 2, sizeof(b));
  return (a | b) != 0;
}

// Whether any of p[0..3] is positive: the top bit of 0 - v is set just for v > 0 (|v| < 2^31).
bool AnyPositive4(const int32_t* p) {
  uint32_t u[4];
  memcpy(u, p, sizeof(u));
  return (((0u - u[0]) | (0u - u[1]) | (0u - u[2]) | (0u - u[3])) >> 31) != 0;
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
  // First what the nodes right of x still lack that the arc x -> x + 1 can carry: nothing while
  // nothing is lacking further right and the node right of x has no deficit, which most of a
  // row is, skipped four at a time.
  flow[n - 1] = 0;
  int32_t want = 0;   // flow[x + 1]
  int32_t first = n;  // the first x where something is wanted
  for (int32_t x = n - 2; x >= 0;) {
    if (want == 0) {
      for (; x >= 3 && !AnyNegative4(tcap + x - 2); x -= 4) memset(flow + x - 3, 0, 16);
      for (; x >= 0 && tcap[x + 1] >= 0; --x) flow[x] = 0;
      if (x < 0) break;
    }
    want = Carry(want - tcap[x + 1], cap_right[x]);
    flow[x] = want;
    first = want > 0 ? x : first;
    --x;
  }
  // Then the excess moves where something is wanted (elsewhere the flow stays 0), from the
  // first such column: the words just stored left of it are not read back at once (a wide load
  // over two fresh narrow stores waits for them).
  int64_t met_total = 0;
  for (int32_t x = first;;) {
    for (; x + 4 <= n && !AnyNonzero4(flow + x); x += 4) {
    }
    for (; x + 1 < n && flow[x] == 0; ++x) {
    }
    if (x + 1 >= n) break;
    const int32_t d = tcap[x] < flow[x] ? tcap[x] : flow[x];
    if (d <= 0) {
      flow[x++] = 0;
      continue;
    }
    const int32_t met = -tcap[x + 1] < d ? -tcap[x + 1] : d;
    met_total += met > 0 ? met : 0;
    tcap[x] -= d;
    tcap[x + 1] += d;
    cap_right[x] -= d;
    flow[x++] = d;
  }
  return met_total;
}

// The first x in x0..x1-1 with tcap[x] > 0 (x1 when none), four at a time.
static int32_t FirstExcess(const int32_t* tcap, int32_t x0, int32_t x1) {
  int32_t x = x0;
  for (; x + 4 <= x1; x += 4) {
    if (AnyPositive4(tcap + x)) break;
  }
  while (x < x1 && tcap[x] <= 0) ++x;
  return x;
}

// One past the last x in x0..x1-1 with tcap[x] < 0 (x0 when none), four at a time.
static int32_t EndOfDeficits(const int32_t* tcap, int32_t x0, int32_t x1) {
  int32_t x = x1;
  for (; x - 4 >= x0; x -= 4) {
    if (AnyNegative4(tcap + x - 4)) break;
  }
  while (x > x0 && tcap[x - 1] >= 0) --x;
  return x;
}

// Writes node row y from its staged rows: roots where the balance is not 0, free nodes elsewhere
// (and outside the live columns, whatever was staged there). Only a root with a residual arc
// into another tree (or to a free node) can grow and is queued; the rest become active later if
// a neighbour leaves their tree (Adopt activates them). The first live node alone (its left
// neighbour is not live: no arc carries anything there), then the row kernel.
void GridMaxflow::InitRow(int32_t y, const GridMaxflowRows& in) {
  // The kernels' node format (grid_maxflow_setup.h).
  static_assert(sizeof(Node) == 4 * sizeof(int32_t) && offsetof(Node, tcap) == 8 &&
                offsetof(Node, ts) == 12 && offsetof(Node, dist) == 14 &&
                offsetof(Node, bits) == 15);
  static_assert(gmf::kTerminal == kTerminal && gmf::kOrphan == kOrphan &&
                gmf::kSourceTree == kSourceTree && gmf::kSinkTree == kSinkTree &&
                gmf::kQueuedBit == kQueuedBit);
  const int32_t w = width_;
  const int32_t x0 = live_[2 * y], x1 = live_[2 * y + 1];
  Node* const row = nodes_ + y * w;
  // Free nodes where the search may look: next to row y's live columns and below or above those
  // of rows y - 1 and y + 1 (tree nodes are live: an arc or a balance is only ever on a live
  // node), with the first and last nodes of a row, which neighbour the rows before and after.
  int32_t lo = x1 > x0 ? x0 - 1 : w, hi = x1 > x0 ? x1 + 1 : 0;
  for (int32_t k = y - 1; k <= y + 1; k += 2) {
    if (k < 0 || k >= height_ || live_[2 * k] >= live_[2 * k + 1]) continue;
    lo = live_[2 * k] < lo ? live_[2 * k] : lo;
    hi = live_[2 * k + 1] > hi ? live_[2 * k + 1] : hi;
    if (k < y && live_[2 * k + 1] == w) row[0] = Node{};
    if (k > y && live_[2 * k] == 0) row[w - 1] = Node{};
  }
  lo = lo > 0 ? lo : 0;
  hi = hi < w ? hi : w;
  // Elsewhere only what InSource reads: such a node has no arc and no balance, so it is on the
  // sink side.
  uint8_t* const tree = reinterpret_cast<uint8_t*>(row) + offsetof(Node, bits);
#pragma GCC unroll 4
  for (int32_t x = 0; x < lo; ++x) tree[16 * x] = kOrphan;
#pragma GCC unroll 4
  for (int32_t x = hi; x < w; ++x) tree[16 * x] = kOrphan;
  if (x1 <= x0) {
    for (int32_t x = lo; x < hi; ++x) row[x] = Node{};
    return;
  }
  for (int32_t x = lo; x < x0; ++x) row[x] = Node{};
  for (int32_t x = x1; x < hi; ++x) row[x] = Node{};
  int32_t count = queue_count_;
  uint8_t* const bytes = reinterpret_cast<uint8_t*>(row);
  const int32_t base = y * w;  // the queue is empty before the search: no wrap
  gmf::InitNodeC(in, bytes, x0, 0, 0, 0, base, queue_, &count);
  const int32_t x = kernels_->init_nodes(in, bytes, x0 + 1, x1, base, queue_, &count);
  if (x < x1) gmf::kReference.init_nodes(in, bytes, x, x1, base, queue_, &count);
  queue_count_ = count;
}

// The roots of a graph set on its nodes (GridMaxflowProbe), without the passes.
void GridMaxflow::InitNodeRow(int32_t y) {
  const int32_t w = width_;
  Node* row = nodes_ + y * w;
  for (int32_t x = 0; x < w; ++x) {
    Node& n = row[x];
    n.ts = 0;
    n.dist = 1;
    n.bits = n.tcap == 0
                 ? kOrphan
                 : static_cast<uint8_t>(kTerminal | ((n.tcap > 0 ? kSourceTree : kSinkTree) << 3));
    if (n.tcap != 0) Activate(y * w + x);
  }
}

// The columns lo..hi-1 common to the live columns of rows y and y + 1 (empty: lo == hi).
void GridMaxflow::Common(int32_t y, int32_t* lo, int32_t* hi) const {
  *lo = live_[2 * y] > live_[2 * y + 2] ? live_[2 * y] : live_[2 * y + 2];
  *hi = live_[2 * y + 1] < live_[2 * y + 3] ? live_[2 * y + 1] : live_[2 * y + 3];
  *hi = *hi > *lo ? *hi : *lo;
}

// The column chain's demands, bottom up: what the column below each node can take.
LB_CLONES_AVX2 void GridMaxflow::ColumnDemands() {
  const int32_t w = width_, h = height_;
  // Row y's demands (its 4th staged row), over the columns lo..hi-1 common to rows y and y + 1:
  // what row y + 1 lacks, plus what the column below it lacks where that pair has columns.
  int32_t below_lo = 0, below_hi = 0;
  for (int32_t y = h - 2; y >= 0; --y) {
    int32_t lo, hi;
    Common(y, &lo, &hi);
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
}

// The column chain's pushes from row y to row y + 1 (their demands are final); leaves in row y's
// 4th staged row what went down, 0 elsewhere in either row's live columns. Returns what met a
// deficit.
LB_CLONES_AVX2 int64_t GridMaxflow::PushDown(int32_t y) {
  const int32_t w = width_;
  int32_t* const tcap = StageRow(y);
  int32_t* const cap_down = tcap + 2 * w;
  int32_t* const down_flow = tcap + 3 * w;
  int32_t lo, hi;
  Common(y, &lo, &hi);
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
  // Elsewhere in either row's live columns nothing went down.
  const int32_t u0 = live_[2 * y] < live_[2 * y + 2] ? live_[2 * y] : live_[2 * y + 2];
  const int32_t u1 = live_[2 * y + 1] > live_[2 * y + 3] ? live_[2 * y + 1] : live_[2 * y + 3];
  const int32_t a = lo < hi ? lo : u0, b = lo < hi ? hi : u0;
  for (int32_t x = u0; x < a; ++x) down_flow[x] = 0;
  for (int32_t x = b; x < u1; ++x) down_flow[x] = 0;
  return row_met;
}

// Before any tree search, over the staged rows: excess moves down the columns toward the
// deficits it can reach (the demands bottom up, then the pushes top down), then along each row
// (ChainRow), and each node row is written once, a row behind. On the depth stage's graphs, the
// column chain before the row chain leaves the search far less to do (the same transformation
// as ChainRow's, over arcs down; an arc down has capacity only where both rows are live, so each
// row pair looks at the columns common to both). The column passes are independent across x:
// plain loops the compiler vectorizes.
void GridMaxflow::Prepare() {
  const int32_t w = width_, h = height_;
  if (!staged_) {
    for (int32_t y = 0; y < h; ++y) InitNodeRow(y);
    return;
  }
  if (h <= 0) return;
  // The padding row above is zeros, and so is any row of it read as int32.
  const int32_t* const zeros = reinterpret_cast<const int32_t*>(storage_);
  ColumnDemands();
  int64_t met = 0;
  GridMaxflowRows in{};
  in.up_tcap = in.up_cap_down = in.flow_in = zeros;  // above row 0: the padding row
  auto own_rows = [&](int32_t y) {
    in.tcap = StageRow(y);
    in.cap_right = in.tcap + w;
    in.cap_down = in.tcap + 2 * w;
  };
  for (int32_t y = 0; y < h; ++y) {
    int32_t* const tcap = StageRow(y);
    int32_t* const cap_right = tcap + w;
    if (y + 1 < h) met += PushDown(y);
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
      own_rows(y - 1);
      InitRow(y - 1, in);
      in.up_tcap = tcap - 4 * w;
      in.up_cap_down = tcap - 2 * w;
      in.flow_in = tcap - w;
    }
  }
  in.flow_out = in.down_tcap = zeros;
  in.flow_right = orphans_ + static_cast<ptrdiff_t>(h - 1) * w;
  own_rows(h - 1);
  InitRow(h - 1, in);
  flow_ += met;
  // The padding row below, over the staged rows now spent.
  memset(static_cast<void*>(nodes_ + count_), 0, sizeof(Node) * static_cast<size_t>(w));
}

}  // namespace lb
