// GridMaxflow's row kernel for NEON (grid_maxflow_setup.h; the reference is gmf::kReference),
// aarch64 and armhf built with NEON, ARMv7 intrinsics only: four nodes a step in 32-bit lanes,
// stored as node words by one interleaving store; the last step overlaps the one before when the
// row does not end on a step (the same words again, its queued lanes already taken skipped).
#include "algo/depth/grid_maxflow_setup.h"

#if defined(__ARM_NEON) || defined(__arm__)
#include <arm_neon.h>

#include <cstddef>

// armhf's baseline has no NEON: this file's functions alone are compiled for it (after every
// include), and SimdKernels() takes them only where the firmware read that the core has NEON.
#if defined(__arm__)
#pragma GCC push_options
#pragma GCC target("fpu=neon")
#endif

namespace lb::gmf {
namespace {

constexpr int32_t kStep = 4;

inline uint32x4_t Load(const int32_t* p) { return vreinterpretq_u32_s32(vld1q_s32(p)); }

inline uint32x4_t Neg(uint32x4_t v) { return vsubq_u32(vdupq_n_u32(0), v); }

// Nodes x..x+3; of the queued ones, those whose lane is set in `keep`.
inline void Step(const GridMaxflowRows& in, uint8_t* row, int32_t x, int32_t base, uint32_t keep,
                 int32_t* queue, int32_t* count) {
  const int32x4_t ts = vld1q_s32(in.tcap + x);
  const uint32x4_t t = vreinterpretq_u32_s32(ts), right = Load(in.cap_right + x);
  const uint32x4_t down = Load(in.cap_down + x), up = Load(in.flow_in + x);
  const uint32x4_t left = Load(in.flow_right + x - 1);
  const uint32x4_t tl = Load(in.tcap + x - 1), tr = Load(in.tcap + x + 1);
  const uint32x4_t td = Load(in.down_tcap + x), tu = Load(in.up_tcap + x);
  const uint32x4_t one = vdupq_n_u32(1);
  // The tests on signs are on the top bit of the lanes (no overflow: every value is within
  // +-2^30): a > 0 is the top bit of 0 - a, b <= 0 that of b - 1, b >= 0 that of ~b. A source
  // root grows over an arc with residual into a node that is not a source root, a sink root
  // over an arc with residual from a node that is not a sink root.
  const uint32x4_t source_grows = vorrq_u32(
      vorrq_u32(vandq_u32(Neg(right), vsubq_u32(tr, one)),
                vandq_u32(Neg(left), vsubq_u32(tl, one))),
      vorrq_u32(vandq_u32(Neg(down), vsubq_u32(td, one)), vandq_u32(Neg(up), vsubq_u32(tu, one))));
  // vbicq_u32(a, b) is a & ~b.
  const uint32x4_t sink_grows = vorrq_u32(vorrq_u32(vbicq_u32(Neg(Load(in.flow_right + x)), tr),
                                                    vbicq_u32(Neg(Load(in.cap_right + x - 1)), tl)),
                                          vorrq_u32(vbicq_u32(Neg(Load(in.flow_out + x)), td),
                                                    vbicq_u32(Neg(Load(in.up_cap_down + x)), tu)));
  // Queued: 0 or 1.
  const uint32x4_t queued =
      vshrq_n_u32(vorrq_u32(vandq_u32(Neg(t), source_grows), vandq_u32(t, sink_grows)), 31);
  const uint32x4_t source = vcgtq_s32(ts, vdupq_n_s32(0));
  const uint32x4_t sink = vcltq_s32(ts, vdupq_n_s32(0));
  // ts 0, dist 1; parent kTerminal on a root (kOrphan less one), else kOrphan; the tree on a
  // root; the queued bit.
  const uint32x4_t tree = vorrq_u32(vandq_u32(source, vdupq_n_u32(kSourceTree << 27)),
                                    vandq_u32(sink, vdupq_n_u32(kSinkTree << 27)));
  uint32x4x4_t node;
  node.val[0] = vorrq_u32(right, vshlq_n_u32(left, 16));
  node.val[1] = vorrq_u32(down, vshlq_n_u32(up, 16));
  node.val[2] = t;
  node.val[3] =
      vaddq_u32(vaddq_u32(vdupq_n_u32(kOrphanWord), vshlq_n_u32(vorrq_u32(source, sink), 24)),
                vaddq_u32(tree, vshlq_n_u32(queued, 29)));
  // Interleaved: node i's four words from lane i of each.
  vst4q_u32(reinterpret_cast<uint32_t*>(row + 16 * static_cast<ptrdiff_t>(x)), node);
  const uint32x2_t any = vorr_u32(vget_low_u32(queued), vget_high_u32(queued));
  if ((vget_lane_u32(any, 0) | vget_lane_u32(any, 1)) == 0) return;
  uint32_t lanes[kStep];
  vst1q_u32(lanes, queued);
  for (int32_t i = 0; i < kStep; ++i) {
    if ((lanes[i] & (keep >> i)) != 0) queue[(*count)++] = base + x + i;
  }
}

int32_t InitNodesNeon(const GridMaxflowRows& in, uint8_t* row, int32_t x, int32_t x1, int32_t base,
                      int32_t* queue, int32_t* count) {
  if (x1 - x < kStep) return x;
  for (; x + kStep <= x1; x += kStep) Step(in, row, x, base, 0xf, queue, count);
  // The lanes before x are done: their nodes are written again alike, their queue entries kept.
  if (x < x1) Step(in, row, x1 - kStep, base, (0xfu << (kStep - (x1 - x))) & 0xfu, queue, count);
  return x1;
}

}  // namespace

const Kernels* NeonKernels() {
  static constexpr Kernels kNeon = {InitNodesNeon};
  return &kNeon;
}

}  // namespace lb::gmf
#if defined(__arm__)
#pragma GCC pop_options
#endif
#else
namespace lb::gmf {
const Kernels* NeonKernels() { return nullptr; }
}  // namespace lb::gmf
#endif
