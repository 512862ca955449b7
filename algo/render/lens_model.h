// Lens model: how far out of focus a point is, in full-resolution pixels, and where the focus is.
//
// Thin-lens optics (notes/method.md): the circle of confusion of a point grows linearly with the
// inverse-depth distance from the focal plane, and disparity is proportional to inverse depth.
// A point at disparity d (working-resolution px per view step) moves by d per view step, so a
// lens whose aperture spans B view steps images it as a disc of diameter B * |d - d_focus|
// working px. At f/2.8 the synthetic lens spans kDiameterPerDispAtF28 = 4 view steps (the width
// of a 5-frame burst); the aperture diameter scales as 1/N, so
//
//   radius_px = 0.5 * 4 * (2.8 / N) * working_scale * |d - d_focus|,  capped at max_radius,
//
// e.g. working_scale 7, f/2.8: 14 full-resolution px of radius per px of disparity difference.
// The sign tells the side: positive = nearer than the focal plane, negative = farther.
#pragma once

#include <cstdint>

#include "algo/core/image.h"

namespace lb {

inline constexpr float kDiameterPerDispAtF28 = 4.0f;

class LensModel {
 public:
  // Begin-time set-up (float only here). f_number must be positive.
  void Set(float f_number, int32_t working_scale, int32_t max_radius, int32_t focus_disp_q8);

  // Signed blur radius in full-resolution px, Q4 (1/16 px), clamped to +-max_radius.
  // Per pixel: one int64 multiply, rounding half up.
  int32_t SignedRadiusQ4(int32_t disp_q8) const {
    int64_t v = int64_t{disp_q8 - focus_disp_q8_} * radius_per_disp_q16_;  // Q24 px
    v = (v + (int64_t{1} << 19)) >> 20;                                    // Q4 px
    return static_cast<int32_t>(v > cap_q4_ ? cap_q4_ : (v < -cap_q4_ ? -cap_q4_ : v));
  }

  int32_t focus_disp_q8() const { return focus_disp_q8_; }
  // Full-resolution px of radius per working px of disparity difference, Q16.
  int32_t radius_per_disp_q16() const { return radius_per_disp_q16_; }
  float radius_per_disp() const { return static_cast<float>(radius_per_disp_q16_) / 65536.0f; }

 private:
  int32_t focus_disp_q8_ = 0;
  int32_t radius_per_disp_q16_ = 0;
  int32_t cap_q4_ = 0;
};

// The focus statistic: the median disparity of the working-resolution region that covers the
// full-resolution rectangle (x, y, w, h). The median ignores a minority of mislabelled pixels; a
// region smaller than 3x3 working px (a tapped point) is grown to 3x3 around its centre; an
// empty rectangle (w or h <= 0) means the default region, the central ninth of the image.
// `histogram` is caller scratch of 256 entries. Returns Q8.8.
int32_t FocusDisparityQ8(ConstImageU16 disp_q8, int32_t working_scale, int32_t x, int32_t y,
                         int32_t w, int32_t h, uint32_t* histogram);

}  // namespace lb
