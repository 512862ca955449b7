// The C reference of the layer row kernels (layer_rows.h) and the gather kernel's body compiled
// for AVX2 (x86-64) and NEON (ARM) too: an always-inline function instantiated once in a plain
// function and once in a target one, so all come from one source (compilers vectorise it well;
// the kernels they do not are written with intrinsics in layer_rows_avx2.cc / _neon.cc).
#include "algo/render/layer_rows.h"

#include "algo/core/cpu.h"
#include "algo/core/int_math.h"

#if defined(__x86_64__)
#define LB_ROW_AVX2 __attribute__((target("avx2")))
#endif
#if defined(__arm__)
#define LB_ROW_NEON __attribute__((target("fpu=neon")))  // beyond armhf's baseline
#elif defined(__ARM_NEON)
#define LB_ROW_NEON
#endif

namespace lb::layer_rows {
namespace {

#define LB_ROW_BODY inline __attribute__((always_inline))

// Rounded signed division, den > 0 (half away from zero; the same on every platform). The
// operands fit int32 (|num| < 2^31 - 2^16), so a 32-bit division suffices.
int32_t RoundDiv(int32_t num, int32_t den) {
  return num >= 0 ? (num + den / 2) / den : -((-num + den / 2) / den);
}
// RoundDiv(num, 65536).
int32_t RoundShift16(int32_t num) {
  return num >= 0 ? (num + 32768) >> 16 : -((-num + 32768) >> 16);
}

// Written so compilers vectorise it: the three weighted spans in wrapping uint32.
LB_ROW_BODY void GatherBody(const uint32_t* p, const KernelRow& k, uint32_t* acc, int32_t x0,
                            int32_t x1) {
  const uint32_t* pa = p + k.left - 1;
  const uint32_t* pb = p + k.left;
  const uint32_t* pc = p + k.right + 1;
  const uint32_t* pd = p + k.right + 2;
  const uint32_t w = static_cast<uint32_t>(k.w), wl = static_cast<uint32_t>(k.wl),
                 wr = static_cast<uint32_t>(k.wr);
  for (int32_t x = x0; x <= x1; ++x) {
    const uint32_t t = w * (pc[x] - pb[x]) + wl * (pb[x] - pa[x]) + wr * (pd[x] - pc[x]);
    acc[x] += t;
  }
}

// Whole groups have a fixed length, so the inner loop is unrolled for each level.
template <int L>
void SumGroupsT(const int16_t* v, int32_t x0, int32_t x1, int32_t up, int32_t* box) {
  int32_t x = x0;
  for (; x + (1 << L) - 1 <= x1; x += 1 << L) {
    int32_t sum = 0;
    for (int32_t k = 0; k < (1 << L); ++k) sum += v[x + k];
    box[x >> L] += sum * (1 << up);
  }
  int32_t sum = 0;
  for (int32_t k = x; k <= x1; ++k) sum += v[k];
  if (x <= x1) box[x >> L] += sum * (1 << up);
}

}  // namespace

void GatherRowC(const uint32_t* p, const KernelRow& k, uint32_t* acc, int32_t x0, int32_t x1) {
  GatherBody(p, k, acc, x0, x1);
}

void CompositeRowC(int32_t* out, const int32_t* colour, const int32_t* alpha, int32_t x0,
                   int32_t x1) {
  for (int32_t x = x0; x <= x1; ++x) {
    const int64_t keep = 65536 - alpha[x];
    out[x] = static_cast<int32_t>(((out[x] * keep + 32768) >> 16) + colour[x]);
  }
}

template <int C>
void LerpCompositeC(const int32_t* col, ptrdiff_t stride, const uint8_t* frac, int32_t level,
                    int32_t x0, int32_t x1, int32_t* out, ptrdiff_t out_stride) {
  const int32_t f = 1 << level;
  for (int32_t x = x0; x <= x1;) {
    const int32_t q = (x - f / 2) >> level;
    const int32_t end = Min(x1, ((q + 1) << level) + f / 2 - 1);
    int32_t a[C + 1];
    int64_t d[C + 1];
    for (int32_t c = 0; c <= C; ++c) {
      a[c] = col[c * stride + q];
      d[c] = col[c * stride + q + 1] - a[c];
    }
    for (; x <= end; ++x) {
      const int32_t alpha = a[C] + static_cast<int32_t>((d[C] * frac[x] + 128) >> 8);
      const int64_t keep = 65536 - alpha;
      for (int32_t c = 0; c < C; ++c) {
        const int32_t colour = a[c] + static_cast<int32_t>((d[c] * frac[x] + 128) >> 8);
        int32_t& o = out[c * out_stride + x];
        o = static_cast<int32_t>(((o * keep + 32768) >> 16) + colour);
      }
      int32_t& o = out[C * out_stride + x];
      o = static_cast<int32_t>(((o * keep + 32768) >> 16) + alpha);
    }
  }
}

void SumGroupsC(const int16_t* v, int32_t x0, int32_t x1, int32_t level, int32_t up, int32_t* box) {
  switch (level) {
    case 1:
      return SumGroupsT<1>(v, x0, x1, up, box);
    case 2:
      return SumGroupsT<2>(v, x0, x1, up, box);
    case 3:
      return SumGroupsT<3>(v, x0, x1, up, box);
    default:
      return SumGroupsT<4>(v, x0, x1, up, box);
  }
}

template <int C>
void FlatPrefixRowC(int32_t x0, int32_t x1, uint32_t* const* p) {
  for (int32_t c = 0; c <= C; ++c) {
    for (int32_t x = x0; x <= x1; ++x) p[c][x + 1] = p[c][x];
  }
}

template <int C>
void PurePrefixRowC(const int16_t* const* v, int32_t shift, int32_t x0, int32_t x1,
                    uint32_t* const* p) {
  for (int32_t c = 0; c < C; ++c) {
    const int16_t* vc = v[c];
    uint32_t* pc = p[c];
    for (int32_t x = x0; x <= x1; ++x) {
      pc[x + 1] = pc[x] + static_cast<uint32_t>((vc[x] * 256) >> shift);
    }
  }
  uint32_t* pa = p[C];
  for (int32_t x = x0; x <= x1; ++x) pa[x + 1] = pa[x] + 256;
}

template <int C>
void WeightedPrefixRowC(const int16_t* const* v, const int16_t* s, const uint16_t* layer_of,
                        int32_t offset, int32_t k, int32_t shift, int32_t x0, int32_t x1,
                        uint32_t* const* p) {
  const int16_t* vc[C];
  uint32_t* pc[C + 1];
  for (int32_t c = 0; c < C; ++c) vc[c] = v[c];
  for (int32_t c = 0; c <= C; ++c) pc[c] = p[c];
  for (int32_t x = x0; x <= x1; ++x) {
    const int32_t a = LayerWeightQ8(layer_of[s[x] + offset], k);
    for (int32_t c = 0; c < C; ++c) {
      pc[c][x + 1] = pc[c][x] + static_cast<uint32_t>((vc[c][x] * a) >> shift);
    }
    pc[C][x + 1] = pc[C][x] + static_cast<uint32_t>(a);
  }
}

template <int C>
void PureBoxRowC(const int16_t* const* v, int32_t shift, int32_t level, int32_t x0, int32_t x1,
                 int32_t* const* box) {
  for (int32_t c = 0; c < C; ++c) SumGroupsC(v[c], x0, x1, level, 8 - shift, box[c]);
  for (int32_t q = x0 >> level; q <= x1 >> level; ++q) {
    box[C][q] += 256 * (Min(x1, ((q + 1) << level) - 1) - (q << level) + 1);
  }
}

template <int C>
void WeightedBoxRowC(const int16_t* const* v, const int16_t* s, const uint16_t* layer_of,
                     int32_t offset, int32_t k, int32_t shift, int32_t level, int32_t x0,
                     int32_t x1, int32_t* const* box) {
  for (int32_t q = x0 >> level; q <= x1 >> level; ++q) {
    int32_t sum[C + 1] = {};
    const int32_t xe = Min(x1, ((q + 1) << level) - 1);
    for (int32_t x = q << level; x <= xe; ++x) {
      const int32_t a = LayerWeightQ8(layer_of[s[x] + offset], k);
      for (int32_t c = 0; c < C; ++c) sum[c] += (v[c][x] * a) >> shift;
      sum[C] += a;
    }
    for (int32_t c = 0; c <= C; ++c) box[c][q] += sum[c];
  }
}

void BoxPrefixRowC(const int32_t* box, int32_t level, int32_t q0, int32_t q1, uint32_t* p) {
  const int32_t round = 1 << (2 * level - 1);
  for (int32_t i = q0; i <= q1; ++i) {
    p[i + 1] = p[i] + static_cast<uint32_t>((box[i] + round) >> (2 * level));
  }
}

#define LB_LAYER_ROWS_INSTANTIATE(C)                                                           \
  template void FlatPrefixRowC<C>(int32_t, int32_t, uint32_t* const*);                         \
  template void PurePrefixRowC<C>(const int16_t* const*, int32_t, int32_t, int32_t,            \
                                  uint32_t* const*);                                           \
  template void WeightedPrefixRowC<C>(const int16_t* const*, const int16_t*, const uint16_t*,  \
                                      int32_t, int32_t, int32_t, int32_t, int32_t,             \
                                      uint32_t* const*);                                       \
  template void PureBoxRowC<C>(const int16_t* const*, int32_t, int32_t, int32_t, int32_t,      \
                               int32_t* const*);                                               \
  template void WeightedBoxRowC<C>(const int16_t* const*, const int16_t*, const uint16_t*,     \
                                   int32_t, int32_t, int32_t, int32_t, int32_t, int32_t,       \
                                   int32_t* const*);                                           \
  template void LerpCompositeC<C>(const int32_t*, ptrdiff_t, const uint8_t*, int32_t, int32_t, \
                                  int32_t, int32_t*, ptrdiff_t);
LB_LAYER_ROWS_INSTANTIATE(1)
LB_LAYER_ROWS_INSTANTIATE(2)
#undef LB_LAYER_ROWS_INSTANTIATE

void NormaliseAlphaRowC(const uint32_t* acc, uint64_t rec, int32_t x0, int32_t x1, int32_t* alpha) {
  for (int32_t x = x0; x <= x1; ++x) {
    const uint64_t a = (uint64_t{acc[x]} * rec) >> 32;
    alpha[x] = static_cast<int32_t>(a > 65536 ? 65536 : a);
  }
}

void NormaliseColourRowC(const uint32_t* acc, uint64_t rec, int32_t shift, int32_t x0, int32_t x1,
                         int32_t* colour) {
  for (int32_t x = x0; x <= x1; ++x) {
    const int64_t sum = static_cast<int32_t>(acc[x]);
    colour[x] = static_cast<int32_t>((sum * static_cast<int64_t>(rec)) >> (32 - shift));
  }
}

void BlendRowsC(const int32_t* a, const int32_t* b, int64_t fy, int32_t q0, int32_t q1,
                int32_t* col) {
  for (int32_t q = q0; q <= q1; ++q) {
    col[q] = static_cast<int32_t>((a[q] * (256 - fy) + b[q] * fy + 128) >> 8);
  }
  col[q0 - 1] = col[q0];
  col[q1 + 1] = col[q1];
}

void ResolveRowC(const int32_t* out, const int32_t* alpha, const int16_t* v, int32_t width,
                 int32_t bias, uint8_t* dst) {
  for (int32_t x = 0; x < width; ++x) {
    // Most pixels are fully covered (alpha 1.0): a shift instead of a division.
    const int32_t value = alpha[x] == 65536 ? RoundShift16(out[x])
                          : alpha[x] > 0    ? RoundDiv(out[x], alpha[x])
                                            : v[x];
    dst[x] = static_cast<uint8_t>(Clamp(value + bias, 0, 255));
  }
}

const Kernels kReference = {GatherRowC,
                            CompositeRowC,
                            {LerpCompositeC<1>, LerpCompositeC<2>},
                            {WeightedBoxRowC<1>, WeightedBoxRowC<2>},
                            {PureBoxRowC<1>, PureBoxRowC<2>},
                            NormaliseAlphaRowC,
                            NormaliseColourRowC,
                            BlendRowsC,
                            BoxPrefixRowC,
                            ResolveRowC,
                            {WeightedPrefixRowC<1>, WeightedPrefixRowC<2>}};

#if defined(LB_ROW_AVX2)
LB_ROW_AVX2 void GatherRowCAvx2(const uint32_t* p, const KernelRow& k, uint32_t* acc, int32_t x0,
                                int32_t x1) {
  GatherBody(p, k, acc, x0, x1);
}
#endif
#if defined(LB_ROW_NEON)
LB_ROW_NEON void GatherRowCNeon(const uint32_t* p, const KernelRow& k, uint32_t* acc, int32_t x0,
                                int32_t x1) {
  GatherBody(p, k, acc, x0, x1);
}
#endif

const Kernels& BestKernels() {
  // What the firmware read of this processor (algo/core/cpu.h): armhf's NEON only when the
  // kernel says the core has it.
  const CpuFeatures cpu = CurrentCpu();
  const Kernels* simd = cpu.avx2 ? Avx2Kernels() : (cpu.neon ? NeonKernels() : nullptr);
  return simd != nullptr ? *simd : kReference;
}

}  // namespace lb::layer_rows
