// Scores a map of inverse depth (any unit) against the truth after the scale AND offset small
// motion cannot know: least squares, then twice more over the pixels within 4 thresholds of the
// last fit, so a minority of wrong pixels does not tilt it. Host-side test helper.
#pragma once

#include <cstdint>
#include <vector>

namespace lb {

// Percentage of pixels (outside `border`) whose fitted estimate is off the truth by more than
// `threshold`; NaN estimates count as bad. `scale` and `offset` receive the fit when set.
// `mask`, when set, holds a byte per pixel: only the pixels where it is non-zero are fitted and
// scored (a truth with unknown pixels, an occlusion mask).
double FittedBadPercent(const std::vector<float>& truth, const std::vector<float>& estimate,
                        int32_t width, int32_t height, double threshold, int32_t border,
                        double* scale, double* offset, const std::vector<uint8_t>* mask = nullptr);

}  // namespace lb
