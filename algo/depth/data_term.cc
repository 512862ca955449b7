#include "algo/depth/data_term.h"

#include <cstring>

#include "algo/core/clones.h"
#include "algo/core/int_math.h"
#include "algo/depth/data_term_kernels.h"
#include "algo/depth/warp_cost.h"

namespace lb {
namespace {

constexpr int32_t kLumaPad = 2;   // the census reaches 2 pixels left and right
constexpr int32_t kLumaRows = 5;  // and 2 rows up and down

// GCC counts a function whose only effect is __builtin_prefetch as pure, and drops the calls whose
// (void) result goes unused: this keeps them. A helper of PrefetchRow's would be dropped too,
// even when marked always_inline (PrefetchRow compiled to a bare return), so it spells its
// requests out.
#if defined(__GNUC__) && !defined(__clang__)
#define LB_KEEP_CALLS __attribute__((noipa))
#else
#define LB_KEEP_CALLS
#endif

// One request per cache line of p[0, bytes) (bytes > 0): a step of 64 from p meets every line
// but perhaps the last.
inline void PrefetchLines(const uint8_t* p, size_t bytes) {
  for (const uint8_t *q = p, *end = p + bytes; q < end; q += 64) __builtin_prefetch(q);
  __builtin_prefetch(p + bytes - 1);
}

// BT.601 luma, Q8 weights summing to 256, rounded; stored +/-128 (xor 0x80) so signed byte
// compares order it; borders replicated into the padding.
LB_CLONES_AVX2 void LumaRow(const uint8_t* rgb, int32_t w, uint8_t* out) {
  for (int32_t x = 0; x < w; ++x) {
    const int32_t l = (77 * rgb[3 * x] + 150 * rgb[3 * x + 1] + 29 * rgb[3 * x + 2] + 128) >> 8;
    out[x] = static_cast<uint8_t>(l ^ 0x80);
  }
  for (int32_t i = 1; i <= kLumaPad; ++i) {
    out[-i] = out[0];
    out[w - 1 + i] = out[w - 1];
  }
}

}  // namespace

bool DataTerm::UseSimd(bool on) {
  const DataTerm::Kernels* simd = on ? dtk::SimdKernels() : nullptr;
  kernels_ = simd != nullptr ? simd : &dtk::kReference;
  return simd != nullptr;
}

void DataTerm::Carve(Arena& arena, int32_t width, int32_t height, int32_t views, int32_t workers) {
  width_ = width;
  height_ = height;
  views_ = views;
  workers_ = Clamp(workers, 1, kMaxWorkers);
  const size_t n = static_cast<size_t>(width) * height;
  const size_t start = arena.used();
  for (int32_t v = 0; v < views; ++v) census_[v] = arena.Allocate<uint8_t>(3 * n);
  census_bytes_ = arena.used() - start;
  for (int32_t i = 0; i < workers_; ++i) {
    Scratch& s = scratch_[i];
    s.luma = arena.Allocate<uint8_t>(static_cast<size_t>(width + 2 * kLumaPad) * kLumaRows);
    s.pixel = arena.Allocate<uint8_t>(static_cast<size_t>(width) + 2 + 2 * dtk::kPixelSlack);
    s.hsum = arena.Allocate<uint16_t>(static_cast<size_t>(width) * 3 * (views - 1));
    s.ref_lanes = arena.Allocate<int32_t>(static_cast<size_t>(width) * 4);
  }
  runner_ = &inline_;
  UseSimd(true);
}

void DataTerm::SetRunner(TaskRunner* runner) {
  runner_ = runner != nullptr && runner->workers() <= workers_ ? runner : &inline_;
}

void DataTerm::SetParams(const DataTermParams& params, int32_t reference) {
  params_ = params;
  reference_ = reference;
  const int32_t c = params.color_trunc + kCensusBits * params.census_weight + 1;
  invalid_cost_ = c > 255 ? 255 : c;
}

void DataTerm::Prepare(const ConstImageU8* views) {
  images_ = views;
  ParallelFor(*runner_, views_,
              [&](int32_t v, int32_t worker) { CensusOfView(scratch_[worker], v); });
}

void DataTerm::CensusOfView(const Scratch& s, int32_t v) {
  const int32_t w = width_, h = height_;
  const ptrdiff_t pitch = w + 2 * kLumaPad;
  // Luma row r lives in ring slot r % 5 (the census needs rows y - 2 .. y + 2, clamped).
  auto slot = [&](int32_t r) { return s.luma + (r % kLumaRows) * pitch + kLumaPad; };
  for (int32_t r = 0; r < 2 && r < h; ++r) LumaRow(images_[v].Row(r), w, slot(r));
  for (int32_t y = 0; y < h; ++y) {
    if (y + 2 < h) LumaRow(images_[v].Row(y + 2), w, slot(y + 2));
    const uint8_t* rows[kLumaRows];
    for (int32_t k = 0; k < kLumaRows; ++k) rows[k] = slot(Clamp(y + k - 2, 0, h - 1));
    kernels_->census(rows, 0, w, w, census_[v] + static_cast<ptrdiff_t>(y) * 3 * w);
  }
}

void DataTerm::PixelCostRow(const PlaneHomography* planes, int32_t view, int32_t y, int32_t x0,
                            int32_t x1, uint8_t* out, const int32_t* ref_lanes) const {
  const WarpSource src{images_[reference_], images_[view], census_[reference_],
                       census_[view],       ref_lanes,     width_};
  PlaneCostRow(planes[view], src, y, params_, invalid_cost_, x0, x1, out, kernels_->plane,
               kernels_->plane_anchors);
}

// Horizontal 3-sum of the pixel costs of row y (borders replicated) for columns x0..x1-1:
// 0..765.
void DataTerm::WindowRow(const Scratch& s, const PlaneHomography* planes, int32_t view, int32_t y,
                         int32_t x0, int32_t x1, uint16_t* hsum) const {
  const int32_t w = width_;
  uint8_t* cost = s.pixel + 1;
  const int32_t c0 = x0 > 0 ? x0 - 1 : 0, c1 = x1 < w ? x1 + 1 : w;
  const bool lanes = kernels_->plane_lanes != nullptr;
  PixelCostRow(planes, view, Clamp(y, 0, height_ - 1), c0, c1, cost, lanes ? s.ref_lanes : nullptr);
  if (x0 == 0) cost[-1] = cost[0];
  if (x1 == w) cost[w] = cost[w - 1];
  kernels_->hsum(cost, x0, x1, hsum);
}

void DataTerm::PrepareRefLanes(const Scratch& s, const PlaneHomography* planes, int32_t y,
                               int32_t x0, int32_t x1) const {
  if (planes == nullptr || kernels_->plane_lanes == nullptr) return;
  const int32_t w = width_, row = Clamp(y, 0, height_ - 1);
  const int32_t c0 = x0 > 0 ? x0 - 1 : 0, c1 = x1 < w ? x1 + 1 : w;  // as WindowRow
  const int32_t a = RefLanesBegin(w, c0);  // s.ref_lanes is indexed by x: column a at + a
  kernels_->plane_lanes(images_[reference_].Row(row),
                        census_[reference_] + static_cast<ptrdiff_t>(row) * 3 * w, w, a,
                        RefLanesEnd(w, c1), s.ref_lanes + a, w);
}

// The views' next rows are far apart (a whole view each), so the hardware prefetcher misses their
// starts; asking early hides the cache misses behind the other views. Rectified shifts read row
// y of each view and of its three census planes, at the label's shift. The plane sweep samples view
// v near H_v(x, y), rows away from y and along a slanted line: per chunk of columns, the rows and
// columns between the chunk's two ends (and the row below, for the bilinear taps). On the
// handheld burst this cut the restricted moves' data term by a quarter.
LB_KEEP_CALLS void DataTerm::PrefetchRow(int32_t y, int32_t x0, int32_t x1,
                                         const dtk::RectRow& shifts) const {
  const int32_t w = width_, h = height_, others = views_ - 1;
  const int32_t row = Clamp(y, 0, h - 1);
  // The reference's own row: a restricted run starts anywhere in it, so no stream finds it.
  const size_t cols = static_cast<size_t>(x1 - x0);
  PrefetchLines(images_[reference_].Row(row) + 3 * x0, 3 * cols);
  const uint8_t* ref_census = census_[reference_] + static_cast<ptrdiff_t>(row) * 3 * w + x0;
  for (int32_t k = 0; k < 3; ++k) PrefetchLines(ref_census + k * w, cols);
  if (planes_ == nullptr) {
    for (int32_t j = 0; j < others; ++j) {
      // The columns the run's costs sample (one more each side for the 3-sums), at the shift.
      const int32_t off = shifts.shift_q8[j] >> 8;
      const int32_t c0 = Clamp(x0 - 1 + off, 0, w - 1), c1 = Clamp(x1 + 2 + off, c0 + 1, w);
      const size_t m = static_cast<size_t>(c1 - c0);
      PrefetchLines(images_[OtherView(j)].Row(row) + 3 * c0, 3 * m);
      const uint8_t* census = census_[OtherView(j)] + static_cast<ptrdiff_t>(row) * 3 * w + c0;
      for (int32_t k = 0; k < 3; ++k) PrefetchLines(census + k * w, m);
    }
    return;
  }
  // The view positions of the chunks' ends only pick lines to ask for, so they come from the
  // homography in double (one division), not from the exact integer Map (two 64-bit ones). A
  // position off by a rounding asks for a neighbouring line; whole pixels, truncated.
  constexpr int32_t kChunk = 64, kMaxRows = 4;
  constexpr double kMinDen = 1 << 20, kMaxDen = 4294967296.0, kMaxPos = 1 << 14;
  for (int32_t j = 0; j < others; ++j) {
    const int32_t v = OtherView(j);
    const int64_t* m = planes_[v].m;
    const double den_row = static_cast<double>(m[7] * row + m[8]);
    const double nx_row = static_cast<double>(m[1] * row + m[2]);
    const double ny_row = static_cast<double>(m[4] * row + m[5]);
    const double m6 = static_cast<double>(m[6]), m0 = static_cast<double>(m[0]);
    const double m3 = static_cast<double>(m[3]);
    auto at = [&](int32_t x, int32_t* px, int32_t* py) {
      const double den = m6 * x + den_row;
      if (!(den >= kMinDen && den < kMaxDen)) return false;
      const double inv = 1.0 / den, fx = (m0 * x + nx_row) * inv, fy = (m3 * x + ny_row) * inv;
      if (!(fx > -kMaxPos && fx < kMaxPos && fy > -kMaxPos && fy < kMaxPos)) return false;
      *px = static_cast<int32_t>(fx);
      *py = static_cast<int32_t>(fy);
      return true;
    };
    int32_t ax = 0, ay = 0;
    bool a_ok = at(x0, &ax, &ay);
    for (int32_t c = x0; c < x1; c += kChunk) {
      int32_t bx = 0, by = 0;
      const bool b_ok = at(Min(c + kChunk, x1 - 1), &bx, &by);
      const int32_t r0 = Max(Min(ay, by), 0), r1 = Min(Max(ay, by) + 1, h - 1);
      const int32_t c0 = Max(Min(ax, bx) - 1, 0), c1 = Min(Max(ax, bx) + 2, w);
      // A chunk crossing more rows is steep (a plane seen almost edge-on): not worth asking for.
      if (a_ok && b_ok && r1 - r0 <= kMaxRows && c0 < c1) {
        const size_t n = static_cast<size_t>(c1 - c0);
        for (int32_t r = r0; r <= r1; ++r) {
          PrefetchLines(images_[v].Row(r) + 3 * c0, 3 * n);
          const uint8_t* census = census_[v] + static_cast<ptrdiff_t>(r) * 3 * w + c0;
          for (int32_t k = 0; k < 3; ++k) PrefetchLines(census + k * w, n);
        }
      }
      ax = bx;
      ay = by;
      a_ok = b_ok;
    }
  }
}

void DataTerm::StartRows(int32_t disp_q8, dtk::RectRow* row) const {
  row->others = views_ - 1;
  row->width = width_;
  row->trunc = params_.color_trunc;
  row->cw = params_.census_weight;
  row->invalid = invalid_cost_;
  // Sample position in view v: x * 256 + shift_q8, the same fraction for every pixel.
  for (int32_t j = 0; j < row->others; ++j) {
    row->shift_q8[j] = -(OtherView(j) - reference_) * disp_q8;
  }
}

void DataTerm::WindowRows(const Scratch& s, const PlaneHomography* planes, int32_t y, int32_t x0,
                          int32_t x1, dtk::RectRow* row) const {
  const int32_t others = views_ - 1;
  if (planes != nullptr) {
    // Row by row, so the plane sweep prepares each reference row once for every view.
    PrepareRefLanes(s, planes, y, x0, x1);
    for (int32_t j = 0; j < others; ++j) {
      WindowRow(s, planes, OtherView(j), y, x0, x1, row->hsum[j]);
    }
    return;
  }
  const int32_t r = Clamp(y, 0, height_ - 1), w = width_;
  const ptrdiff_t census_row = static_cast<ptrdiff_t>(r) * 3 * w;
  row->ref = images_[reference_].Row(r);
  row->cref = census_[reference_] + census_row;
  for (int32_t j = 0; j < others; ++j) {
    row->img[j] = images_[OtherView(j)].Row(r);
    row->cimg[j] = census_[OtherView(j)] + census_row;
  }
  row->x0 = x0;
  row->x1 = x1;
  row->pixel = s.pixel;
  kernels_->rect_row(*row);
}

int32_t DataTerm::Bands(int32_t rows, int64_t pixels) const {
  // A band's first two rows of 3-sums are its overhead, and a task costs a wake-up: bands of
  // at least kMinBandRows rows and kMinBandPixels pixels, a few per worker to even out the load,
  // and one band on a single worker (more would only add their overhead).
  constexpr int32_t kMinBandRows = 8, kMinBandPixels = 8192, kBandsPerWorker = 4;
  int32_t bands = runner_->workers() > 1 ? runner_->workers() * kBandsPerWorker : 1;
  bands = Min(bands, rows / kMinBandRows);
  return Min(bands, static_cast<int32_t>(pixels / kMinBandPixels));
}

void DataTerm::ComputeRect(int32_t disp_q8, int32_t x0, int32_t x1, int32_t y0, int32_t y1,
                           uint16_t* out, ptrdiff_t stride) {
  const int32_t rows = y1 - y0, cols = x1 - x0;
  const int32_t bands = Bands(rows, int64_t{rows} * cols);
  if (bands <= 1) {
    ComputeBand(scratch_[0], planes_, scratch_[0].hsum, false, disp_q8, x0, x1, y0, y1, out,
                stride);
    return;
  }
  ParallelFor(*runner_, bands, [&](int32_t band, int32_t worker) {
    const int32_t b0 = y0 + static_cast<int32_t>(int64_t{rows} * band / bands);
    const int32_t b1 = y0 + static_cast<int32_t>(int64_t{rows} * (band + 1) / bands);
    const Scratch& s = scratch_[worker];
    ComputeBand(s, planes_, s.hsum, false, disp_q8, x0, x1, b0, b1, out + (b0 - y0) * stride,
                stride);
  });
}

void DataTerm::ComputeRowsCarried(int32_t disp_q8, const PlaneHomography* planes, int32_t y0,
                                  int32_t y1, bool continues, uint16_t* ring, uint16_t* out,
                                  ptrdiff_t stride, int32_t worker) {
  if (y0 >= y1) return;
  ComputeBand(scratch_[Clamp(worker, 0, workers_ - 1)], planes, ring, continues, disp_q8, 0, width_,
              y0, y1, out, stride);
}

void RowRuns::Add(int32_t lo, int32_t hi, int32_t width, int32_t join) {
  if (hi - lo < kMinWidth && width >= kMinWidth) {
    lo = Clamp((lo + hi - kMinWidth) / 2, 0, width - kMinWidth);
    hi = lo + kMinWidth;
  }
  // Joined to the run before when it is near (widening may even overlap it), or when full.
  if (count > 0 && (lo - x[2 * count - 1] < join || count == kMax)) {
    x[2 * count - 1] = Max(x[2 * count - 1], hi);
    return;
  }
  x[2 * count] = lo;
  x[2 * count + 1] = hi;
  ++count;
}

void RowRuns::FromMarks(const uint8_t* mark, int32_t lo, int32_t hi, int32_t width, int32_t join) {
  // Marks are 0 or 1: eight at a time while a word is all 0 (a gap) or all 1 (a run).
  constexpr uint64_t kOnes = 0x0101010101010101u;
  auto word = [&](int32_t x) {
    uint64_t v;
    memcpy(&v, mark + x, sizeof(v));
    return v;
  };
  count = 0;
  int32_t start = -1, end = -1;  // the run being gathered: [start, end)
  for (int32_t x = lo; x < hi;) {
    while (x + 8 <= hi && word(x) == 0) x += 8;
    while (x < hi && mark[x] == 0) ++x;
    if (x >= hi) break;
    int32_t e = x + 1;
    while (e + 8 <= hi && word(e) == kOnes) e += 8;
    while (e < hi && mark[e] != 0) ++e;
    if (start >= 0 && x - end >= join) {
      Add(start, end, width, join);
      start = -1;
    }
    if (start < 0) start = x;
    end = e;
    x = e;
  }
  if (start >= 0) Add(start, end, width, join);
}

void DataTerm::ComputeRuns(int32_t disp_q8, const RowRuns* runs, int32_t y0, int32_t y1,
                           uint16_t* out, ptrdiff_t stride) {
  const int32_t rows = y1 - y0;
  int64_t pixels = 0;
  for (int32_t y = y0; y < y1; ++y) {
    for (int32_t k = 0; k < runs[y].count; ++k) pixels += runs[y].x[2 * k + 1] - runs[y].x[2 * k];
  }
  const int32_t bands = Bands(rows, pixels);
  if (bands <= 1) {
    ComputeRunBand(scratch_[0], disp_q8, runs, y0, y1, out, stride);
    return;
  }
  // Bands of equal rows: the runs of a restricted move are spread over the image.
  ParallelFor(*runner_, bands, [&](int32_t band, int32_t worker) {
    const int32_t b0 = y0 + static_cast<int32_t>(int64_t{rows} * band / bands);
    const int32_t b1 = y0 + static_cast<int32_t>(int64_t{rows} * (band + 1) / bands);
    ComputeRunBand(scratch_[worker], disp_q8, runs, b0, b1, out + (b0 - y0) * stride, stride);
  });
}

namespace {

// The columns of ring row r's 3-sums that rows r - 1 .. r + 1 of the band y0..y1-1 read: the
// union of their runs, ascending, joined where closer than `join`. Returns the count (at most
// 3 * RowRuns::kMax) of [iv[2k], iv[2k + 1]).
int32_t NeededColumns(const RowRuns* runs, int32_t r, int32_t y0, int32_t y1, int32_t join,
                      int32_t* iv) {
  int32_t n = 0;
  for (int32_t y = Max(r - 1, y0); y <= r + 1 && y < y1; ++y) {
    for (int32_t k = 0; k < runs[y].count; ++k) {
      const int32_t a = runs[y].x[2 * k], b = runs[y].x[2 * k + 1];
      if (a >= b) continue;
      int32_t i = n++;  // insertion by start
      for (; i > 0 && iv[2 * i - 2] > a; --i) {
        iv[2 * i] = iv[2 * i - 2];
        iv[2 * i + 1] = iv[2 * i - 1];
      }
      iv[2 * i] = a;
      iv[2 * i + 1] = b;
    }
  }
  int32_t m = 0;
  for (int32_t i = 0; i < n; ++i) {
    if (m > 0 && iv[2 * i] - iv[2 * m - 1] < join) {
      iv[2 * m - 1] = Max(iv[2 * m - 1], iv[2 * i + 1]);
    } else {
      iv[2 * m] = iv[2 * i];
      iv[2 * m + 1] = iv[2 * i + 1];
      ++m;
    }
  }
  return m;
}

}  // namespace

void DataTerm::ComputeRunBand(const Scratch& s, int32_t disp_q8, const RowRuns* runs, int32_t y0,
                              int32_t y1, uint16_t* out, ptrdiff_t stride) const {
  const int32_t w = width_;
  const int32_t others = views_ - 1;
  auto ring = [&](int32_t j, int32_t row) {
    return s.hsum + (static_cast<size_t>(j) * 3 + static_cast<size_t>((row - y0 + 1) % 3)) * w;
  };
  dtk::RectRow row;
  StartRows(disp_q8, &row);
  int32_t iv[2 * 3 * RowRuns::kMax];
  const int32_t join = RunJoin();
  auto window_rows = [&](int32_t r, int32_t n) {
    for (int32_t j = 0; j < others; ++j) row.hsum[j] = ring(j, r);
    for (int32_t i = 0; i < n; ++i) WindowRows(s, planes_, r, iv[2 * i], iv[2 * i + 1], &row);
  };
  for (int32_t r = y0 - 1; r <= y0; ++r) window_rows(r, NeededColumns(runs, r, y0, y1, join, iv));
  // The columns of row y + 1, found one row earlier for their prefetch.
  int32_t n = NeededColumns(runs, y0 + 1, y0, y1, join, iv);
  for (int32_t y = y0; y < y1; ++y) {
    window_rows(y + 1, n);
    // As ComputeBand: ask early for the views' next rows, which the prefetcher misses.
    n = NeededColumns(runs, y + 2, y0, y1, join, iv);
    for (int32_t i = 0; i < n; ++i) PrefetchRow(y + 2, iv[2 * i], iv[2 * i + 1], row);
    // The ring's three rows of each view are y - 1 .. y + 1.
    for (int32_t k = 0; k < runs[y].count; ++k) {
      const int32_t x0 = runs[y].x[2 * k], x1 = runs[y].x[2 * k + 1];
      if (x0 < x1)
        kernels_->select(s.hsum, w, others, 9 * invalid_cost_, x0, x1, out + (y - y0) * stride);
    }
  }
}

void DataTerm::ComputeBand(const Scratch& s, const PlaneHomography* planes, uint16_t* hsum,
                           bool continues, int32_t disp_q8, int32_t x0, int32_t x1, int32_t y0,
                           int32_t y1, uint16_t* out, ptrdiff_t stride) const {
  const int32_t w = width_;
  const int32_t others = views_ - 1;
  auto ring = [&](int32_t j, int32_t row) {  // row >= -1
    return hsum + (static_cast<size_t>(j) * 3 + static_cast<size_t>((row + 3) % 3)) * w;
  };
  dtk::RectRow row;
  StartRows(disp_q8, &row);
  auto window_rows = [&](int32_t r) {
    for (int32_t j = 0; j < others; ++j) row.hsum[j] = ring(j, r);
    WindowRows(s, planes, r, x0, x1, &row);
  };
  if (!continues) {
    for (int32_t r = y0 - 1; r <= y0; ++r) window_rows(r);
  }
  for (int32_t y = y0; y < y1; ++y) {
    window_rows(y + 1);
    // No PrefetchRow: whole rows follow each other in every view (a stream the hardware
    // prefetcher follows), and the winner-take-all's bands keep them in cache from one label to
    // the next; asking again cost more than it saved (teddy's shifts, as the plane sweep).
    // The ring's three rows of each view are y - 1 .. y + 1, in any order.
    kernels_->select(hsum, w, others, 9 * invalid_cost_, x0, x1, out + (y - y0) * stride);
  }
}

}  // namespace lb
