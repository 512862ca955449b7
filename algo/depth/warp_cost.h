// Plane-sweep pixel costs (ViewGeometry::kKnownPoses): one reference row against one view warped
// through a label's plane homography. The pixel cost is the rectified one (data_term.h) but the
// sample position changes per pixel and in both axes: colour is bilinear over 4 taps, and the
// census Hamming distance is the nearest tap's: on handheld bursts no worse than interpolating
// it over the 4 taps, and faster (docs/performance.md).
//
// Positions: the exact PlaneHomography::Map at anchors every kAnchorStep pixels and at the row's
// last pixel, linear in between. Along a row x' = N(x) / D(x) with N, D linear in x, so
// x'' = -2 m6 x'_x / D (the same for y'), and the chord error is at most
// kAnchorStep^2 / 8 * 2 |m6| |x'_x| / D. m6 is the rotation's R20 / f (a translation only moves
// the constant column), so at 640x480 (f ~ 500 px) a 2 degree rotation gives at most
// 32 * 2 * 0.035 / 500 / 0.97 ~ 1/215 px, a quarter of 1/64 (tested in warp_cost_test.cc).
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/image.h"
#include "algo/depth/data_term.h"
#include "algo/motion/plane_homography.h"

namespace lb {

inline constexpr int32_t kAnchorStep = 16;

// Both views RGB8 of one size; censuses as DataTerm keeps them (per row, three byte planes of
// `width` bytes).
struct WarpSource {
  ConstImageU8 ref, view;
  const uint8_t* census_ref = nullptr;
  const uint8_t* census_view = nullptr;
  // Optional: the row's reference pixels as the kernel's lanes (RefLanes), prepared by the
  // caller once for the row and reused for every view; nullptr: the kernel reads ref itself.
  const int32_t* ref_lanes = nullptr;
  ptrdiff_t lanes_stride = 0;
};

// The reference row as 32-bit lanes, the form a SIMD kernel subtracts and compares in: four
// planes `stride` int32 apart, R, G, B and the 24-bit census (as Census() in warp_cost.cc),
// column x at index x - x0. The data term fills them once per row (a per-worker buffer) instead
// of every view's kernel unpacking the same bytes again. A kernel reading them for a
// PlaneCostRow over x_begin..x_end needs columns RefLanesBegin .. RefLanesEnd - 1 (the spans
// holding that range, and a last step of 8 pixels ending at the row's end).
inline int32_t RefLanesBegin(int32_t width, int32_t x_begin) {
  const int32_t first = x_begin - x_begin % kAnchorStep - kAnchorStep, step = width - 8;
  const int32_t a = first < step ? first : step;
  return a > 0 ? a : 0;
}
inline int32_t RefLanesEnd(int32_t width, int32_t x_end) {
  return x_end + kAnchorStep + 1 < width ? x_end + kAnchorStep + 1 : width;
}

// PlaneHomography::Map along one row y: the same results bit for bit, with one division instead
// of two 64-bit ones (a library call each on 32-bit ARM, where PlaneCostRow uses this). The
// quotient (|n| 2^16 + den / 2) / den <= 2^30 is estimated through den's reciprocal in double
// (relative error under 2^-50, so within 1 of the true quotient) and corrected by its remainder,
// which integer arithmetic gives exactly (q den < 2^63). Only per anchor, never per pixel.
class PlaneRowMap {
 public:
  PlaneRowMap(const PlaneHomography& h, int32_t y)
      : m_(h.m), den_(h.m[7] * y + h.m[8]), nx_(h.m[1] * y + h.m[2]), ny_(h.m[4] * y + h.m[5]) {}

  // kExactDivide: Map's own 64-bit division (one instruction on x86-64 and aarch64) instead of
  // the estimate; the row's constant terms are still summed once.
  template <bool kExactDivide = false>
  bool At(int32_t x, int32_t* x_q16, int32_t* y_q16) const {
    return FromSums<kExactDivide>(m_[6] * x + den_, m_[0] * x + nx_, m_[3] * x + ny_, x_q16, y_q16);
  }

  // The row's denominator and numerators at column x, and their change over dx columns: a
  // caller stepping along the row adds the changes (the same integers as At's products).
  void Sums(int32_t x, int64_t* sums) const {
    sums[0] = m_[6] * x + den_;
    sums[1] = m_[0] * x + nx_;
    sums[2] = m_[3] * x + ny_;
  }
  void Changes(int32_t dx, int64_t* changes) const {
    changes[0] = m_[6] * dx;
    changes[1] = m_[0] * dx;
    changes[2] = m_[3] * dx;
  }

  // At from the sums. The range tests in unsigned arithmetic, one compare each: den in
  // [2^20, 2^32) and |n| < den 2^14 (n + lim - 1 wraps below 2 lim - 1 exactly then).
  template <bool kExactDivide = false>
  static bool FromSums(int64_t den, int64_t nx, int64_t ny, int32_t* x_q16, int32_t* y_q16) {
    constexpr uint64_t kMin = uint64_t{1} << 20, kMax = uint64_t{1} << 32;
    if (static_cast<uint64_t>(den) - kMin >= kMax - kMin) return false;
    const uint64_t lim = static_cast<uint64_t>(den) << 14, span = 2 * lim - 1;
    if (static_cast<uint64_t>(nx) + (lim - 1) >= span ||
        static_cast<uint64_t>(ny) + (lim - 1) >= span) {
      return false;
    }
    if (kExactDivide) {
      *x_q16 = Exact(nx, den);
      *y_q16 = Exact(ny, den);
      return true;
    }
    const double inv = 1.0 / static_cast<double>(den);
    *x_q16 = Div(nx, den, inv);
    *y_q16 = Div(ny, den, inv);
    return true;
  }

 private:
  static int32_t Exact(int64_t n, int64_t den) {
    const int64_t a = n < 0 ? -n : n;
    const int64_t q = ((a << 16) + (den >> 1)) / den;  // as PlaneHomography::Map
    return static_cast<int32_t>(n < 0 ? -q : q);
  }
  static int32_t Div(int64_t n, int64_t den, double inv) {
    const int64_t a = n < 0 ? -n : n;
    const int64_t num = (a << 16) + (den >> 1);  // a < den 2^14: below 2^62 + 2^31
    int32_t q = static_cast<int32_t>(static_cast<double>(num) * inv);
    const int64_t r = num - int64_t{q} * den;
    q += r < 0 ? -1 : r >= den ? 1 : 0;
    return n < 0 ? -q : q;
  }

  const int64_t* m_;
  int64_t den_, nx_, ny_;  // the row's constant terms
};

// View positions (Q16, pixel-index coordinates) of reference pixels x0..x1 of row y, inclusive,
// with x1 - x0 <= kAnchorStep: exact at both ends, linear between. False when an end has no map.
bool WarpSpan(const PlaneHomography& h, int32_t x0, int32_t x1, int32_t y, int32_t* x_q16,
              int32_t* y_q16);

// One reference row against one view, as the span kernels read it.
struct WarpRow {
  const uint8_t* view = nullptr;  // RGB8, rows `stride` bytes apart
  ptrdiff_t stride = 0;
  const uint8_t* census_view = nullptr;  // per row, three planes of `width` bytes
  const uint8_t* ref = nullptr;          // the reference row, RGB8, indexed by x
  const uint8_t* cref = nullptr;         // its census: three planes of `width` bytes
  int32_t width = 0, height = 0, trunc = 0, cw = 0;
  uint8_t invalid = 255;
  const int32_t* ref_lanes = nullptr;  // optional (WarpSource), indexed from lanes_x0
  int32_t lanes_x0 = 0;
  ptrdiff_t lanes_stride = 0;
};

// The view positions of one span and the columns wanted from it: pixels x0 .. x0 + n (n <=
// kAnchorStep) have their positions interpolated between the anchors a = Map(x0) and b =
// Map(x0 + n) as WarpSpan does; lo..hi-1 (x0 <= lo < hi <= x0 + n + 1) are computed.
struct WarpSpanJob {
  int32_t x0, n, ax, ay, bx, by, lo, hi;
};

// True when no position of the span samples inside the view, so every column's cost is
// r.invalid: its positions lie between its anchors (WarpSpan's steps are truncated toward zero),
// and a position is valid when its Q8 rounding lies in 0 .. (size - 1) * 256 on both axes, a test
// monotone in each axis. Kernels test it only on spans they cannot take on their fast path (the
// spans inside the view), so the common span pays nothing for it.
inline bool SpanOutsideView(const WarpRow& r, const WarpSpanJob& job) {
  const int32_t xmax = (r.width - 1) * 256, ymax = (r.height - 1) * 256;
  auto q8 = [](int32_t q16) { return (q16 + 128) >> 8; };
  return q8(job.ax > job.bx ? job.ax : job.bx) < 0 ||
         q8(job.ax < job.bx ? job.ax : job.bx) > xmax ||
         q8(job.ay > job.by ? job.ay : job.by) < 0 || q8(job.ay < job.by ? job.ay : job.by) > ymax;
}

// Columns lo..hi-1 of a span outside the view.
inline void FillInvalid(const WarpRow& r, const WarpSpanJob& job, uint8_t* out) {
  for (int32_t x = job.lo; x < job.hi; ++x) out[x] = r.invalid;
}

// A run of neighbouring spans along one row, each inner anchor shared by the spans either side
// of it, as PlaneCostRow hands them to a kernel: anchors k = 0..count (x_q16[k], y_q16[k], the
// exact Map) at reference columns x0 + kAnchorStep k, but the last, at column `last`: x0 +
// kAnchorStep count, or the row's last column when the run ends the row (a shorter span, whose
// end column is computed too). Columns lo..hi-1 are computed (x0 <= lo < hi <= last + 1). One
// call per run, not per span: the kernel sets itself up once and can test many spans at once.
struct WarpRun {
  const int32_t* x_q16;
  const int32_t* y_q16;
  int32_t x0, count, last, lo, hi;
};

// At most this many spans per run (PlaneCostRow's anchors live on its stack): 48 spans hold a
// 768-pixel row, so a depth row at 640 is one run.
inline constexpr int32_t kRunSpans = 48;

// Span k of a run as a job, its columns clipped to lo..hi (empty when the span lies outside).
inline WarpSpanJob RunSpan(const WarpRun& run, int32_t k) {
  const int32_t x0 = run.x0 + kAnchorStep * k;
  const bool inner = k + 1 < run.count;
  const int32_t n = inner ? kAnchorStep : run.last - x0;
  const int32_t end = inner ? x0 + kAnchorStep : run.last + 1;
  return WarpSpanJob{x0,
                     n,
                     run.x_q16[k],
                     run.y_q16[k],
                     run.x_q16[k + 1],
                     run.y_q16[k + 1],
                     x0 > run.lo ? x0 : run.lo,
                     end < run.hi ? end : run.hi};
}

// The spans of a run that hold columns lo..hi-1 (first, end): the others are not looked at.
inline void RunSpans(const WarpRun& run, int32_t* first, int32_t* end) {
  const int32_t a = (run.lo - run.x0) / kAnchorStep, b = (run.hi - 1 - run.x0) / kAnchorStep + 1;
  *first = a < run.count - 1 ? a : run.count - 1;
  *end = b < run.count ? b : run.count;
}

// A span kernel: the pixel costs of columns lo..hi-1 of a run into out (indexed by x). The C
// reference is dtk::PlaneSpansC (warp_cost.cc); the SIMD twins (warp_cost_avx2.cc,
// warp_cost_neon.cc) give the same bytes, and the data term picks one through its kernel table
// (data_term_kernels.h).
using PlaneSpanFn = void (*)(const WarpRow& row, const WarpRun& run, uint8_t* out);

// The anchors of one row after a first one: sums (den, nx, ny: PlaneRowMap::Sums at the first
// anchor) stepped by changes (PlaneRowMap::Changes), anchor k = 1..count into x_q16[k - 1],
// y_q16[k - 1] and ok[k - 1] as PlaneRowMap::FromSums gives them (0s where it refuses). True
// when every one maps. The C reference is dtk::PlaneAnchorsC (warp_cost.cc); the AVX2 twin
// (warp_cost_avx2.cc) gives the same values four anchors at a time.
using PlaneAnchorsFn = bool (*)(const int64_t* sums, const int64_t* changes, int32_t count,
                                int32_t* x_q16, int32_t* y_q16, bool* ok);

// Pixel costs 0..255 of columns x0..x1-1 of reference row y (out indexed by x) against the view
// seen through h (invalid_cost where a sample needs a pixel outside the view, or the plane has no
// map there). The anchors stay at multiples of kAnchorStep, so a column's cost does not depend on
// the range asked for. `span` and `anchors` are the kernels (nullptr: the C references).
void PlaneCostRow(const PlaneHomography& h, const WarpSource& src, int32_t y,
                  const DataTermParams& params, int32_t invalid_cost, int32_t x0, int32_t x1,
                  uint8_t* out, PlaneSpanFn span = nullptr, PlaneAnchorsFn anchors = nullptr);

}  // namespace lb
