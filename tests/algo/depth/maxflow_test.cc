// The grid max-flow against a slow textbook max-flow (Edmonds-Karp on a dense matrix) on
// thousands of random small grids, and the cut it reports against the flow it claims.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <deque>
#include <random>
#include <vector>

#include "algo/depth/grid_maxflow.h"

namespace lb {
namespace {

struct Graph {
  int32_t w = 0, h = 0;
  std::vector<int32_t> source, sink;  // per node
  std::vector<int32_t> right_fwd, right_bwd, down_fwd, down_bwd;
};

// Terminal capacities up to max_cap, arcs up to max_cap too but a pair's two together within
// GridMaxflow::kMaxArc (the arc back takes what is left when the arc forth took more).
Graph RandomGraph(std::mt19937& rng, int32_t w, int32_t h, int32_t max_cap) {
  Graph g;
  g.w = w;
  g.h = h;
  const size_t n = static_cast<size_t>(w * h);
  std::uniform_int_distribution<int32_t> cap(0, max_cap);
  std::uniform_int_distribution<int32_t> arc(0, std::min(max_cap, GridMaxflow::kMaxArc));
  std::bernoulli_distribution zero(0.3);
  for (auto* v : {&g.source, &g.sink, &g.right_fwd, &g.right_bwd, &g.down_fwd, &g.down_bwd}) {
    const bool terminal = v == &g.source || v == &g.sink;
    v->resize(n);
    for (auto& c : *v) c = zero(rng) ? 0 : (terminal ? cap(rng) : arc(rng));
  }
  for (size_t i = 0; i < n; ++i) {
    g.right_bwd[i] = std::min(g.right_bwd[i], GridMaxflow::kMaxArc - g.right_fwd[i]);
    g.down_bwd[i] = std::min(g.down_bwd[i], GridMaxflow::kMaxArc - g.down_fwd[i]);
  }
  return g;
}

// Edmonds-Karp on the explicit graph: node 0 is the source, 1 the sink, pixel p is p + 2. With
// `reachable`, also the pixels the source reaches in the residual graph of the maximum flow: the
// least source side of a minimum cut, the same for every maximum flow.
int64_t TextbookMaxflow(const Graph& g, std::vector<bool>* reachable = nullptr) {
  const int32_t n = g.w * g.h + 2;
  std::vector<int64_t> cap(static_cast<size_t>(n * n), 0);
  auto at = [&](int32_t a, int32_t b) -> int64_t& { return cap[static_cast<size_t>(a * n + b)]; };
  for (int32_t y = 0; y < g.h; ++y) {
    for (int32_t x = 0; x < g.w; ++x) {
      const int32_t p = y * g.w + x;
      at(0, p + 2) += g.source[p];
      at(p + 2, 1) += g.sink[p];
      if (x + 1 < g.w) {
        at(p + 2, p + 3) += g.right_fwd[p];
        at(p + 3, p + 2) += g.right_bwd[p];
      }
      if (y + 1 < g.h) {
        at(p + 2, p + 2 + g.w) += g.down_fwd[p];
        at(p + 2 + g.w, p + 2) += g.down_bwd[p];
      }
    }
  }
  int64_t flow = 0;
  for (;;) {
    std::vector<int32_t> prev(static_cast<size_t>(n), -1);
    prev[0] = 0;
    std::deque<int32_t> queue{0};
    while (!queue.empty() && prev[1] < 0) {
      const int32_t a = queue.front();
      queue.pop_front();
      for (int32_t b = 0; b < n; ++b) {
        if (prev[b] < 0 && at(a, b) > 0) {
          prev[b] = a;
          queue.push_back(b);
        }
      }
    }
    if (prev[1] < 0) {
      if (reachable != nullptr) {
        reachable->assign(static_cast<size_t>(g.w * g.h), false);
        for (int32_t p = 0; p < g.w * g.h; ++p) (*reachable)[p] = prev[p + 2] >= 0;
      }
      return flow;
    }
    int64_t push = INT64_MAX;
    for (int32_t b = 1; b != 0; b = prev[b]) push = std::min(push, at(prev[b], b));
    for (int32_t b = 1; b != 0; b = prev[b]) {
      at(prev[b], b) -= push;
      at(b, prev[b]) += push;
    }
    flow += push;
  }
}

// The capacity of the cut the solver reports, from the original capacities.
int64_t CutCapacity(const Graph& g, const GridMaxflow& mf) {
  int64_t cut = 0;
  for (int32_t y = 0; y < g.h; ++y) {
    for (int32_t x = 0; x < g.w; ++x) {
      const int32_t p = y * g.w + x;
      const bool s = mf.InSource(p);
      cut += s ? g.sink[p] : g.source[p];
      if (x + 1 < g.w) {
        const bool sq = mf.InSource(p + 1);
        if (s && !sq) cut += g.right_fwd[p];
        if (!s && sq) cut += g.right_bwd[p];
      }
      if (y + 1 < g.h) {
        const bool sq = mf.InSource(p + g.w);
        if (s && !sq) cut += g.down_fwd[p];
        if (!s && sq) cut += g.down_bwd[p];
      }
    }
  }
  return cut;
}

int64_t Solve(const Graph& g, GridMaxflow& mf) {
  using Probe = GridMaxflowProbe;
  Probe::Reset(mf, g.w, g.h);
  for (int32_t y = 0; y < g.h; ++y) {
    for (int32_t x = 0; x < g.w; ++x) {
      const int32_t p = y * g.w + x;
      Probe::AddTerminal(mf, p, g.source[p], g.sink[p]);
      if (x + 1 < g.w) Probe::AddEdge(mf, p, GridMaxflow::kRight, g.right_fwd[p], g.right_bwd[p]);
      if (y + 1 < g.h) Probe::AddEdge(mf, p, GridMaxflow::kDown, g.down_fwd[p], g.down_bwd[p]);
    }
  }
  return mf.Solve();
}

class MaxflowTest : public ::testing::Test {
 protected:
  static constexpr int32_t kMaxSide = 64;
  MaxflowTest() : memory_(Planned()), arena_(memory_.data(), memory_.size()) {
    mf_.Carve(arena_, kMaxSide, kMaxSide);
  }
  static size_t Planned() {
    Arena plan;
    GridMaxflow mf;
    mf.Carve(plan, kMaxSide, kMaxSide);
    return plan.used();
  }
  std::vector<uint8_t> memory_;
  Arena arena_;
  GridMaxflow mf_;
};

TEST_F(MaxflowTest, MatchesTextbookOnThousandsOfRandomGrids) {
  std::mt19937 rng(12345);
  std::uniform_int_distribution<int32_t> side(1, 7);
  for (int trial = 0; trial < 3000; ++trial) {
    const int32_t w = side(rng), h = side(rng);
    const int32_t max_cap = trial % 3 == 0 ? 3 : (trial % 3 == 1 ? 100 : 100000);
    const Graph g = RandomGraph(rng, w, h, max_cap);
    const int64_t expected = TextbookMaxflow(g);
    const int64_t flow = Solve(g, mf_);
    ASSERT_EQ(flow, expected) << "trial " << trial << " " << w << "x" << h;
    ASSERT_EQ(CutCapacity(g, mf_), expected) << "trial " << trial;
  }
}

// The depth stage's labels depend on which minimum cut is reported, not only on its capacity:
// the source side must be the least one (what the source reaches in the residual graph), which
// every maximum flow gives, so that a change of the solver's insides keeps the labels' bits.
TEST_F(MaxflowTest, SourceSideIsTheLeastMinimumCut) {
  std::mt19937 rng(4321);
  std::uniform_int_distribution<int32_t> side(1, 8);
  for (int trial = 0; trial < 2000; ++trial) {
    const int32_t w = side(rng), h = side(rng);
    // Small capacities make ties between minimum cuts common.
    const Graph g = RandomGraph(rng, w, h, trial % 2 == 0 ? 2 : 30);
    std::vector<bool> reachable;
    ASSERT_EQ(Solve(g, mf_), TextbookMaxflow(g, &reachable)) << "trial " << trial;
    for (int32_t p = 0; p < w * h; ++p) ASSERT_EQ(mf_.InSource(p), reachable[p]) << trial;
  }
}

TEST_F(MaxflowTest, LargerGridsAgreeAndStorageIsReused) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    const int32_t w = 12 + trial % 5, h = 10 + trial % 3;
    const Graph g = RandomGraph(rng, w, h, 50);
    const int64_t expected = TextbookMaxflow(g);
    ASSERT_EQ(Solve(g, mf_), expected) << "trial " << trial;
    ASSERT_EQ(CutCapacity(g, mf_), expected);
  }
}

TEST_F(MaxflowTest, ThinStripsAndZeroGraph) {
  std::mt19937 rng(99);
  for (int trial = 0; trial < 200; ++trial) {
    const bool row = trial & 1;
    const Graph g = RandomGraph(rng, row ? 40 : 1, row ? 1 : 40, 20);
    ASSERT_EQ(Solve(g, mf_), TextbookMaxflow(g));
  }
  Graph empty = RandomGraph(rng, 5, 5, 0);
  EXPECT_EQ(Solve(empty, mf_), 0);
}

// The streamed entry point (Begin, SetNode, RowDone, Truncate) as the depth stage uses it: arcs
// only to the right and down, none across the last column or row, empty rows left at the end.
TEST_F(MaxflowTest, StreamedRowsMatchTextbookAndEdgeBuiltCut) {
  std::mt19937 rng(2024);
  std::uniform_int_distribution<int32_t> side(1, 9);
  GridMaxflow edges;
  std::vector<uint8_t> memory(Planned());
  Arena arena(memory.data(), memory.size());
  edges.Carve(arena, kMaxSide, kMaxSide);
  for (int trial = 0; trial < 2000; ++trial) {
    const int32_t w = side(rng), h = side(rng), tail = trial % 3;
    Graph g = RandomGraph(rng, w, h, trial % 2 ? 5 : 1000);
    int64_t direct = 0;
    for (int32_t y = 0; y < h; ++y) {
      for (int32_t x = 0; x < w; ++x) {
        const int32_t p = y * w + x;
        g.right_bwd[p] = g.down_bwd[p] = 0;
        if (x + 1 == w) g.right_fwd[p] = 0;
        if (y + 1 == h) g.down_fwd[p] = 0;
        direct += std::min(g.source[p], g.sink[p]);
      }
    }
    mf_.Begin(w, h + tail);
    for (int32_t y = 0; y < h; ++y) {
      for (int32_t x = 0; x < w; ++x) {
        const int32_t p = y * w + x;
        mf_.SetNode(p, g.source[p] - g.sink[p], g.right_fwd[p], g.down_fwd[p]);
      }
      mf_.RowDone(y);
    }
    if (tail > 0) mf_.Truncate(h);
    const int64_t expected = TextbookMaxflow(g);
    ASSERT_EQ(mf_.Solve() + direct, expected) << "trial " << trial << " " << w << "x" << h;
    ASSERT_EQ(CutCapacity(g, mf_), expected) << "trial " << trial;
    // The source side of the minimum cut is unique: the edge-built solver reports the same one.
    ASSERT_EQ(Solve(g, edges), expected);
    for (int32_t p = 0; p < w * h; ++p) ASSERT_EQ(mf_.InSource(p), edges.InSource(p)) << trial;
  }
}

// As the depth stage builds its graphs: only some pixels are free (SetNode), the others idle
// (SetIdle), each row done with the columns from its first free node to its last, rows with no
// free node between others, arcs only between two free nodes. The flow, and the least source
// side against the same graph built arc by arc.
TEST_F(MaxflowTest, StreamedRowsWithIdleNodesMatchTextbook) {
  std::mt19937 rng(77);
  std::uniform_int_distribution<int32_t> side(1, 12);
  GridMaxflow edges;
  std::vector<uint8_t> memory(Planned());
  Arena arena(memory.data(), memory.size());
  edges.Carve(arena, kMaxSide, kMaxSide);
  for (int trial = 0; trial < 1500; ++trial) {
    const int32_t w = side(rng), h = side(rng);
    Graph g = RandomGraph(rng, w, h, trial % 2 ? 6 : 500);
    std::bernoulli_distribution free_draw(trial % 3 == 0 ? 0.9 : 0.5);
    std::vector<bool> free(static_cast<size_t>(w * h));
    for (size_t p = 0; p < free.size(); ++p) free[p] = free_draw(rng);
    int64_t direct = 0;
    for (int32_t y = 0; y < h; ++y) {
      for (int32_t x = 0; x < w; ++x) {
        const int32_t p = y * w + x;
        g.right_bwd[p] = g.down_bwd[p] = 0;
        if (x + 1 == w || !free[p] || !free[p + 1]) g.right_fwd[p] = 0;
        if (y + 1 == h || !free[p] || !free[p + w]) g.down_fwd[p] = 0;
        if (!free[p]) g.source[p] = g.sink[p] = 0;
        direct += std::min(g.source[p], g.sink[p]);
      }
    }
    mf_.Begin(w, h);
    for (int32_t y = 0; y < h; ++y) {
      int32_t first = w, last = -1;
      for (int32_t x = 0; x < w; ++x) {
        const int32_t p = y * w + x;
        if (!free[p]) {
          mf_.SetIdle(p);
          continue;
        }
        first = std::min(first, x);
        last = x;
        mf_.SetNode(p, g.source[p] - g.sink[p], g.right_fwd[p], g.down_fwd[p]);
      }
      mf_.RowDone(y, last < 0 ? 0 : first, last + 1);
    }
    std::vector<bool> reachable;
    const int64_t expected = TextbookMaxflow(g, &reachable);
    ASSERT_EQ(mf_.Solve() + direct, expected) << "trial " << trial << " " << w << "x" << h;
    ASSERT_EQ(CutCapacity(g, mf_), expected) << "trial " << trial;
    for (int32_t p = 0; p < w * h; ++p) ASSERT_EQ(mf_.InSource(p), reachable[p]) << trial;
    ASSERT_EQ(Solve(g, edges), expected);
  }
}

// Rows as wide as the solver's row kernels take (several steps of eight or four nodes, with the
// rest one by one), graphs truncated after Begin, storage full of garbage before each graph and
// only the nodes a free node can reach set (as the depth stage does): the flow and the least
// source side against the textbook, and the same residual on every arc whether the passes
// before the search ran the SIMD twin of their row kernel or the C reference.
TEST_F(MaxflowTest, WideStreamedRowsMatchTextbookWithAnyLanes) {
  std::mt19937 rng(31337);
  std::uniform_int_distribution<int32_t> width(9, 33), height(1, 6), tail(0, 3), byte(0, 255);
  GridMaxflow four;
  std::vector<uint8_t> memory(Planned());
  Arena arena(memory.data(), memory.size());
  four.Carve(arena, kMaxSide, kMaxSide);
  GridMaxflowProbe::UseSimd(four, false);
  for (int trial = 0; trial < 300; ++trial) {
    const int32_t w = width(rng), h = height(rng), extra = tail(rng);
    Graph g = RandomGraph(rng, w, h, trial % 2 ? 7 : 800);
    // Free pixels in runs, whole rows free now and then (first and last column live).
    std::vector<bool> free(static_cast<size_t>(w * h));
    for (int32_t y = 0; y < h; ++y) {
      const int mode = static_cast<int>(rng() % 3);
      const int32_t a = static_cast<int32_t>(rng() % static_cast<uint32_t>(w));
      const int32_t b = a + static_cast<int32_t>(rng() % static_cast<uint32_t>(w - a + 1));
      for (int32_t x = 0; x < w; ++x) {
        const bool in_run = x >= a && x < b;
        free[y * w + x] = mode == 0 ? true : (mode == 1 ? in_run : (in_run && rng() % 4 != 0));
      }
    }
    int64_t direct = 0;
    for (int32_t y = 0; y < h; ++y) {
      for (int32_t x = 0; x < w; ++x) {
        const int32_t p = y * w + x;
        g.right_bwd[p] = g.down_bwd[p] = 0;
        if (x + 1 == w || !free[p] || !free[p + 1]) g.right_fwd[p] = 0;
        if (y + 1 == h || !free[p] || !free[p + w]) g.down_fwd[p] = 0;
        if (!free[p]) g.source[p] = g.sink[p] = 0;
        direct += std::min(g.source[p], g.sink[p]);
      }
    }
    auto first_last = [&](int32_t y, int32_t* first, int32_t* last) {
      *first = w;
      *last = -1;
      for (int32_t x = 0; x < w; ++x) {
        if (free[y * w + x]) {
          *first = std::min(*first, x);
          *last = x;
        }
      }
    };
    for (GridMaxflow* mf : {&mf_, &four}) {
      GridMaxflowProbe::Poison(*mf, static_cast<uint8_t>(byte(rng)));
      mf->Begin(w, h + extra);
      for (int32_t y = 0; y < h; ++y) {
        // The nodes a free node can reach: free runs of rows y - 1..y + 1, one column either
        // side, and the row's first and last nodes.
        int32_t lo = w, hi = 0;
        for (int32_t k = std::max(0, y - 1); k <= std::min(h - 1, y + 1); ++k) {
          int32_t first, last;
          first_last(k, &first, &last);
          if (last < 0) continue;
          lo = std::min(lo, first - 1);
          hi = std::max(hi, last + 2);
        }
        lo = std::max(lo, 0);
        hi = std::min(hi, w);
        mf->SetIdle(y * w);
        mf->SetIdle(y * w + w - 1);
        for (int32_t x = lo; x < hi; ++x) {
          const int32_t p = y * w + x;
          if (free[p]) {
            mf->SetNode(p, g.source[p] - g.sink[p], g.right_fwd[p], g.down_fwd[p]);
          } else {
            mf->SetIdle(p);
          }
        }
        int32_t first, last;
        first_last(y, &first, &last);
        mf->RowDone(y, last < 0 ? 0 : first, last + 1);
      }
      if (extra > 0) mf->Truncate(h);
    }
    std::vector<bool> reachable;
    const int64_t expected = TextbookMaxflow(g, &reachable);
    ASSERT_EQ(mf_.Solve() + direct, expected) << "trial " << trial << " " << w << "x" << h;
    ASSERT_EQ(four.Solve() + direct, expected) << "trial " << trial;
    ASSERT_EQ(CutCapacity(g, mf_), expected) << "trial " << trial;
    for (int32_t p = 0; p < w * h; ++p) {
      ASSERT_EQ(mf_.InSource(p), reachable[p]) << trial << " " << p;
      ASSERT_EQ(four.InSource(p), reachable[p]) << trial << " " << p;
      if (!free[p]) continue;
      for (int dir = 0; dir < 4; ++dir) {
        const auto d = static_cast<GridMaxflow::Dir>(dir);
        ASSERT_EQ(GridMaxflowProbe::Residual(mf_, p, d), GridMaxflowProbe::Residual(four, p, d))
            << trial << " " << p << " " << dir;
      }
    }
  }
}

// A corridor that winds through the whole grid, the source at one end and the sink at the
// other: the augmenting path is far longer than the record Augment keeps of it (a thousand
// nodes a side on 64 x 64), and no push along a row or column can shorten it (no row or column
// has both an excess and a deficit). One path: the flow is its narrowest arc, and the least
// source side is the corridor up to that arc's first occurrence. The narrowest arc is put near
// either end, where the trees' paths are longest from where they meet.
TEST_F(MaxflowTest, LongWindingPathAgrees) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int32_t> cap(3, 400);
  for (int trial = 0; trial < 4; ++trial) {
    const int32_t side = trial < 2 ? 33 : 64;
    const bool near_sink = trial % 2 == 1;
    Graph g = RandomGraph(rng, side, side, 0);
    std::vector<int32_t> path;   // the corridor's nodes, source end first
    std::vector<int32_t*> arc;   // arc[i]: the capacity of path[i] -> path[i + 1]
    std::vector<int32_t*> back;  // back[i]: the capacity of path[i + 1] -> path[i]
    auto link = [&](int32_t p, int32_t q) {
      int32_t* forward = q == p + 1   ? &g.right_fwd[p]
                         : q == p - 1 ? &g.right_bwd[q]
                                      : &g.down_fwd[p];
      int32_t* backward = q == p + 1   ? &g.right_bwd[p]
                          : q == p - 1 ? &g.right_fwd[q]
                                       : &g.down_bwd[p];
      *forward = cap(rng);
      *backward = cap(rng);
      arc.push_back(forward);
      back.push_back(backward);
    };
    for (int32_t y = 0; y < side; y += 2) {
      const bool rightward = (y / 2) % 2 == 0;
      for (int32_t i = 0; i < side; ++i) {
        const int32_t p = y * side + (rightward ? i : side - 1 - i);
        if (!path.empty()) link(path.back(), p);
        path.push_back(p);
      }
      // Down through the wall row below, at the end the corridor reached.
      if (y + 2 < side) {
        const int32_t p = (y + 1) * side + (rightward ? side - 1 : 0);
        link(path.back(), p);
        path.push_back(p);
      }
    }
    g.source[path.front()] = 1000;
    g.sink[path.back()] = 1000;
    const size_t narrowest = near_sink ? arc.size() - 40 : 40;
    *arc[narrowest] = 2;  // below every other capacity
    const int64_t expected = 2;
    ASSERT_GT(path.size(), static_cast<size_t>(side * side / 2));
    ASSERT_EQ(Solve(g, mf_), expected) << trial;
    ASSERT_EQ(CutCapacity(g, mf_), expected) << trial;
    // Off the corridor, nodes have no arcs: never on the source side.
    std::vector<bool> source_side(static_cast<size_t>(side * side), false);
    for (size_t i = 0; i <= narrowest; ++i) source_side[path[i]] = true;
    for (int32_t p = 0; p < side * side; ++p) {
      ASSERT_EQ(mf_.InSource(p), source_side[p]) << trial << " " << p;
    }
    // The flow of 2 went along the whole corridor, once: every arc of it carries exactly 2.
    for (size_t i = 0; i + 1 < path.size(); ++i) {
      const int32_t p = path[i], q = path[i + 1];
      const GridMaxflow::Dir dir = q == p + 1   ? GridMaxflow::kRight
                                   : q == p - 1 ? GridMaxflow::kLeft
                                                : GridMaxflow::kDown;
      const GridMaxflow::Dir sister = static_cast<GridMaxflow::Dir>(dir ^ 1);
      ASSERT_EQ(GridMaxflowProbe::Residual(mf_, p, dir), *arc[i] - 2) << trial << " " << i;
      ASSERT_EQ(GridMaxflowProbe::Residual(mf_, q, sister), *back[i] + 2) << trial << " " << i;
    }
    if (side <= 40) {
      ASSERT_EQ(TextbookMaxflow(g), expected);
    }
  }
}

// The 16-bit time stamps wrap within a search that starts just below the wrap: no stale stamp
// may pass for a fresh one.
TEST_F(MaxflowTest, TimeStampsWrapWithinASearch) {
  std::mt19937 rng(31);
  std::uniform_int_distribution<int32_t> side(4, 24);
  int64_t searches_over_wrap = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const int32_t w = side(rng), h = side(rng);
    const Graph g = RandomGraph(rng, w, h, trial % 2 ? 40 : 3000);
    GridMaxflowProbe::StartTime(mf_, 0xffff - trial % 8);
    std::vector<bool> reachable;
    const int64_t expected = TextbookMaxflow(g, &reachable);
    ASSERT_EQ(Solve(g, mf_), expected) << "trial " << trial;
    searches_over_wrap += GridMaxflowProbe::Time(mf_) < 0xffff - trial % 8;
    for (int32_t p = 0; p < w * h; ++p) ASSERT_EQ(mf_.InSource(p), reachable[p]) << trial;
  }
  GridMaxflowProbe::StartTime(mf_, 0);
  EXPECT_GT(searches_over_wrap, 100);  // most searches augment more than 8 paths
}

TEST_F(MaxflowTest, LargeCapacitiesDoNotOverflow) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 100; ++trial) {
    Graph g = RandomGraph(rng, 6, 6, GridMaxflow::kMaxCapacity);
    ASSERT_EQ(Solve(g, mf_), TextbookMaxflow(g));
  }
}

}  // namespace
}  // namespace lb
