// Loads views of the HCI 4D light-field scene "antinous" (../shared/data/hci, see its README) as
// small-motion bursts, and scores inverse-depth maps against its ground truth the way the
// benchmark does after the fit small motion needs: BadPix t is the share of pixels off by more
// than t px per view step once the estimate's scale AND offset of inverse depth are fitted.
// Host-side test helper; allocates freely.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "algo/core/image.h"
#include "algo/core/status.h"

namespace lb::hci {

// Which views: the centre row or column (5 or 9 views), or the 5-view cross.
enum class Layout : uint8_t { kRow5, kRow9, kColumn9, kCross5 };
const char* LayoutName(Layout layout);

struct Burst {
  int32_t width = 0, height = 0;
  int32_t reference = 0;
  std::vector<std::vector<uint8_t>> views;  // RGB8, tightly packed
  // Per view: its camera's grid offset from the centre's, in view steps (column, row). A centre
  // pixel with disparity d is seen at (x - d dc, y - d dr).
  std::vector<int32_t> dc, dr;
  std::vector<float> truth;  // the centre view's disparity, px per view step, row-major
  std::vector<ConstImageU8> Views() const;
};

// The data folder (from LB_SOURCE_DIR or the working directory), empty when absent.
std::string DataDir();
Status Load(const std::string& dir, Layout layout, Burst* burst);

// BadPix `threshold` (percent) of `estimate` (px per view step, signed; NaN = no value) after
// the scale and offset that fit the truth best: least squares, then twice more over the pixels
// within 4 thresholds of the last fit, so a minority of wrong pixels does not tilt it. The
// fitted scale and offset are returned when the pointers are set. `border` px are left out.
double FittedBadPixPercent(const Burst& burst, const std::vector<float>& estimate, double threshold,
                           int32_t border, double* scale, double* offset);

}  // namespace lb::hci
