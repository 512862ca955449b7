// The Lucas-Kanade tracker's window kernels (tracker.cc): bilinear samples of a window and the
// sums of one iteration. Every sample of a window lies whole pixels from the others, so they
// share one fraction: the weights are set once and the rows go eight samples a step. The C
// reference is tk::kReference (tracker_kernels.cc); the SIMD twins (tracker_avx2.cc,
// tracker_neon.cc) give the same bits, integers throughout, and the tracker picks one table when
// it is carved (tk::SimdKernels, from algo/core/cpu.h). tests/algo/motion/tracker_kernels_test.cc
// holds every twin the CPU has to the reference.
//
// Formats: image bytes; samples Q4 (what (top (256 - fy) + bottom fy + 2048) >> 12 gives, top
// and bottom the rows' a (256 - fx) + b fx), at most 4080; window sides 3..17.
#pragma once

#include <cstddef>
#include <cstdint>

namespace lb::tk {

// The sums of one iteration: per window sample, its error e = view - template, and the sums of
// gx e, gy e and |e| (each product below 2^24, so at most 289 of them fit int64 with room).
struct WindowSums {
  int64_t bx = 0, by = 0, abs_err = 0;
};

struct Kernels {
  // out[j * n + i] = the sample at pixel (i, j) of p (rows `stride` bytes apart) plus (fx, fy)
  // in 1/256: reads n + 1 bytes of n + 1 rows.
  void (*sample)(const uint8_t* p, ptrdiff_t stride, int32_t fx, int32_t fy, int32_t n,
                 int32_t* out);
  // The sums over the n x n window of samples as `sample` makes them (not stored), against tmpl,
  // gx and gy (n x n, row after row).
  WindowSums (*sums)(const uint8_t* p, ptrdiff_t stride, int32_t fx, int32_t fy, int32_t n,
                     const int32_t* tmpl, const int32_t* gx, const int32_t* gy);
};

extern const Kernels kReference;
const Kernels* Avx2Kernels();  // nullptr where not built
const Kernels* NeonKernels();  // nullptr where not built
// The table for this CPU (CurrentCpu): AVX2, NEON, or nullptr for the reference.
const Kernels* SimdKernels();

// One sample, as every kernel computes it.
inline int32_t SampleQ4(const uint8_t* a, ptrdiff_t stride, int32_t fx, int32_t fy) {
  const int32_t top = a[0] * (256 - fx) + a[1] * fx;
  const int32_t bot = a[stride] * (256 - fx) + a[stride + 1] * fx;
  return (top * (256 - fy) + bot * fy + 2048) >> 12;
}

// One sample's error e against the template, into the sums, as every kernel adds it.
inline void AddError(int32_t e, int32_t gx, int32_t gy, WindowSums* s) {
  s->bx += int64_t{gx} * e;
  s->by += int64_t{gy} * e;
  s->abs_err += e < 0 ? -e : e;
}

}  // namespace lb::tk
