#include "tests/algo/depth/fit_score.h"

#include <cmath>

namespace lb {

double FittedBadPercent(const std::vector<float>& truth, const std::vector<float>& e, int32_t width,
                        int32_t height, double threshold, int32_t border, double* scale_out,
                        double* offset_out, const std::vector<uint8_t>* mask) {
  double a = 1, c = 0;
  double band = -1;  // the first fit takes every pixel
  for (int round = 0; round < 3; ++round) {
    double n = 0, se = 0, st = 0, see = 0, set = 0;
    for (int32_t y = border; y < height - border; ++y) {
      for (int32_t x = border; x < width - border; ++x) {
        const size_t i = static_cast<size_t>(y) * width + x;
        if ((mask && !(*mask)[i]) || !std::isfinite(e[i])) continue;
        if (band > 0 && std::fabs(a * e[i] + c - truth[i]) > band) continue;
        n += 1;
        se += e[i];
        st += truth[i];
        see += double{e[i]} * e[i];
        set += double{e[i]} * truth[i];
      }
    }
    const double det = n * see - se * se;
    if (!(n > 1) || !(std::fabs(det) > 0)) break;
    a = (n * set - se * st) / det;
    c = (st - a * se) / n;
    band = 4 * threshold;
  }
  int64_t bad = 0, total = 0;
  for (int32_t y = border; y < height - border; ++y) {
    for (int32_t x = border; x < width - border; ++x) {
      const size_t i = static_cast<size_t>(y) * width + x;
      if (mask && !(*mask)[i]) continue;
      ++total;
      bad += !std::isfinite(e[i]) || std::fabs(a * e[i] + c - truth[i]) > threshold;
    }
  }
  if (scale_out) *scale_out = a;
  if (offset_out) *offset_out = c;
  return total ? 100.0 * static_cast<double>(bad) / static_cast<double>(total) : 100.0;
}

}  // namespace lb
