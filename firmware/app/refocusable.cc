#include "firmware/app/refocusable.h"

#include <utility>

#include "firmware/refocusable/xmp_writer.h"

namespace lb {

FocusUsed FocusOf(const RenderStage& render, const RenderParams& params, int32_t width,
                  int32_t height) {
  FocusUsed f;
  f.focus_disp_q8 = render.focus_disp_q8();
  f.blur_at_infinity_px = render.blur_at_infinity();
  const FocusRegion& r = params.focus;
  if (r.width > 0 && r.height > 0) {
    f.point_x =
        (static_cast<float>(r.x) + 0.5f * static_cast<float>(r.width)) / static_cast<float>(width);
    f.point_y = (static_cast<float>(r.y) + 0.5f * static_cast<float>(r.height)) /
                static_cast<float>(height);
  }
  return f;
}

Status BuildRefocusableSegments(ConstImageU16 disp_q8, const DisparityRange& range,
                                const std::vector<uint8_t>& original_jpeg, const FocusUsed& focus,
                                int32_t width, std::vector<JpegSegment>* segments) {
  return BuildRefocusableSegments(disp_q8, range, std::vector<uint8_t>(original_jpeg), focus, width,
                                  segments);
}

Status BuildRefocusableSegments(ConstImageU16 disp_q8, const DisparityRange& range,
                                std::vector<uint8_t>&& original_jpeg, const FocusUsed& focus,
                                int32_t width, std::vector<JpegSegment>* segments) {
  RefocusableXmp xmp;
  // 16 bits: the stored depth decodes back to exactly the disparity the picture was rendered from.
  LB_RETURN_IF_ERROR(SetDepthFromDisparity(disp_q8, range, 16, &xmp));
  xmp.image = std::move(original_jpeg);
  xmp.has_focus = true;
  xmp.focus.focal_distance = DepthForDisparity(focus.focus_disp_q8);
  xmp.focus.blur_at_infinity = focus.blur_at_infinity_px / static_cast<float>(width);
  xmp.focus.focal_point_x = focus.point_x;
  xmp.focus.focal_point_y = focus.point_y;
  return BuildXmpSegments(xmp, segments);
}

}  // namespace lb
