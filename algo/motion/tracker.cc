#include "algo/motion/tracker.h"

namespace lb {
namespace {

// True when the window of half size `half` around (x, y) can be sampled bilinearly.
inline bool Inside(const ImageU8& img, int32_t x_q16, int32_t y_q16, int32_t half) {
  const int32_t x0 = (x_q16 >> 16) - half, y0 = (y_q16 >> 16) - half;
  return x0 >= 0 && y0 >= 0 && x0 + 2 * half + 1 < img.width && y0 + 2 * half + 1 < img.height;
}

inline int32_t RoundQ16(double v) {
  const double s = v * 65536.0;
  return static_cast<int32_t>(s >= 0 ? s + 0.5 : s - 0.5);
}

}  // namespace

Status Tracker::Carve(const TrackerParams& params, Arena& arena, int32_t workers) {
  if (params.radius < 1 || params.radius > 8 || params.max_iterations < 1 ||
      params.max_iterations > 50 || params.max_error_q4 < 1) {
    return Status(Code::kInvalidArgument, "tracker: radius %d (1..8), iterations %d (1..50)",
                  params.radius, params.max_iterations);
  }
  if (workers < 1 || workers > kMaxWorkers) {
    return Status(Code::kInvalidArgument, "tracker: %d workers (1..%d)", workers, kMaxWorkers);
  }
  params_ = params;
  workers_ = workers;
  const tk::Kernels* simd = tk::SimdKernels();
  kernels_ = simd != nullptr ? simd : &tk::kReference;
  const size_t t = 2 * static_cast<size_t>(params.radius) + 3;
  const size_t w = 2 * static_cast<size_t>(params.radius) + 1;
  for (int32_t i = 0; i < workers; ++i) {
    windows_[i].tmpl = arena.Allocate<int32_t>(t * t);
    windows_[i].inner = arena.Allocate<int32_t>(w * w);
    windows_[i].gx = arena.Allocate<int32_t>(w * w);
    windows_[i].gy = arena.Allocate<int32_t>(w * w);
  }
  return Status::Ok();
}

void Tracker::Track(const GreyPyramid& ref, const GreyPyramid& view, const int32_t* x_q16,
                    const int32_t* y_q16, int32_t n, int32_t* dx_q16, int32_t* dy_q16, uint8_t* ok,
                    TaskRunner* runner) const {
  // Runs of points a task: enough to outweigh a wake-up, small enough to even out the load.
  constexpr int32_t kRun = 64;
  if (runner == nullptr || runner->workers() > workers_ || n <= kRun) {
    TrackRange(windows_[0], ref, view, x_q16, y_q16, 0, n, dx_q16, dy_q16, ok);
    return;
  }
  ParallelFor(*runner, (n + kRun - 1) / kRun, [&](int32_t task, int32_t worker) {
    const int32_t begin = task * kRun, end = begin + kRun < n ? begin + kRun : n;
    TrackRange(windows_[worker], ref, view, x_q16, y_q16, begin, end, dx_q16, dy_q16, ok);
  });
}

void Tracker::TrackRange(const Window& w, const GreyPyramid& ref, const GreyPyramid& view,
                         const int32_t* x_q16, const int32_t* y_q16, int32_t begin, int32_t end,
                         int32_t* dx_q16, int32_t* dy_q16, uint8_t* ok) const {
  for (int32_t i = begin; i < end; ++i) {
    const bool guessed = dx_q16[i] != 0 || dy_q16[i] != 0;
    int32_t error = 0;
    // From a guess only the two finest levels run: the coarse ones alias a fine repetitive
    // texture and would drag the start off to a wrong period.
    const int32_t top = guessed && ref.levels() > 2 ? 1 : ref.levels() - 1;
    bool found = TrackOne(w, ref, view, x_q16[i], y_q16[i], top, &dx_q16[i], &dy_q16[i], &error);
    if (guessed) {
      int32_t dx0 = 0, dy0 = 0, error0 = 0;
      // The guess wins unless no motion matches clearly better (half the error): on a
      // repetitive texture both starts match about as well, and only the guess is right.
      if (TrackOne(w, ref, view, x_q16[i], y_q16[i], ref.levels() - 1, &dx0, &dy0, &error0) &&
          (!found || 2 * error0 < error)) {
        found = true;
        dx_q16[i] = dx0;
        dy_q16[i] = dy0;
      }
    }
    ok[i] = found ? 1 : 0;
  }
}

bool Tracker::TrackOne(const Window& w, const GreyPyramid& ref, const GreyPyramid& view,
                       int32_t x_q16, int32_t y_q16, int32_t top, int32_t* dx_q16, int32_t* dy_q16,
                       int32_t* error_q4) const {
  const int32_t r = params_.radius;
  const int32_t tw = 2 * r + 3, ww = 2 * r + 1;
  constexpr int32_t kHalfQ16 = 1 << 15;
  int32_t dx = *dx_q16, dy = *dy_q16;
  dx >>= top;  // the guess, at the coarsest level
  dy >>= top;
  int32_t mean_error = 0;
  for (int32_t level = top; level >= 0; --level) {
    const ImageU8& ti = ref.level(level);
    const ImageU8& vi = view.level(level);
    int32_t px = ((x_q16 + kHalfQ16) >> level) - kHalfQ16;
    int32_t py = ((y_q16 + kHalfQ16) >> level) - kHalfQ16;
    // Near the border a coarse level's window is moved inward until it fits: it measures the
    // motion of the neighbouring patch, a start the finer levels correct. Only level 0 must
    // hold the point's own window.
    const bool coarse = level > 0;
    if (!Inside(ti, px, py, r + 1)) {
      const int32_t lo = (r + 1) << 16;
      const int32_t hx = (ti.width - r - 3) << 16, hy = (ti.height - r - 3) << 16;
      if (!coarse || hx < lo || hy < lo) {
        if (!coarse) return false;
        dx *= 2;
        dy *= 2;
        continue;
      }
      px = px < lo ? lo : (px > hx ? hx : px);
      py = py < lo ? lo : (py > hy ? hy : py);
    }
    // The window's samples lie whole pixels apart: one fraction for all (tracker_kernels.h).
    kernels_->sample(ti.Row((py >> 16) - r - 1) + (px >> 16) - r - 1, ti.stride, (px >> 8) & 255,
                     (py >> 8) & 255, tw, w.tmpl);
    int64_t gxx = 0, gyy = 0, gxy = 0;
    for (int32_t j = 0; j < ww; ++j) {
      for (int32_t i = 0; i < ww; ++i) {
        const int32_t* t = w.tmpl + (j + 1) * tw + (i + 1);
        const int32_t gx = t[1] - t[-1];
        const int32_t gy = t[tw] - t[-tw];
        w.inner[j * ww + i] = t[0];
        w.gx[j * ww + i] = gx;
        w.gy[j * ww + i] = gy;
        gxx += int64_t{gx} * gx;
        gyy += int64_t{gy} * gy;
        gxy += int64_t{gx} * gy;
      }
    }
    const double a = static_cast<double>(gxx), b = static_cast<double>(gxy);
    const double c = static_cast<double>(gyy);
    const double det = a * c - b * b;
    // A flat or edge-only window has no 2D position: its smaller eigenvalue is ~0.
    const bool flat = !(det > 1e-6 * (a + c) * (a + c)) || a + c <= 0;
    if (flat && !coarse) return false;
    for (int32_t it = 0; it < params_.max_iterations && !flat; ++it) {
      const int32_t qx = px + dx, qy = py + dy;
      if (!Inside(vi, qx, qy, r)) {
        if (!coarse) return false;
        break;
      }
      const tk::WindowSums sums =
          kernels_->sums(vi.Row((qy >> 16) - r) + (qx >> 16) - r, vi.stride, (qx >> 8) & 255,
                         (qy >> 8) & 255, ww, w.inner, w.gx, w.gy);
      const int64_t bx = sums.bx, by = sums.by, abs_err = sums.abs_err;
      mean_error = static_cast<int32_t>(abs_err / (ww * ww));
      const double sx = 2.0 * (c * static_cast<double>(bx) - b * static_cast<double>(by)) / det;
      const double sy = 2.0 * (a * static_cast<double>(by) - b * static_cast<double>(bx)) / det;
      const double lim = r;  // one step never leaves the window
      const int32_t stx = RoundQ16(sx > lim ? lim : (sx < -lim ? -lim : sx));
      const int32_t sty = RoundQ16(sy > lim ? lim : (sy < -lim ? -lim : sy));
      dx -= stx;
      dy -= sty;
      // Below 1/128 px at level 0. A coarse level only starts the next one, which doubles its
      // residual and corrects it: 1/16 px there is well within that level's reach, and the
      // iterations that would polish it further were a tenth of the motion stage's time.
      const int32_t still = coarse ? 4096 : 512;
      if ((stx < 0 ? -stx : stx) + (sty < 0 ? -sty : sty) < still) break;
    }
    if (level > 0) {
      dx *= 2;
      dy *= 2;
    }
  }
  if (!Inside(view.level(0), x_q16 + dx, y_q16 + dy, r)) return false;
  *dx_q16 = dx;
  *dy_q16 = dy;
  *error_q4 = mean_error;
  return mean_error <= params_.max_error_q4;
}

}  // namespace lb
