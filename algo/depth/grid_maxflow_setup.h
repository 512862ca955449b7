// The row kernel of GridMaxflow's passes before the search (grid_maxflow_setup.cc): it writes a
// row's nodes from the staged rows, each node once, and queues the roots that can grow. The C
// reference is gmf::kReference (grid_maxflow_setup.cc); the SIMD twins (grid_maxflow_setup_avx2.cc,
// grid_maxflow_setup_neon.cc) give the same bytes and the same queue, and GridMaxflow picks one
// table when it is carved (gmf::SimdKernels, from algo/core/cpu.h).
// tests/algo/depth/grid_maxflow_setup_test.cc holds every twin the CPU runs to the reference.
// Internal to algo/depth.
#pragma once

#include <cstdint>

namespace lb {

// What the row kernel reads of row y: its staged balances, residual arcs right and down, its
// flows to the right (the row chain: the residual of the arc left of x + 1, 0 at the last live
// x), down (to row y + 1: the residual of row y + 1's arcs up) and in from row y - 1 (the
// residual of row y's arcs up); the final balances of rows y - 1 and y + 1 and the residual arcs
// down from row y - 1 (zeros for the padding rows). Balances within +-2^30, arcs 0..0xffff.
struct GridMaxflowRows {
  const int32_t* tcap;
  const int32_t* cap_right;
  const int32_t* cap_down;
  const int32_t* flow_right;
  const int32_t* flow_out;
  const int32_t* flow_in;
  const int32_t* up_tcap;
  const int32_t* up_cap_down;
  const int32_t* down_tcap;
};

namespace gmf {

// A node as the kernels write it, 16 bytes (little-endian): the residual arcs right, left, down
// and up (16 bits each; as words right | left << 16 and down | up << 16), the terminal balance
// (int32), then one word of the time stamp (16 bits, 0), the distance (8 bits, 1) and the bits:
// the parent (bits 0-2), the tree (3-4) and the queued flag (5). The same values as
// GridMaxflow's, which checks them.
inline constexpr uint32_t kTerminal = 4, kOrphan = 5;  // parents besides a direction
inline constexpr uint32_t kSourceTree = 1, kSinkTree = 2;
inline constexpr uint32_t kQueuedBit = 0x20;
// The last word of a node that is no root (ts 0, dist 1, parent kOrphan, free).
inline constexpr uint32_t kOrphanWord = (1u << 16) | (kOrphan << 24);

// Writes nodes x..x1-1 of a row at row + 16 x (each has a live left neighbour: x > the row's
// first live column): a root where the balance is not 0, else a free node; a root with a residual
// arc into a node that is not a root of its tree (a source root's arcs out, a sink root's arcs in)
// is queued, its index base + x appended at queue[*count] in the order of x (the queue has room
// for 8 entries past its end, which a twin may write). Returns where it stopped: x1 for the
// reference, and for a twin where fewer nodes remain than its step (the caller finishes with the
// reference).
using InitNodesFn = int32_t (*)(const GridMaxflowRows& in, uint8_t* row, int32_t x, int32_t x1,
                                int32_t base, int32_t* queue, int32_t* count);

struct Kernels {
  InitNodesFn init_nodes;
};

// One node as the reference writes it, its left neighbour's balance, arc right and flow right
// given (0 for a row's first live node, whose left neighbour is not live).
void InitNodeC(const GridMaxflowRows& in, uint8_t* row, int32_t x, int32_t left_tcap,
               int32_t left_right, int32_t left_flow, int32_t base, int32_t* queue, int32_t* count);

extern const Kernels kReference;
const Kernels* Avx2Kernels();  // nullptr where not built
// nullptr where not built; armhf builds it whatever its baseline: the caller checks the CPU.
const Kernels* NeonKernels();
// The table for this CPU (CurrentCpu): AVX2, NEON, or nullptr for the reference.
const Kernels* SimdKernels();

}  // namespace gmf
}  // namespace lb
