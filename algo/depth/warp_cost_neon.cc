// The plane sweep's span kernel for NEON (warp_cost.h; the C reference is dtk::PlaneSpansC in
// warp_cost.cc), aarch64 and armhf built with NEON, ARMv7 intrinsics only: a run of spans a call,
// span by span, 8 pixels a step. NEON
// has no gathers, so positions, weights and offsets are vector arithmetic, each pixel's taps are
// scalar loads into small buffers, and the interpolation, differences and census counts are
// vector arithmetic again. Views narrower than a step or too large for 32-bit offsets, and
// truncations or census weights outside 0..765 and 0..255, take the reference.
#include "algo/depth/data_term_kernels.h"

#if defined(__ARM_NEON) || defined(__arm__)
#include <arm_neon.h>

#include <cstring>

#include "algo/core/int_math.h"

// armhf: compiled for NEON after every include, taken only where the core has it (as
// data_term_neon.cc).
#if defined(__arm__)
#pragma GCC push_options
#pragma GCC target("fpu=neon")
#endif

namespace lb::dtk {
namespace {

constexpr int32_t kLanes = 8;

struct Consts {
  int32x4_t xmax, ymax, wm2, hm2, stride, census_row;
  uint16x8_t trunc;
  uint8x8_t cw, invalid;
};

// 8 lanes of 32-bit values as two halves.
struct Lanes {
  int32x4_t h[2];
};

inline uint16x8_t Narrow(const Lanes& v) {
  return vcombine_u16(vmovn_u32(vreinterpretq_u32_s32(v.h[0])),
                      vmovn_u32(vreinterpretq_u32_s32(v.h[1])));
}

// Format (per lane, as dtk::PlaneSpansC): positions Q16 (|.| < 2^30), rounded to Q8 and clamped
// to the view so every load stays inside it (lanes outside take `invalid` at the end). The tap
// pair's left column is at most width - 2 with a weight of up to 256 on the right one (likewise
// for rows): (w-1, f 0) becomes (w-2, f 256), the same sum. Colour: a row's pair a (256 - fx) +
// b fx <= 65280 in 16 bits, then top (256 - fy) + bottom fy <= 255 * 65536 in 32 bits, rounded
// half up to Q0 by the rounding narrow shift. min(|dRGB|, trunc) + bits * weight <= 765 + 24 *
// 255 in 16 bits, saturated to 255 by the narrowing.
void Step(const WarpRow& r, const Consts& k, int32_t x, const Lanes& xq, const Lanes& yq,
          uint8_t* dst) {
  Lanes xb, yb, fx, fy, nx, ny;
  uint32x4_t bad[2];
  const int32x4_t zero = vdupq_n_s32(0), c127 = vdupq_n_s32(127);
  for (int32_t h = 0; h < 2; ++h) {
    const int32x4_t xs = vshrq_n_s32(vaddq_s32(xq.h[h], vdupq_n_s32(128)), 8);
    const int32x4_t ys = vshrq_n_s32(vaddq_s32(yq.h[h], vdupq_n_s32(128)), 8);
    bad[h] = vorrq_u32(vorrq_u32(vcltq_s32(xs, zero), vcgtq_s32(xs, k.xmax)),
                       vorrq_u32(vcltq_s32(ys, zero), vcgtq_s32(ys, k.ymax)));
    const int32x4_t xc = vminq_s32(vmaxq_s32(xs, zero), k.xmax);
    const int32x4_t yc = vminq_s32(vmaxq_s32(ys, zero), k.ymax);
    xb.h[h] = vminq_s32(vshrq_n_s32(xc, 8), k.wm2);
    yb.h[h] = vminq_s32(vshrq_n_s32(yc, 8), k.hm2);
    fx.h[h] = vsubq_s32(xc, vshlq_n_s32(xb.h[h], 8));
    fy.h[h] = vsubq_s32(yc, vshlq_n_s32(yb.h[h], 8));
    // The nearest tap: the right (lower) one from a fraction of 128 on (the mask is -1).
    nx.h[h] = vsubq_s32(xb.h[h], vreinterpretq_s32_u32(vcgtq_s32(fx.h[h], c127)));
    ny.h[h] = vsubq_s32(yb.h[h], vreinterpretq_s32_u32(vcgtq_s32(fy.h[h], c127)));
  }
  int32_t tap[kLanes], near[kLanes];
  for (int32_t h = 0; h < 2; ++h) {
    const int32x4_t x3 = vaddq_s32(xb.h[h], vaddq_s32(xb.h[h], xb.h[h]));
    vst1q_s32(tap + 4 * h, vmlaq_s32(x3, yb.h[h], k.stride));
    vst1q_s32(near + 4 * h, vmlaq_s32(nx.h[h], ny.h[h], k.census_row));
  }
  // Each pixel's two tap pairs (6 bytes each, inside the view: the pair's left column is at most
  // w - 2) and its nearest census tap, one byte per plane.
  uint8_t top[3 * 2 * kLanes], bottom[3 * 2 * kLanes], census[3][kLanes];
  for (int32_t j = 0; j < kLanes; ++j) {
    const uint8_t* p = r.view + tap[j];
    std::memcpy(top + 6 * j, p, 6);
    std::memcpy(bottom + 6 * j, p + r.stride, 6);
    const uint8_t* c = r.census_view + near[j];
    census[0][j] = c[0];
    census[1][j] = c[r.width];
    census[2][j] = c[2 * r.width];
  }
  // De-interleaved by 3, each channel holds its pairs: 16-bit lanes a | b << 8.
  const uint8x16x3_t t3 = vld3q_u8(top), b3 = vld3q_u8(bottom);
  const uint16x8_t fx16 = Narrow(fx), fy16 = Narrow(fy);
  const uint16x8_t gx16 = vsubq_u16(vdupq_n_u16(256), fx16);
  const uint16x8_t gy16 = vsubq_u16(vdupq_n_u16(256), fy16);
  const uint16x8_t low = vdupq_n_u16(0xff);
  const uint8x8x3_t ref = vld3_u8(r.ref + 3 * x);
  uint16x8_t ad = vdupq_n_u16(0);
  for (int32_t c = 0; c < 3; ++c) {
    const uint16x8_t tp = vreinterpretq_u16_u8(t3.val[c]), bp = vreinterpretq_u16_u8(b3.val[c]);
    const uint16x8_t tv = vmlaq_u16(vmulq_u16(vandq_u16(tp, low), gx16), vshrq_n_u16(tp, 8), fx16);
    const uint16x8_t bv = vmlaq_u16(vmulq_u16(vandq_u16(bp, low), gx16), vshrq_n_u16(bp, 8), fx16);
    const uint32x4_t s_lo = vmlal_u16(vmull_u16(vget_low_u16(tv), vget_low_u16(gy16)),
                                      vget_low_u16(bv), vget_low_u16(fy16));
    const uint32x4_t s_hi = vmlal_u16(vmull_u16(vget_high_u16(tv), vget_high_u16(gy16)),
                                      vget_high_u16(bv), vget_high_u16(fy16));
    const uint16x8_t v = vcombine_u16(vrshrn_n_u32(s_lo, 16), vrshrn_n_u32(s_hi, 16));
    ad = vaddq_u16(ad, vabdq_u16(vmovl_u8(ref.val[c]), v));
  }
  ad = vminq_u16(ad, k.trunc);
  uint8x8_t ham = vdup_n_u8(0);
  for (int32_t p = 0; p < 3; ++p) {
    ham = vadd_u8(ham, vcnt_u8(veor_u8(vld1_u8(census[p]), vld1_u8(r.cref + p * r.width + x))));
  }
  const uint8x8_t cost = vqmovn_u16(vmlal_u8(ad, ham, k.cw));
  const uint8x8_t outside = vmovn_u16(vcombine_u16(vmovn_u32(bad[0]), vmovn_u32(bad[1])));
  vst1_u8(dst, vbsl_u8(outside, k.invalid, cost));
}

}  // namespace

// Positions as WarpSpan's Q32 accumulators, split so that 32-bit lanes give the same bits: with
// the step s = q 2^16 + r (0 <= r < 2^16), (a 2^16 + 2^15 + i s) >> 16 = a + i q +
// ((2^15 + i r) >> 16); i <= 16 keeps 2^15 + i r below 2^21, and a + i q wraps only where the
// exact result (a Q16 position, |.| < 2^30) does not.
void PlaneSpansNeon(const WarpRow& r, const WarpRun& run, uint8_t* out) {
  const int64_t bytes = int64_t{r.height} * r.stride;
  if (r.width < kLanes || r.height < 2 || r.stride <= 0 || bytes >= (int64_t{1} << 31) ||
      r.trunc < 0 || r.trunc > 765 || r.cw < 0 || r.cw > 255) {
    return PlaneSpansC(r, run, out);
  }
  const Consts k{vdupq_n_s32((r.width - 1) * 256),
                 vdupq_n_s32((r.height - 1) * 256),
                 vdupq_n_s32(r.width - 2),
                 vdupq_n_s32(r.height - 2),
                 vdupq_n_s32(static_cast<int32_t>(r.stride)),
                 vdupq_n_s32(3 * r.width),
                 vdupq_n_u16(static_cast<uint16_t>(r.trunc)),
                 vdup_n_u8(static_cast<uint8_t>(r.cw)),
                 vdup_n_u8(r.invalid)};
  const int32_t lane_index[kLanes] = {0, 1, 2, 3, 4, 5, 6, 7};
  const int32x4_t iota_lo = vld1q_s32(lane_index), iota_hi = vld1q_s32(lane_index + 4);
  const int32x4_t half = vdupq_n_s32(32768);
  int32_t first = 0, end = 0;
  RunSpans(run, &first, &end);
  for (int32_t span = first; span < end; ++span) {
    const WarpSpanJob spanjob = RunSpan(run, span);
    const WarpSpanJob* const job = &spanjob;
    if (job->lo >= job->hi) continue;
    if (SpanOutsideView(r, *job)) {
      FillInvalid(r, *job, out);
      continue;
    }
    // A whole span divides exactly (2^16 / kAnchorStep is whole): no division.
    const int32_t n = job->n;
    const int64_t dx = int64_t{job->bx} - job->ax, dy = int64_t{job->by} - job->ay;
    const int64_t sx = n == kAnchorStep ? dx * (65536 / kAnchorStep) : n > 0 ? dx * 65536 / n : 0;
    const int64_t sy = n == kAnchorStep ? dy * (65536 / kAnchorStep) : n > 0 ? dy * 65536 / n : 0;
    const int32x4_t qx = vdupq_n_s32(static_cast<int32_t>(sx >> 16));
    const int32x4_t qy = vdupq_n_s32(static_cast<int32_t>(sy >> 16));
    const int32x4_t rx = vdupq_n_s32(static_cast<int32_t>(sx & 0xffff));
    const int32x4_t ry = vdupq_n_s32(static_cast<int32_t>(sy & 0xffff));
    // Lanes off the span (short ranges only) repeat its end pixels.
    auto axis = [&](int32x4_t i, int32_t a, int32_t b, int32x4_t q, int32x4_t rem) {
      const uint32x4_t frac =
          vshrq_n_u32(vreinterpretq_u32_s32(vmlaq_s32(half, i, rem)), 16);  // < 2^21
      const int32x4_t p = vaddq_s32(vmlaq_s32(vdupq_n_s32(a), i, q), vreinterpretq_s32_u32(frac));
      return vbslq_s32(vceqq_s32(i, vdupq_n_s32(n)), vdupq_n_s32(b), p);
    };
    auto step = [&](int32_t x, uint8_t* dst) {
      const int32x4_t base = vdupq_n_s32(x - job->x0), end = vdupq_n_s32(n);
      const int32x4_t zero = vdupq_n_s32(0);
      const int32x4_t i_lo = vminq_s32(vmaxq_s32(vaddq_s32(base, iota_lo), zero), end);
      const int32x4_t i_hi = vminq_s32(vmaxq_s32(vaddq_s32(base, iota_hi), zero), end);
      const Lanes xq{{axis(i_lo, job->ax, job->bx, qx, rx), axis(i_hi, job->ax, job->bx, qx, rx)}};
      const Lanes yq{{axis(i_lo, job->ay, job->by, qy, ry), axis(i_hi, job->ay, job->by, qy, ry)}};
      Step(r, k, x, xq, yq, dst);
    };
    if (job->hi - job->lo < kLanes) {
      // A short range: one step over 8 pixels of the row that hold it, into a buffer.
      const int32_t x = Min(job->lo, r.width - kLanes);
      uint8_t costs[kLanes];
      step(x, costs);
      std::memcpy(out + job->lo, costs + (job->lo - x), static_cast<size_t>(job->hi - job->lo));
      continue;
    }
    for (int32_t s = job->lo; s < job->hi; s += kLanes) {
      // The last step overlaps the one before: the same bytes again.
      const int32_t x = s + kLanes <= job->hi ? s : job->hi - kLanes;
      step(x, out + x);
    }
  }
}

}  // namespace lb::dtk
#if defined(__arm__)
#pragma GCC pop_options
#endif
#endif
