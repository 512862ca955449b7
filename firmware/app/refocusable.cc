#include "firmware/app/refocusable.h"

#include <algorithm>
#include <utility>

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
                                int32_t width, std::vector<JpegSegment>* segments,
                                DynamicDepthTrailer* dd, ConstImageU8 confidence) {
  return BuildRefocusableSegments(disp_q8, range, std::vector<uint8_t>(original_jpeg), focus, width,
                                  segments, dd, confidence);
}

Status BuildRefocusableSegments(ConstImageU16 disp_q8, const DisparityRange& range,
                                std::vector<uint8_t>&& original_jpeg, const FocusUsed& focus,
                                int32_t width, std::vector<JpegSegment>* segments,
                                DynamicDepthTrailer* dd, ConstImageU8 confidence) {
  RefocusableXmp local;
  RefocusableXmp& xmp = dd != nullptr ? dd->xmp : local;
  xmp = RefocusableXmp();
  // 16 bits: the stored depth decodes back to exactly the disparity the picture was rendered from.
  LB_RETURN_IF_ERROR(SetDepthFromDisparity(disp_q8, range, 16, &xmp));
  if (!confidence.empty()) LB_RETURN_IF_ERROR(SetConfidence(confidence, &xmp));
  xmp.image = std::move(original_jpeg);
  xmp.has_focus = true;
  xmp.focus.focal_distance = DepthForDisparity(focus.focus_disp_q8);
  xmp.focus.blur_at_infinity = focus.blur_at_infinity_px / static_cast<float>(width);
  xmp.focus.focal_point_x = focus.point_x;
  xmp.focus.focal_point_y = focus.point_y;
  if (dd != nullptr) LB_RETURN_IF_ERROR(SetDynamicDepth(dd->extras, &xmp));
  return BuildXmpSegments(xmp, segments);
}

Status WriteDynamicDepthTrailer(const DynamicDepthTrailer& dd, AtomicFile* file) {
  return WriteDynamicDepthItems(dd.xmp, dd.extras, [file](const uint8_t* data, size_t size) {
    return file->Write(data, size);
  });
}

DdImagingModel ImagingModelOf(double focal_px, int32_t width, int32_t height) {
  DdImagingModel m;
  if (!(focal_px > 0.0) || width <= 0 || height <= 0) return m;
  const double side = std::max(width, height);
  m.focal_length_x = m.focal_length_y = focal_px / side;
  m.principal_point_x = m.principal_point_y = 0.5;
  m.image_width = width;
  m.image_height = height;
  return m;
}

}  // namespace lb
