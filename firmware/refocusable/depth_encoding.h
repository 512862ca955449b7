// Depth map encodings of the refocusable JPEG (GDepth, see shared/notes/formats.md) for our
// disparity maps. Disparity (Q8.8 px per view step) is proportional to inverse depth; with no
// metric scale we take depth = 1 / disparity in px, so near = 1 / disp_max and far = 1 / disp_min.
// RangeInverse is then linear in disparity:
//   dn = (far - near * far / d) / (far - near) = (disp_max - disp) / (disp_max - disp_min)
// quantised to 8 or 16 bits (0 = near). The per-pixel path is integer-only, so the bytes are the
// same on every platform.
#pragma once

#include <cstdint>
#include <string_view>

#include "algo/core/image.h"
#include "algo/core/status.h"

namespace lb {

struct DisparityRange {
  int32_t min_q8 = 0;  // farthest plane; 0 (infinity) is written with a Far of 1e6
  int32_t max_q8 = 0;  // nearest plane
};

// Checks the range and gives the GDepth Near and Far for it.
Status DepthNearFar(const DisparityRange& range, double* near_depth, double* far_depth);

// The disparity range that a file's Near and Far describe (inverse of DepthNearFar).
Status DisparityRangeFromNearFar(double near_depth, double far_depth, DisparityRange* range);

// The depth (in Near/Far units) of a disparity, e.g. the focal plane for GFocus:FocalDistance.
// Disparity 0 (infinity) is taken as 1/256 px.
double DepthForDisparity(int32_t disp_q8);

// disp_q8 -> RangeInverse value of `bits` (8 or 16) bits, rounded to nearest; disparities outside
// the range clamp to its ends. The range must have passed DepthNearFar.
uint16_t EncodeRangeInverse(int32_t disp_q8, const DisparityRange& range, int bits);

// RangeInverse value -> disp_q8, rounded to nearest. With 16 bits and a range of at most 65535
// Q8 steps, Decode(Encode(d)) == d for every d in the range.
int32_t DecodeRangeInverse(uint16_t value, const DisparityRange& range, int bits);

// Whole maps: `values` and `disp_q8` have the same size.
Status EncodeDepthMap(ConstImageU16 disp_q8, const DisparityRange& range, int bits,
                      ImageU16 values);
Status DecodeDepthMap(ConstImageU16 values, const DisparityRange& range, int bits,
                      ImageU16 disp_q8);

// How a file's stored values map to depth between Near (value 0) and Far (the top value):
// RangeInverse is linear in 1 / depth, RangeLinear in depth.
enum class DepthFormat { kRangeInverse, kRangeLinear };
Status DepthFormatOf(std::string_view text, DepthFormat* format);

// A file's stored depth values (`bits` 8 or 16, in `format`, Near and Far in the file's units) as
// Q8.8 disparity = `scale` / depth, clamped to 16 bits, and the disparities of Near and Far in
// `range`. RangeInverse at scale 1 is the product's own encoding: DecodeDepthMap, exact. The
// others compute each value in double (one division a pixel, nothing allocated).
Status DepthValuesToDisparity(ConstImageU16 values, int bits, DepthFormat format, double near_depth,
                              double far_depth, double scale, ImageU16 disp_q8,
                              DisparityRange* range);

}  // namespace lb
