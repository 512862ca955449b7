// The refocusable JPEG of a render: the XMP (GDepth: the photo's depth map as a lossless 16-bit
// RangeInverse PNG, and its confidence as an 8-bit grey PNG; GImage: the all-in-focus reference as
// JPEG; GFocus: the focus the picture was rendered with) as APP1 segments for the JpegWriter, and
// beside GDepth the same depth and original as Dynamic Depth (its Device element in the main XMP,
// its items after the primary's EOI), so that readers of either format open the photo. Shared by
// `refocus run`, `refocus rerender` and the daemon.
//
// What the second format costs: neither can point at the other's bytes (GDepth holds its images
// as base64 in the XMP, Dynamic Depth only as items after the EOI), so the depth PNG and the
// original JPEG are in the file twice, the second time raw (three quarters of their base64),
// neither encoded again; docs/performance.md has the figures at 12 MP.
#pragma once

#include <cstdint>
#include <vector>

#include "algo/core/image.h"
#include "algo/render/render_stage.h"
#include "firmware/codecs/jpeg_writer.h"
#include "firmware/refocusable/depth_encoding.h"
#include "firmware/refocusable/dynamic_depth.h"
#include "firmware/refocusable/xmp_writer.h"
#include "firmware/storage/atomic_file.h"

namespace lb {

// What the render stage settled on in Begin, for GFocus.
struct FocusUsed {
  int32_t focus_disp_q8 = 0;
  float blur_at_infinity_px = 0;         // blur radius of a point at infinity, full-resolution px
  float point_x = 0.5f, point_y = 0.5f;  // centre of the focus region, fractions of the image
};

FocusUsed FocusOf(const RenderStage& render, const RenderParams& params, int32_t width,
                  int32_t height);

// The Dynamic Depth items a photo carries after its EOI and the XMP that lists them, kept until
// the file is written: the items are written from this XMP's depth image and original.
struct DynamicDepthTrailer {
  RefocusableXmp xmp;
  DynamicDepthExtras extras;  // the caller may fill imaging_model before the build
};

// Builds the segments. `original_jpeg` is the all-in-focus reference, already encoded. With
// `dd`, the XMP lists Dynamic Depth's items too and `dd` keeps what WriteDynamicDepthTrailer
// writes; without, the file is GDepth only (tests' inputs). `confidence` (0..255, 255: sure),
// when not empty, is the map's size and goes in as GDepth:Confidence and Dynamic Depth's
// confidence item. Allocates (host and device alike: outside the pipeline's no-allocation
// window).
Status BuildRefocusableSegments(ConstImageU16 disp_q8, const DisparityRange& range,
                                const std::vector<uint8_t>& original_jpeg, const FocusUsed& focus,
                                int32_t width, std::vector<JpegSegment>* segments,
                                DynamicDepthTrailer* dd = nullptr,
                                ConstImageU8 confidence = ConstImageU8());
// The same, taking the original over rather than copying it (a megabyte less at the peak).
Status BuildRefocusableSegments(ConstImageU16 disp_q8, const DisparityRange& range,
                                std::vector<uint8_t>&& original_jpeg, const FocusUsed& focus,
                                int32_t width, std::vector<JpegSegment>* segments,
                                DynamicDepthTrailer* dd = nullptr,
                                ConstImageU8 confidence = ConstImageU8());

// Appends `dd`'s items to `file`, after JpegWriter::Finish and before Commit.
Status WriteDynamicDepthTrailer(const DynamicDepthTrailer& dd, AtomicFile* file);

// The intrinsics Dynamic Depth's Camera element records for a width x height photo whose focal
// length is `focal_px` pixels (0: not known, none recorded): normalised as the specification
// asks, the focal length by the larger side, the principal point (the centre) by each side.
DdImagingModel ImagingModelOf(double focal_px, int32_t width, int32_t height);

}  // namespace lb
