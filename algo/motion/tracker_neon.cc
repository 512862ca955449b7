// The tracker's window kernels for NEON (tracker_kernels.h; the reference is tk::kReference):
// eight samples a step, each row's bytes at x and x + 1 widened to 16 bits and mixed into 32-bit
// lanes by (256 - fx, fx), then the rows by (256 - fy, fy); the columns past the last whole step
// one by one. A lane takes at most 4 products of < 2^24 a row (two steps of 17 columns, two halves
// on NEON), so over 17 rows its sum stays in int32. ARMv7 intrinsics only.
#include "algo/motion/tracker_kernels.h"

#if defined(__ARM_NEON) || defined(__arm__)
#include <arm_neon.h>

// armhf's baseline has no NEON: this file's functions alone are compiled for it, and
// SimdKernels() takes them only where the firmware read that the core has NEON.
#if defined(__arm__)
#pragma GCC push_options
#pragma GCC target("fpu=neon")
#endif

namespace lb::tk {
namespace {

struct Eight {
  int32x4_t lo, hi;
};

// Samples i..i+7 of the row at a (rows `stride` apart).
inline Eight Step(const uint8_t* a, ptrdiff_t stride, uint16_t fx, uint16_t gx, uint32_t fy,
                  uint32_t gy) {
  const uint16x8_t a0 = vmovl_u8(vld1_u8(a)), a1 = vmovl_u8(vld1_u8(a + 1));
  const uint16x8_t b0 = vmovl_u8(vld1_u8(a + stride)), b1 = vmovl_u8(vld1_u8(a + stride + 1));
  const uint32x4_t top_lo = vmlal_n_u16(vmull_n_u16(vget_low_u16(a0), gx), vget_low_u16(a1), fx);
  const uint32x4_t top_hi = vmlal_n_u16(vmull_n_u16(vget_high_u16(a0), gx), vget_high_u16(a1), fx);
  const uint32x4_t bot_lo = vmlal_n_u16(vmull_n_u16(vget_low_u16(b0), gx), vget_low_u16(b1), fx);
  const uint32x4_t bot_hi = vmlal_n_u16(vmull_n_u16(vget_high_u16(b0), gx), vget_high_u16(b1), fx);
  const uint32x4_t round = vdupq_n_u32(2048);
  const uint32x4_t lo = vmlaq_n_u32(vmlaq_n_u32(round, top_lo, gy), bot_lo, fy);
  const uint32x4_t hi = vmlaq_n_u32(vmlaq_n_u32(round, top_hi, gy), bot_hi, fy);
  return {vreinterpretq_s32_u32(vshrq_n_u32(lo, 12)), vreinterpretq_s32_u32(vshrq_n_u32(hi, 12))};
}

void SampleNeon(const uint8_t* p, ptrdiff_t stride, int32_t fx, int32_t fy, int32_t n,
                int32_t* out) {
  const uint16_t fx16 = static_cast<uint16_t>(fx), gx16 = static_cast<uint16_t>(256 - fx);
  const uint32_t fy32 = static_cast<uint32_t>(fy), gy32 = static_cast<uint32_t>(256 - fy);
  for (int32_t j = 0; j < n; ++j) {
    const uint8_t* a = p + j * stride;
    int32_t* o = out + j * n;
    int32_t i = 0;
    for (; i + 8 <= n; i += 8) {
      const Eight v = Step(a + i, stride, fx16, gx16, fy32, gy32);
      vst1q_s32(o + i, v.lo);
      vst1q_s32(o + i + 4, v.hi);
    }
    for (; i < n; ++i) o[i] = SampleQ4(a + i, stride, fx, fy);
  }
}

int64_t LaneSum(int32x4_t v) {
  return int64_t{vgetq_lane_s32(v, 0)} + vgetq_lane_s32(v, 1) + vgetq_lane_s32(v, 2) +
         vgetq_lane_s32(v, 3);
}

WindowSums SumsNeon(const uint8_t* p, ptrdiff_t stride, int32_t fx, int32_t fy, int32_t n,
                    const int32_t* tmpl, const int32_t* gx, const int32_t* gy) {
  const uint16_t fx16 = static_cast<uint16_t>(fx), gx16 = static_cast<uint16_t>(256 - fx);
  const uint32_t fy32 = static_cast<uint32_t>(fy), gy32 = static_cast<uint32_t>(256 - fy);
  int32x4_t bx = vdupq_n_s32(0), by = bx, ae = bx;
  WindowSums s;
  for (int32_t j = 0; j < n; ++j) {
    const uint8_t* a = p + j * stride;
    const int32_t k0 = j * n;
    int32_t i = 0;
    for (; i + 8 <= n; i += 8) {
      const int32_t k = k0 + i;
      const Eight v = Step(a + i, stride, fx16, gx16, fy32, gy32);
      const int32x4_t e_lo = vsubq_s32(v.lo, vld1q_s32(tmpl + k));
      const int32x4_t e_hi = vsubq_s32(v.hi, vld1q_s32(tmpl + k + 4));
      bx = vmlaq_s32(vmlaq_s32(bx, vld1q_s32(gx + k), e_lo), vld1q_s32(gx + k + 4), e_hi);
      by = vmlaq_s32(vmlaq_s32(by, vld1q_s32(gy + k), e_lo), vld1q_s32(gy + k + 4), e_hi);
      ae = vaddq_s32(ae, vaddq_s32(vabsq_s32(e_lo), vabsq_s32(e_hi)));
    }
    for (; i < n; ++i) {
      const int32_t k = k0 + i;
      AddError(SampleQ4(a + i, stride, fx, fy) - tmpl[k], gx[k], gy[k], &s);
    }
  }
  s.bx += LaneSum(bx);
  s.by += LaneSum(by);
  s.abs_err += LaneSum(ae);
  return s;
}

}  // namespace

const Kernels* NeonKernels() {
  static constexpr Kernels kNeon = {SampleNeon, SumsNeon};
  return &kNeon;
}

}  // namespace lb::tk
#if defined(__arm__)
#pragma GCC pop_options
#endif
#else
namespace lb::tk {
const Kernels* NeonKernels() { return nullptr; }
}  // namespace lb::tk
#endif
