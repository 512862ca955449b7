// What a focus *point* means, the same for `refocus` (--focus X,Y) and refocusd.conf
// (focus = point X,Y): a square of 2 kFocusPointHalfSide px around it, small enough to pick one
// object, large enough that the median of its depths (lens_model.h) is stable.
#pragma once

#include <cstdint>

#include "algo/core/status.h"
#include "algo/render/render_stage.h"

namespace lb {

inline constexpr int32_t kFocusPointHalfSide = 8;

inline FocusRegion FocusAtPoint(int32_t x, int32_t y) {
  return {x - kFocusPointHalfSide, y - kFocusPointHalfSide, 2 * kFocusPointHalfSide,
          2 * kFocusPointHalfSide};
}

// kInvalidArgument when a chosen region lies wholly outside a width x height photo (the
// default, empty region always fits).
inline Status CheckFocusRegion(const FocusRegion& r, int32_t width, int32_t height) {
  if (r.width <= 0 || r.height <= 0) return Status::Ok();
  if (r.x >= width || r.y >= height || r.x + r.width <= 0 || r.y + r.height <= 0) {
    return Status(Code::kInvalidArgument,
                  "the focus region %d,%d,%d,%d lies outside the %dx%d photo", r.x, r.y, r.width,
                  r.height, width, height);
  }
  return Status::Ok();
}

}  // namespace lb
