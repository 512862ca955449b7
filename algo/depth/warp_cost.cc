#include "algo/depth/warp_cost.h"

#include "algo/depth/data_term_kernels.h"

namespace lb {
namespace {

// The same halving-sum bit count as data_term.cc (baseline x86-64 has no popcount).
inline int32_t BitCount(uint32_t v) {
  v = v - ((v >> 1) & 0x55555555u);
  v = (v & 0x33333333u) + ((v >> 2) & 0x33333333u);
  v = (v + (v >> 4)) & 0x0f0f0f0fu;
  v = v + (v >> 8);
  v = v + (v >> 16);
  return static_cast<int32_t>(v & 0x3fu);
}

// The 24-bit census of pixel x of a census row (three planes of `width` bytes).
inline uint32_t Census(const uint8_t* row, int32_t width, int32_t x) {
  return (uint32_t{row[x]} << 16) | (uint32_t{row[width + x]} << 8) | row[2 * width + x];
}

// One pixel: ref_rgb / cref are the reference pixel and its census, (x_q16, y_q16) the view
// position. The position is rounded half up to Q8; the 4 bilinear weights (256 - f) * (256 - g)
// etc. are Q16 and sum to 65536, so a colour sum is <= 255 * 65536 (int32), rounded half up to
// Q0. The census tap is the nearest (fractions of 128/256 round up). Cost 0..255 as in
// data_term.cc: min(|dRGB|, trunc) + 24 bits * weight <= 765 + 240, capped.
inline uint8_t SampleCost(const WarpRow& r, const uint8_t* ref_rgb, uint32_t cref, int32_t x_q16,
                          int32_t y_q16) {
  const int32_t xs = (x_q16 + 128) >> 8, ys = (y_q16 + 128) >> 8;  // |q16| < 2^30: no overflow
  const int32_t x0 = xs >> 8, y0 = ys >> 8, fx = xs & 255, fy = ys & 255;
  // A tap of weight zero may sit outside the view, as in the rectified kernel.
  const int32_t x1 = x0 + (fx != 0 ? 1 : 0), y1 = y0 + (fy != 0 ? 1 : 0);
  if (x0 < 0 || y0 < 0 || x1 >= r.width || y1 >= r.height) return r.invalid;
  const int32_t w00 = (256 - fx) * (256 - fy), w01 = fx * (256 - fy);
  const int32_t w10 = (256 - fx) * fy, w11 = fx * fy;
  const uint8_t* a = r.view + y0 * r.stride + 3 * x0;
  const uint8_t* b = r.view + y0 * r.stride + 3 * x1;
  const uint8_t* c = r.view + y1 * r.stride + 3 * x0;
  const uint8_t* d = r.view + y1 * r.stride + 3 * x1;
  int32_t ad = 0;
  for (int32_t ch = 0; ch < 3; ++ch) {
    const int32_t v = (a[ch] * w00 + b[ch] * w01 + c[ch] * w10 + d[ch] * w11 + 32768) >> 16;
    const int32_t diff = ref_rgb[ch] - v;
    ad += diff < 0 ? -diff : diff;
  }
  ad = ad < r.trunc ? ad : r.trunc;
  const int32_t nx = fx >= 128 ? x1 : x0, ny = fy >= 128 ? y1 : y0;
  const uint8_t* crow = r.census_view + static_cast<ptrdiff_t>(ny) * 3 * r.width;
  const int32_t ham = BitCount(cref ^ Census(crow, r.width, nx));
  const int32_t cost = ad + ham * r.cw;
  return static_cast<uint8_t>(cost > 255 ? 255 : cost);
}

// Positions 0..n of a span from its anchors (WarpSpan).
void SpanPositions(int32_t ax, int32_t ay, int32_t bx, int32_t by, int32_t n, int32_t* x_q16,
                   int32_t* y_q16) {
  x_q16[0] = ax;
  y_q16[0] = ay;
  if (n == 0) return;
  // Q32 accumulators, started half a Q16 step up so the shift rounds; the truncated steps lose
  // under n * 2^-32 px over the span.
  const int64_t sx = (int64_t{bx} - ax) * 65536 / n, sy = (int64_t{by} - ay) * 65536 / n;
  int64_t px = int64_t{ax} * 65536 + 32768, py = int64_t{ay} * 65536 + 32768;
  for (int32_t i = 1; i < n; ++i) {
    px += sx;
    py += sy;
    x_q16[i] = static_cast<int32_t>(px >> 16);
    y_q16[i] = static_cast<int32_t>(py >> 16);
  }
  x_q16[n] = bx;
  y_q16[n] = by;
}

}  // namespace

namespace dtk {

void PlaneSpansC(const WarpRow& row, const WarpRun& run, uint8_t* out) {
  int32_t first = 0, end = 0;
  RunSpans(run, &first, &end);
  for (int32_t k = first; k < end; ++k) {
    const WarpSpanJob job = RunSpan(run, k);
    if (job.lo >= job.hi) continue;
    if (SpanOutsideView(row, job)) {
      FillInvalid(row, job, out);
      continue;
    }
    int32_t xq[kAnchorStep + 1], yq[kAnchorStep + 1];
    SpanPositions(job.ax, job.ay, job.bx, job.by, job.n, xq, yq);
    for (int32_t x = job.lo; x < job.hi; ++x) {
      out[x] = SampleCost(row, row.ref + 3 * x, Census(row.cref, row.width, x), xq[x - job.x0],
                          yq[x - job.x0]);
    }
  }
}

}  // namespace dtk

bool WarpSpan(const PlaneHomography& h, int32_t x0, int32_t x1, int32_t y, int32_t* x_q16,
              int32_t* y_q16) {
  int32_t ax = 0, ay = 0, bx = 0, by = 0;
  if (!h.Map(x0, y, &ax, &ay) || !h.Map(x1, y, &bx, &by)) return false;
  SpanPositions(ax, ay, bx, by, x1 - x0, x_q16, y_q16);
  return true;
}

void PlaneCostRow(const PlaneHomography& h, const WarpSource& src, int32_t y,
                  const DataTermParams& params, int32_t invalid_cost, int32_t x_begin,
                  int32_t x_end, uint8_t* out, PlaneSpanFn span) {
  if (span == nullptr) span = dtk::PlaneSpansC;
  const int32_t w = src.ref.width;
  const ptrdiff_t census_row = static_cast<ptrdiff_t>(y) * 3 * w;
  const WarpRow row{src.view.data,
                    src.view.stride,
                    src.census_view,
                    src.ref.Row(y),
                    src.census_ref + census_row,
                    w,
                    src.ref.height,
                    params.color_trunc,
                    params.census_weight,
                    static_cast<uint8_t>(invalid_cost)};
  int32_t first = x_begin - x_begin % kAnchorStep;
  if (first == w - 1 && first > 0) first -= kAnchorStep;  // w - 1 ends the span before it
  // A span's end anchor is the next one's start: one Map per span.
  // Where a 64-bit division is an instruction (x86-64, aarch64) Map's two are as fast as the
  // row map's estimate and correction; on 32-bit ARM they are library calls.
  constexpr bool kExactDivide = sizeof(void*) >= 8;
  const PlaneRowMap row_map(h, y);
  auto map = [&](int32_t x, int32_t* x_q16, int32_t* y_q16) {
    return row_map.At<kExactDivide>(x, x_q16, y_q16);
  };
  // The run being gathered: its anchors so far (the next span's start anchor is the last one),
  // its first span's start column and first wanted column. A run ends where a plane has no map
  // (those spans cost `invalid`), when it is full, and at the end of the range.
  int32_t ax[kRunSpans + 1] = {}, ay[kRunSpans + 1] = {};
  int32_t count = 0, run_x0 = first, run_lo = x_begin;
  auto flush = [&](int32_t last, int32_t hi) {
    if (count > 0) span(row, WarpRun{ax, ay, run_x0, count, last, run_lo, hi}, out);
    ax[0] = ax[count];
    ay[0] = ay[count];
    count = 0;
  };
  bool a_ok = map(first, &ax[0], &ay[0]);
  int32_t last = first, last_hi = first;
  for (int32_t x0 = first, end = 0; x0 < x_end; x0 = end) {
    const int32_t x1 = x0 + kAnchorStep < w - 1 ? x0 + kAnchorStep : w - 1;
    end = x1 == w - 1 ? w : x1;  // the last span keeps its end anchor
    const int32_t lo = x0 > x_begin ? x0 : x_begin, hi = end < x_end ? end : x_end;
    int32_t bx = ax[count], by = ay[count];
    const bool b_ok = x1 == x0 ? a_ok : map(x1, &bx, &by);
    if (a_ok && b_ok) {
      if (count == 0) {
        run_x0 = x0;
        run_lo = lo;
      }
      ++count;
      ax[count] = bx;
      ay[count] = by;
      last = x1;
      last_hi = hi;
      if (count == kRunSpans) flush(last, last_hi);
    } else {
      flush(last, last_hi);
      for (int32_t x = lo; x < hi; ++x) out[x] = row.invalid;
      ax[0] = bx;
      ay[0] = by;
    }
    a_ok = b_ok;
  }
  flush(last, last_hi);
}

}  // namespace lb
