
#include "algo/render/lens_model.h"

#include <cmath>

#include "algo/core/int_math.h"

namespace lb {

void LensModel::Set(float f_number, int32_t working_scale, int32_t max_radius,
                    int32_t focus_disp_q8) {
  const double radius = 0.5 * kDiameterPerDispAtF28 * (2.8 / f_number) * working_scale;
  radius_per_disp_q16_ = static_cast<int32_t>(std::lround(radius * 65536.0));
  focus_disp_q8_ = focus_disp_q8;
  cap_q4_ = max_radius * 16;
}

int32_t FocusDisparityQ8(ConstImageU16 disp, int32_t s, int32_t x, int32_t y, int32_t w, int32_t h,
                         uint32_t* histogram) {
  if (w <= 0 || h <= 0) {
    const int32_t fw = disp.width * s, fh = disp.height * s;
    x = fw / 3, y = fh / 3, w = fw / 3, h = fh / 3;
  }
  // Working-pixel rectangle [x0, x1) x [y0, y1), at least 3x3 around its centre.
  int32_t x0 = x / s, y0 = y / s, x1 = (x + w + s - 1) / s, y1 = (y + h + s - 1) / s;
  if (x1 - x0 < 3) x0 = (x0 + x1) / 2 - 1, x1 = x0 + 3;
  if (y1 - y0 < 3) y0 = (y0 + y1) / 2 - 1, y1 = y0 + 3;
  x0 = Clamp(x0, 0, disp.width - 1), x1 = Clamp(x1, x0 + 1, disp.width);
  y0 = Clamp(y0, 0, disp.height - 1), y1 = Clamp(y1, y0 + 1, disp.height);

  // Exact median in two passes of 256 bins: the high byte first, then the low byte inside it.
  const uint32_t total = static_cast<uint32_t>((x1 - x0) * (y1 - y0));
  const uint32_t rank = (total - 1) / 2;  // the lower median
  uint32_t below = 0;
  int32_t high = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (int32_t i = 0; i < 256; ++i) histogram[i] = 0;
    for (int32_t yy = y0; yy < y1; ++yy) {
      const uint16_t* row = disp.Row(yy);
      for (int32_t xx = x0; xx < x1; ++xx) {
        if (pass == 0) {
          ++histogram[row[xx] >> 8];
        } else if ((row[xx] >> 8) == high) {
          ++histogram[row[xx] & 255];
        }
      }
    }
    int32_t bin = 0;
    while (bin < 255 && below + histogram[bin] <= rank) below += histogram[bin++];
    if (pass == 1) return (high << 8) | bin;
    high = bin;
  }
  return 0;
}

}  // namespace lb
