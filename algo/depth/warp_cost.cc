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

bool PlaneAnchorsC(const int64_t* sums, const int64_t* changes, int32_t count, int32_t* x_q16,
                   int32_t* y_q16, bool* ok) {
  // Where a 64-bit division is an instruction (x86-64, aarch64) Map's two are as fast as the
  // row map's estimate and correction; on 32-bit ARM they are library calls.
  constexpr bool kExactDivide = sizeof(void*) >= 8;
  int64_t den = sums[0], nx = sums[1], ny = sums[2];
  bool all = true;
  for (int32_t k = 0; k < count; ++k) {
    den += changes[0];
    nx += changes[1];
    ny += changes[2];
    ok[k] = PlaneRowMap::FromSums<kExactDivide>(den, nx, ny, &x_q16[k], &y_q16[k]);
    if (!ok[k]) x_q16[k] = y_q16[k] = 0;
    all &= ok[k];
  }
  return all;
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
                  int32_t x_end, uint8_t* out, PlaneSpanFn span, PlaneAnchorsFn anchors) {
  if (span == nullptr) span = dtk::PlaneSpansC;
  if (anchors == nullptr) anchors = dtk::PlaneAnchorsC;
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
                    static_cast<uint8_t>(invalid_cost),
                    src.ref_lanes,
                    0,
                    src.lanes_stride};
  int32_t first = x_begin - x_begin % kAnchorStep;
  if (first == w - 1 && first > 0) first -= kAnchorStep;  // w - 1 ends the span before it
  // A span's end anchor is the next one's start: one Map per span.
  constexpr bool kExactDivide = sizeof(void*) >= 8;  // as PlaneAnchorsC
  const PlaneRowMap row_map(h, y);
  // An anchor that does not map gets 0s: its entries are copied along, never read.
  auto map = [&](int32_t x, int32_t* x_q16, int32_t* y_q16) {
    const bool ok = row_map.At<kExactDivide>(x, x_q16, y_q16);
    if (!ok) *x_q16 = *y_q16 = 0;
    return ok;
  };
  // Spans x0 = first + kAnchorStep k up to x_end, the last one ending on column w - 1; each
  // chunk of up to kRunSpans spans maps its anchors in one tight loop, then goes to the kernel as
  // one run, or, where a plane has no map at some anchor, as the runs between (the spans
  // touching that anchor cost `invalid`).
  // Not zeroed (a fill per call costs a fair part of this short function's time): every entry
  // is written before it is read.
  int32_t ax[kRunSpans + 1], ay[kRunSpans + 1];
  bool ok[kRunSpans + 1];
  ok[0] = map(first, &ax[0], &ay[0]);
  for (int32_t x0 = first; x0 < x_end;) {
    // Spans of this chunk: while the span starting at x0 + kAnchorStep k begins before x_end.
    const int32_t left = (x_end - x0 + kAnchorStep - 1) / kAnchorStep;
    const int32_t count = left < kRunSpans ? left : kRunSpans;
    bool all = ok[0];
    // The anchors on the grid before w - 1, their sums stepped along the row.
    const int32_t grid = (w - 2 - x0) / kAnchorStep;  // x0 + kAnchorStep k < w - 1 for k <= grid
    const int32_t stepped = count < grid ? count : grid;
    int64_t sums[3], changes[3];
    row_map.Sums(x0, sums);
    row_map.Changes(kAnchorStep, changes);
    if (stepped > 0) all &= anchors(sums, changes, stepped, ax + 1, ay + 1, ok + 1);
    int32_t k = stepped + 1;
    int32_t spans = k - 1, last = x0 + kAnchorStep * spans;
    if (k <= count) {
      // The row's last span ends on column w - 1 (w - 1 - x0 <= kAnchorStep k; a row of one
      // column has a single anchor, start and end).
      last = w - 1;
      spans = k;
      ok[k] = last == x0 + kAnchorStep * (k - 1) ? ok[k - 1] : map(last, &ax[k], &ay[k]);
      if (last == x0 + kAnchorStep * (k - 1)) {
        ax[k] = ax[k - 1];
        ay[k] = ay[k - 1];
      }
      all &= ok[k];
    }
    const int32_t end = last == w - 1 ? w : last;  // columns x0 .. end - 1 are this chunk's
    const int32_t lo = x0 > x_begin ? x0 : x_begin, hi = end < x_end ? end : x_end;
    if (all) {
      span(row, WarpRun{ax, ay, x0, spans, last, lo, hi}, out);
    } else {
      // Runs of spans whose anchors all map; the others invalid.
      for (int32_t s = 0; s < spans;) {
        const int32_t sx = x0 + kAnchorStep * s;
        if (!ok[s] || !ok[s + 1]) {
          const int32_t se = s + 1 == spans ? end : sx + kAnchorStep;
          for (int32_t x = sx > lo ? sx : lo; x < se && x < hi; ++x) out[x] = row.invalid;
          ++s;
          continue;
        }
        int32_t e = s + 1;
        while (e < spans && ok[e + 1]) ++e;
        const int32_t run_last = e == spans ? last : x0 + kAnchorStep * e;
        const int32_t run_end = e == spans ? end : run_last;
        const int32_t run_lo = sx > lo ? sx : lo, run_hi = run_end < hi ? run_end : hi;
        if (run_lo < run_hi) {
          span(row, WarpRun{ax + s, ay + s, sx, e - s, run_last, run_lo, run_hi}, out);
        }
        s = e;
      }
    }
    if (end >= x_end) break;
    x0 = last;
    ax[0] = ax[spans];
    ay[0] = ay[spans];
    ok[0] = ok[spans];
  }
}

}  // namespace lb
