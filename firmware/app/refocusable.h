// The refocusable JPEG of a render: the XMP (GDepth: the working-resolution disparity as a
// lossless 16-bit RangeInverse PNG; GImage: the all-in-focus reference as JPEG; GFocus: the focus
// the picture was rendered with) as APP1 segments for the JpegWriter. Shared by `refocus run`,
// `refocus rerender` and the daemon.
#pragma once

#include <cstdint>
#include <vector>

#include "algo/core/image.h"
#include "algo/render/render_stage.h"
#include "firmware/codecs/jpeg_writer.h"
#include "firmware/refocusable/depth_encoding.h"

namespace lb {

// What the render stage settled on in Begin, for GFocus.
struct FocusUsed {
  int32_t focus_disp_q8 = 0;
  float blur_at_infinity_px = 0;         // blur radius of a point at infinity, full-resolution px
  float point_x = 0.5f, point_y = 0.5f;  // centre of the focus region, fractions of the image
};

FocusUsed FocusOf(const RenderStage& render, const RenderParams& params, int32_t width,
                  int32_t height);

// Builds the segments. `original_jpeg` is the all-in-focus reference, already encoded.
// Allocates (host and device alike: outside the pipeline's no-allocation window).
Status BuildRefocusableSegments(ConstImageU16 disp_q8, const DisparityRange& range,
                                const std::vector<uint8_t>& original_jpeg, const FocusUsed& focus,
                                int32_t width, std::vector<JpegSegment>* segments);
// The same, taking the original over rather than copying it (a megabyte less at the peak).
Status BuildRefocusableSegments(ConstImageU16 disp_q8, const DisparityRange& range,
                                std::vector<uint8_t>&& original_jpeg, const FocusUsed& focus,
                                int32_t width, std::vector<JpegSegment>* segments);

}  // namespace lb
