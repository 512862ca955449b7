// GridMaxflow's row kernel for AVX2 (grid_maxflow_setup.h; the reference is gmf::kReference):
// eight nodes a step in 32-bit lanes, transposed to node words and stored whole; the last step
// overlaps the one before when the row does not end on a step (the same words again, its queued
// lanes already taken skipped). The queued lanes' indices are packed to the front by a table
// lookup and stored whole.
#include "algo/depth/grid_maxflow_setup.h"

#if defined(__x86_64__)
#include <immintrin.h>

#include <cstddef>

#define LB_AVX2 __attribute__((target("avx2")))

namespace lb::gmf {
namespace {

constexpr int32_t kStep = 8;

// For each 8-bit mask, the indices of its set bits in order, then zeros.
struct QueueOrder {
  uint8_t lanes[256 * 8];
  constexpr QueueOrder() : lanes() {
    for (int32_t m = 0; m < 256; ++m) {
      int32_t k = 0;
      for (int32_t i = 0; i < 8; ++i) {
        if ((m >> i) & 1) lanes[8 * m + k++] = static_cast<uint8_t>(i);
      }
    }
  }
};
constexpr QueueOrder kQueueOrder;

LB_AVX2 inline __m256i Load(const int32_t* p) {
  return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p));
}

LB_AVX2 inline __m256i Neg(__m256i v) { return _mm256_sub_epi32(_mm256_setzero_si256(), v); }

// Nodes x..x+7; of the queued ones, those whose lane is set in `keep`.
LB_AVX2 inline void Step(const GridMaxflowRows& in, uint8_t* row, int32_t x, int32_t base,
                         uint32_t keep, int32_t* queue, int32_t* count) {
  const __m256i t = Load(in.tcap + x), right = Load(in.cap_right + x);
  const __m256i down = Load(in.cap_down + x), up = Load(in.flow_in + x);
  const __m256i left = Load(in.flow_right + x - 1);
  const __m256i tl = Load(in.tcap + x - 1), tr = Load(in.tcap + x + 1);
  const __m256i td = Load(in.down_tcap + x), tu = Load(in.up_tcap + x);
  const __m256i one = _mm256_set1_epi32(1);
  // The tests on signs are on the top bit of the lanes (no overflow: every value is within
  // +-2^30): a > 0 is the top bit of 0 - a, b <= 0 that of b - 1, b >= 0 that of ~b. A source
  // root grows over an arc with residual into a node that is not a source root, a sink root
  // over an arc with residual from a node that is not a sink root.
  const __m256i source_grows =
      _mm256_or_si256(_mm256_or_si256(_mm256_and_si256(Neg(right), _mm256_sub_epi32(tr, one)),
                                      _mm256_and_si256(Neg(left), _mm256_sub_epi32(tl, one))),
                      _mm256_or_si256(_mm256_and_si256(Neg(down), _mm256_sub_epi32(td, one)),
                                      _mm256_and_si256(Neg(up), _mm256_sub_epi32(tu, one))));
  const __m256i sink_grows =
      _mm256_or_si256(_mm256_or_si256(_mm256_andnot_si256(tr, Neg(Load(in.flow_right + x))),
                                      _mm256_andnot_si256(tl, Neg(Load(in.cap_right + x - 1)))),
                      _mm256_or_si256(_mm256_andnot_si256(td, Neg(Load(in.flow_out + x))),
                                      _mm256_andnot_si256(tu, Neg(Load(in.up_cap_down + x)))));
  // Queued: the top bit.
  const __m256i queued =
      _mm256_or_si256(_mm256_and_si256(Neg(t), source_grows), _mm256_and_si256(t, sink_grows));
  const __m256i source = _mm256_cmpgt_epi32(t, _mm256_setzero_si256());
  const __m256i sink = _mm256_cmpgt_epi32(_mm256_setzero_si256(), t);
  // ts 0, dist 1; parent kTerminal on a root (kOrphan less one), else kOrphan; the tree on a
  // root; the queued bit.
  const __m256i tree = _mm256_or_si256(
      _mm256_and_si256(source, _mm256_set1_epi32(static_cast<int32_t>(kSourceTree << 27))),
      _mm256_and_si256(sink, _mm256_set1_epi32(static_cast<int32_t>(kSinkTree << 27))));
  const __m256i last = _mm256_add_epi32(
      _mm256_add_epi32(_mm256_set1_epi32(static_cast<int32_t>(kOrphanWord)),
                       _mm256_slli_epi32(_mm256_or_si256(source, sink), 24)),
      _mm256_add_epi32(tree, _mm256_slli_epi32(_mm256_srli_epi32(queued, 31), 29)));
  const __m256i right_left = _mm256_or_si256(right, _mm256_slli_epi32(left, 16));
  const __m256i down_up = _mm256_or_si256(down, _mm256_slli_epi32(up, 16));
  // Transposed to nodes (right | left, down | up, tcap, last): per 128-bit half, nodes 0-3 and
  // 4-7 of the step.
  const __m256i lo_caps = _mm256_unpacklo_epi32(right_left, down_up);  // nodes 0, 1 | 4, 5
  const __m256i hi_caps = _mm256_unpackhi_epi32(right_left, down_up);  // nodes 2, 3 | 6, 7
  const __m256i lo_rest = _mm256_unpacklo_epi32(t, last);
  const __m256i hi_rest = _mm256_unpackhi_epi32(t, last);
  const __m256i n04 = _mm256_unpacklo_epi64(lo_caps, lo_rest);
  const __m256i n15 = _mm256_unpackhi_epi64(lo_caps, lo_rest);
  const __m256i n26 = _mm256_unpacklo_epi64(hi_caps, hi_rest);
  const __m256i n37 = _mm256_unpackhi_epi64(hi_caps, hi_rest);
  __m256i* const out = reinterpret_cast<__m256i*>(row + 16 * static_cast<ptrdiff_t>(x));
  _mm256_storeu_si256(out, _mm256_permute2x128_si256(n04, n15, 0x20));
  _mm256_storeu_si256(out + 1, _mm256_permute2x128_si256(n26, n37, 0x20));
  _mm256_storeu_si256(out + 2, _mm256_permute2x128_si256(n04, n15, 0x31));
  _mm256_storeu_si256(out + 3, _mm256_permute2x128_si256(n26, n37, 0x31));
  // The queued lanes' indices packed to the front and stored whole (the queue has room for 8
  // past its end); the count moves on by how many there were.
  const uint32_t mask =
      static_cast<uint32_t>(_mm256_movemask_ps(_mm256_castsi256_ps(queued))) & keep;
  if (mask != 0) {
    const __m256i order = _mm256_cvtepu8_epi32(_mm_loadl_epi64(
        reinterpret_cast<const __m128i*>(kQueueOrder.lanes + static_cast<ptrdiff_t>(8) * mask)));
    const __m256i index = _mm256_add_epi32(_mm256_set1_epi32(base + x), order);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(queue + *count), index);
    *count += __builtin_popcount(mask);
  }
}

LB_AVX2 int32_t InitNodesAvx2(const GridMaxflowRows& in, uint8_t* row, int32_t x, int32_t x1,
                              int32_t base, int32_t* queue, int32_t* count) {
  if (x1 - x < kStep) return x;
  for (; x + kStep <= x1; x += kStep) Step(in, row, x, base, 0xff, queue, count);
  // The lanes before x are done: their nodes are written again alike, their queue entries kept.
  if (x < x1) Step(in, row, x1 - kStep, base, (0xffu << (kStep - (x1 - x))) & 0xffu, queue, count);
  return x1;
}

}  // namespace

const Kernels* Avx2Kernels() {
  static constexpr Kernels kAvx2 = {InitNodesAvx2};
  return &kAvx2;
}

}  // namespace lb::gmf
#else
namespace lb::gmf {
const Kernels* Avx2Kernels() { return nullptr; }
}  // namespace lb::gmf
#endif
