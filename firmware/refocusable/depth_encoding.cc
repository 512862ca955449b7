#include "firmware/refocusable/depth_encoding.h"

#include <algorithm>
#include <cmath>

namespace lb {
namespace {

// Largest disparity the product uses is far below this; it keeps 65535 * span inside int64.
constexpr int32_t kMaxDispQ8 = 1 << 24;

// A range that reaches infinity (disparity 0) gets a finite Far, as viewers expect, far enough
// that it reads back as disparity 0 (256 / 1e6 < 1/2 in Q8) so the map stays lossless.
constexpr double kFarForInfinity = 1e6;

bool SameSize(ConstImageU16 a, ConstImageU16 b) {
  return !a.empty() && !b.empty() && a.width == b.width && a.height == b.height &&
         a.channels == 1 && b.channels == 1;
}

}  // namespace

Status DepthNearFar(const DisparityRange& range, double* near_depth, double* far_depth) {
  if (range.min_q8 < 0 || range.max_q8 > kMaxDispQ8 || range.min_q8 >= range.max_q8) {
    return Status(Code::kInvalidArgument, "depth encoding: disparity range %d..%d (Q8) is empty",
                  static_cast<int>(range.min_q8), static_cast<int>(range.max_q8));
  }
  *near_depth = 256.0 / range.max_q8;
  *far_depth = range.min_q8 > 0 ? 256.0 / range.min_q8 : kFarForInfinity;
  return Status::Ok();
}

Status DisparityRangeFromNearFar(double near_depth, double far_depth, DisparityRange* range) {
  if (!(near_depth > 0.0 && far_depth > near_depth && std::isfinite(far_depth))) {
    return Status(Code::kCorruptData, "depth encoding: Near %g and Far %g are not 0 < near < far",
                  near_depth, far_depth);
  }
  const double max_q8 = 256.0 / near_depth, min_q8 = 256.0 / far_depth;
  if (max_q8 > kMaxDispQ8) {
    return Status(Code::kUnsupported, "depth encoding: Near %g is closer than this reader handles",
                  near_depth);
  }
  range->max_q8 = static_cast<int32_t>(std::lround(max_q8));
  range->min_q8 = static_cast<int32_t>(std::lround(min_q8));
  if (range->min_q8 >= range->max_q8) {
    return Status(Code::kCorruptData, "depth encoding: Near %g and Far %g are too close",
                  near_depth, far_depth);
  }
  return Status::Ok();
}

double DepthForDisparity(int32_t disp_q8) { return 256.0 / (disp_q8 > 0 ? disp_q8 : 1); }

uint16_t EncodeRangeInverse(int32_t disp_q8, const DisparityRange& range, int bits) {
  const int64_t top = bits == 8 ? 255 : 65535;
  const int32_t far_q8 = range.min_q8;
  const int32_t d = disp_q8 < far_q8 ? far_q8 : (disp_q8 > range.max_q8 ? range.max_q8 : disp_q8);
  const int64_t span = range.max_q8 - far_q8;
  // Round half up; the numerator is at most 65535 * 2^24 * 2.
  return static_cast<uint16_t>(((range.max_q8 - d) * top * 2 + span) / (2 * span));
}

int32_t DecodeRangeInverse(uint16_t value, const DisparityRange& range, int bits) {
  const int64_t top = bits == 8 ? 255 : 65535;
  const int64_t v = value > top ? top : value;
  const int64_t span = range.max_q8 - range.min_q8;
  return range.max_q8 - static_cast<int32_t>((v * span * 2 + top) / (2 * top));
}

// What encoding and decoding a map both ask of their arguments.
static Status CheckMaps(const DisparityRange& range, int bits, bool same_size) {
  double near_depth, far_depth;
  LB_RETURN_IF_ERROR(DepthNearFar(range, &near_depth, &far_depth));
  if (bits != 8 && bits != 16) {
    return Status(Code::kInvalidArgument, "depth encoding: %d bits (8 or 16)", bits);
  }
  if (!same_size) return Status(Code::kInvalidArgument, "depth encoding: map sizes differ");
  return Status::Ok();
}

Status EncodeDepthMap(ConstImageU16 disp_q8, const DisparityRange& range, int bits,
                      ImageU16 values) {
  LB_RETURN_IF_ERROR(CheckMaps(range, bits, SameSize(disp_q8, values)));
  for (int32_t y = 0; y < disp_q8.height; ++y) {
    const uint16_t* in = disp_q8.Row(y);
    uint16_t* out = values.Row(y);
    for (int32_t x = 0; x < disp_q8.width; ++x) out[x] = EncodeRangeInverse(in[x], range, bits);
  }
  return Status::Ok();
}

Status DecodeDepthMap(ConstImageU16 values, const DisparityRange& range, int bits,
                      ImageU16 disp_q8) {
  LB_RETURN_IF_ERROR(CheckMaps(range, bits, SameSize(values, disp_q8)));
  if (range.max_q8 > 65535) {
    return Status(Code::kUnsupported, "depth encoding: disparity %d (Q8) does not fit 16 bits",
                  static_cast<int>(range.max_q8));
  }
  for (int32_t y = 0; y < values.height; ++y) {
    const uint16_t* in = values.Row(y);
    uint16_t* out = disp_q8.Row(y);
    for (int32_t x = 0; x < values.width; ++x) {
      out[x] = static_cast<uint16_t>(DecodeRangeInverse(in[x], range, bits));
    }
  }
  return Status::Ok();
}

Status DepthFormatOf(std::string_view text, DepthFormat* format) {
  if (text == "RangeInverse") {
    *format = DepthFormat::kRangeInverse;
  } else if (text == "RangeLinear") {
    *format = DepthFormat::kRangeLinear;
  } else {
    return Status(Code::kUnsupported, "depth map: Format '%.*s' (RangeInverse or RangeLinear)",
                  static_cast<int>(std::min<size_t>(text.size(), 32)), text.data());
  }
  return Status::Ok();
}

Status DepthValuesToDisparity(ConstImageU16 values, int bits, DepthFormat format, double near_depth,
                              double far_depth, double scale, ImageU16 disp_q8,
                              DisparityRange* range) {
  const bool linear = format == DepthFormat::kRangeLinear;
  if (!linear && scale == 1.0) {
    LB_RETURN_IF_ERROR(DisparityRangeFromNearFar(near_depth, far_depth, range));
    return DecodeDepthMap(values, *range, bits, disp_q8);
  }
  if (!(scale > 0.0 && std::isfinite(scale) && near_depth > 0.0 && far_depth > near_depth &&
        std::isfinite(far_depth))) {
    return Status(Code::kUnsupported, "depth map: Near %g, Far %g at scale %g give no disparity",
                  near_depth, far_depth, scale);
  }
  if (!(256.0 * scale / near_depth <= 65535.0)) {
    return Status(Code::kUnsupported, "depth map: Near %g at scale %g is too close", near_depth,
                  scale);
  }
  if (bits != 8 && bits != 16) {
    return Status(Code::kInvalidArgument, "depth encoding: %d bits (8 or 16)", bits);
  }
  if (!SameSize(values, disp_q8)) {
    return Status(Code::kInvalidArgument, "depth encoding: map sizes differ");
  }
  range->max_q8 = static_cast<int32_t>(std::lround(256.0 * scale / near_depth));
  range->min_q8 = static_cast<int32_t>(std::lround(256.0 * scale / far_depth));
  if (range->min_q8 >= range->max_q8) {
    return Status(Code::kUnsupported, "depth map: Near %g and Far %g are one disparity at scale %g",
                  near_depth, far_depth, scale);
  }
  const int32_t top = bits == 16 ? 65535 : 255;
  const double span = far_depth - near_depth;
  for (int32_t y = 0; y < values.height; ++y) {
    const uint16_t* in = values.Row(y);
    uint16_t* out = disp_q8.Row(y);
    for (int32_t x = 0; x < values.width; ++x) {
      const double dn = static_cast<double>(std::min<int32_t>(in[x], top)) / top;
      const double depth =
          linear ? near_depth + dn * span : far_depth * near_depth / (far_depth - dn * span);
      out[x] = static_cast<uint16_t>(std::clamp(std::lround(256.0 * scale / depth), 0L, 65535L));
    }
  }
  return Status::Ok();
}

}  // namespace lb
