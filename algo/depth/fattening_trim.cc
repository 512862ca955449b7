#include "algo/depth/fattening_trim.h"

#include <array>
#include <cstring>
#include <utility>

namespace lb {
namespace {

constexpr int32_t kMaxColourStep = 3 * 255;

// 256 * exp(-d / kColourScale) for d = 0..765: Q16 steps of exp(-1/16) = 61565.3 / 65536.
constexpr std::array<uint16_t, kMaxColourStep + 1> MakeWeights() {
  static_assert(FatteningTrim::kColourScale == 16, "the step below is exp(-1/16)");
  std::array<uint16_t, kMaxColourStep + 1> w{};
  uint64_t q16 = uint64_t{256} << 16;
  for (int32_t d = 0; d <= kMaxColourStep; ++d) {
    w[static_cast<size_t>(d)] = static_cast<uint16_t>((q16 + (1u << 15)) >> 16);
    q16 = (q16 * 61565u + (1u << 15)) >> 16;
  }
  return w;
}
constexpr std::array<uint16_t, kMaxColourStep + 1> kWeights = MakeWeights();

inline int32_t Abs(int32_t v) { return v < 0 ? -v : v; }
inline int32_t Min(int32_t a, int32_t b) { return a < b ? a : b; }
inline uint16_t Min(uint16_t a, uint16_t b) { return a < b ? a : b; }
inline int32_t Min3(int32_t a, int32_t b, int32_t c) {
  const int32_t m = a < b ? a : b;
  return m < c ? m : c;
}

// The smallest of value[0..n) whose samples at or below it weigh at least `need` (at most the
// sum of weight[0..n)): a quickselect, three ways around a pivot, that keeps the weights along.
uint16_t WeightedSelect(uint16_t* value, uint16_t* weight, int32_t n, int32_t need) {
  int32_t lo = 0, hi = n;
  for (;;) {
    const uint16_t pivot = value[lo + (hi - lo) / 2];
    // [lo, lt): below the pivot, [lt, i): equal, [gt, hi): above.
    int32_t lt = lo, i = lo, gt = hi, below = 0, equal = 0;
    while (i < gt) {
      if (value[i] < pivot) {
        below += weight[i];
        std::swap(value[i], value[lt]);
        std::swap(weight[i], weight[lt]);
        ++lt, ++i;
      } else if (value[i] > pivot) {
        --gt;
        std::swap(value[i], value[gt]);
        std::swap(weight[i], weight[gt]);
      } else {
        equal += weight[i];
        ++i;
      }
    }
    if (below >= need) {
      hi = lt;
    } else if (below + equal >= need) {
      return pivot;
    } else {
      need -= below + equal;
      lo = gt;
    }
  }
}

}  // namespace

size_t FatteningTrim::RequiredBytes(int32_t width, int32_t workers) {
  Arena plan;
  FatteningTrim t;
  t.Carve(plan, width, workers);
  return plan.used();
}

void FatteningTrim::Carve(Arena& arena, int32_t width, int32_t workers) {
  width_ = width;
  workers_ = workers < 1 ? 1 : (workers > kMaxWorkers ? kMaxWorkers : workers);
  for (int32_t i = 0; i < workers_; ++i)
    column_min_[i] = arena.Allocate<uint16_t>(static_cast<size_t>(width));
  runner_ = &inline_;
}

void FatteningTrim::SetRunner(TaskRunner* runner) {
  runner_ = runner != nullptr && runner->workers() <= workers_ ? runner : &inline_;
}

int64_t FatteningTrim::Run(const ConstImageU8& reference, ConstImageU16 in, ImageU16 out,
                           int32_t label_step_q8) {
  const int32_t w = in.width, h = in.height;
  if (column_min_[0] == nullptr || w > width_ || out.width != w || out.height != h ||
      reference.width != w || reference.height != h) {
    return 0;
  }
  const int32_t edge = EdgeStepQ8(label_step_q8);
  const int32_t bands = runner_->workers() > 1 ? 4 * runner_->workers() : 1;
  int64_t moved[4 * kMaxWorkers] = {};
  ParallelFor(*runner_, bands, [&](int32_t b, int32_t worker) {
    moved[b] = Rows(reference, in, out, edge, h * b / bands, h * (b + 1) / bands, worker);
  });
  int64_t total = 0;
  for (int32_t b = 0; b < bands; ++b) total += moved[b];
  return total;
}

int64_t FatteningTrim::Rows(const ConstImageU8& reference, ConstImageU16 in, ImageU16 out,
                            int32_t edge, int32_t y0, int32_t y1, int32_t worker) const {
  const int32_t w = in.width, h = in.height;
  uint16_t* const column_min = column_min_[worker];
  constexpr int32_t kWindow = (2 * kRadius + 1) * (2 * kRadius + 1);
  uint16_t value[kWindow] = {};
  uint16_t weight[kWindow] = {};
  int64_t moved = 0;
  for (int32_t y = y0; y < y1; ++y) {
    memcpy(out.Row(y), in.Row(y), static_cast<size_t>(w) * sizeof(uint16_t));
    // Windows stay centred at the borders, so a slanted surface there keeps its median.
    const int32_t ry = Min3(kRadius, y, h - 1 - y);
    const int32_t r0 = y - ry, r1 = y + ry;
    memcpy(column_min, in.Row(r0), static_cast<size_t>(w) * sizeof(uint16_t));
    for (int32_t r = r0 + 1; r <= r1; ++r) {
      const uint16_t* row = in.Row(r);
      for (int32_t x = 0; x < w; ++x) column_min[x] = Min(column_min[x], row[x]);
    }
    const uint16_t* centres = in.Row(y);
    uint16_t* dst = out.Row(y);
    for (int32_t x = 0; x < w; ++x) {
      const int32_t rx = Min3(kRadius, x, w - 1 - x);
      const int32_t c0 = x - rx, c1 = x + rx;
      const int32_t centre = centres[x];
      int32_t lo = centre;
      for (int32_t c = c0; c <= c1; ++c) lo = Min(lo, static_cast<int32_t>(column_min[c]));
      // Only a pixel with a farther surface in reach, a step away, can have overreached.
      if (centre - lo <= edge) continue;
      const uint8_t* p = reference.At(x, y);
      int32_t total = 0, farther = 0, n = 0;
      for (int32_t r = r0; r <= r1; ++r) {
        const uint16_t* row = in.Row(r);
        const uint8_t* q = reference.At(c0, r);
        for (int32_t c = c0; c <= c1; ++c, q += 3) {
          const int32_t d = Abs(p[0] - q[0]) + Abs(p[1] - q[1]) + Abs(p[2] - q[2]);
          const int32_t wt = kWeights[static_cast<size_t>(d)];
          total += wt;
          if (row[c] < centre && wt > 0) {
            farther += wt;
            value[n] = row[c];
            weight[n] = static_cast<uint16_t>(wt);
            ++n;
          }
        }
      }
      // The median is the smallest value whose weight from below reaches half the total.
      const int32_t half = (total + 1) / 2;
      if (farther < half) continue;
      dst[x] = WeightedSelect(value, weight, n, half);
      ++moved;
    }
  }
  return moved;
}

}  // namespace lb
