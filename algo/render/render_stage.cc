// Foundation render stage: a gather blur whose box radius follows the disparity difference from
// the focal plane. It has the final interface, streaming and memory discipline; the layered,
// aperture-shaped renderer replaces the per-pixel kernel.
#include "algo/render/render_stage.h"

#include <cstdlib>

namespace lb {
namespace {

constexpr int32_t kHistBins = 1024;  // disparity histogram bins of 1/4 px (Q8 >> 6)

// Blur diameter at f/2.8 per pixel of disparity difference at full resolution: the burst acts as
// an aperture a few view steps wide.
constexpr float kDiameterPerDispAtF28 = 4.0f;

}  // namespace

Status RenderStage::Validate(const RenderConfig& c) {
  if (c.width < 16 || c.height < 16) {
    return Status(Code::kInvalidArgument, "render: output %dx%d is below 16x16", c.width, c.height);
  }
  if (c.working_scale < 1 || c.working_width * c.working_scale > c.width ||
      c.working_height * c.working_scale > c.height || c.working_width < 1 ||
      c.working_height < 1) {
    return Status(Code::kInvalidArgument, "render: working size %dx%d x%d does not fit %dx%d",
                  c.working_width, c.working_height, c.working_scale, c.width, c.height);
  }
  if (c.max_radius < 0 || c.max_radius > 128) {
    return Status(Code::kInvalidArgument, "render: largest blur radius %d outside 0..128",
                  c.max_radius);
  }
  return Status::Ok();
}

size_t RenderStage::RequiredBytes(const RenderConfig& config) {
  RenderStage planner;
  planner.config_ = config;
  Arena plan;
  (void)planner.Carve(plan);
  return plan.used();
}

Status RenderStage::Carve(Arena& arena) {
  const int32_t cw = (config_.width + 1) / 2;
  strip_.count = 3;
  strip_.planes[0] = arena.AllocateImage<uint8_t>(config_.width, RenderConfig::kStripRows);
  strip_.planes[1] = arena.AllocateImage<uint8_t>(cw, RenderConfig::kStripRows / 2);
  strip_.planes[2] = arena.AllocateImage<uint8_t>(cw, RenderConfig::kStripRows / 2);
  histogram_ = arena.Allocate<uint16_t>(kHistBins);
  if (arena.overflowed()) return Status(Code::kOutOfMemory, "render: arena too small");
  return Status::Ok();
}

Status RenderStage::Configure(const RenderConfig& config, Arena& arena) {
  LB_RETURN_IF_ERROR(Validate(config));
  config_ = config;
  return Carve(arena);
}

Status RenderStage::Begin(const ConstPlanarU8& ref, ConstImageU16 disp_q8,
                          const RenderParams& params) {
  if (ref.count != 3 || ref.planes[0].width != config_.width ||
      ref.planes[0].height != config_.height) {
    return Status(Code::kInvalidArgument, "render: reference is not %dx%d YCbCr", config_.width,
                  config_.height);
  }
  if (disp_q8.width != config_.working_width || disp_q8.height != config_.working_height) {
    return Status(Code::kInvalidArgument, "render: disparity is %dx%d, expected %dx%d",
                  disp_q8.width, disp_q8.height, config_.working_width, config_.working_height);
  }
  if (!(params.f_number >= 1.0f && params.f_number <= 32.0f)) {
    return Status(Code::kInvalidArgument, "render: f-number %.2f outside f/1 .. f/32",
                  static_cast<double>(params.f_number));
  }
  ref_ = ref;
  disp_ = disp_q8;
  params_ = params;
  next_row_ = 0;

  // Focus region in working pixels; the default is the central ninth of the image.
  FocusRegion r = params.focus;
  if (r.width <= 0 || r.height <= 0) {
    r = {config_.width / 3, config_.height / 3, config_.width / 3, config_.height / 3};
  }
  const int32_t s = config_.working_scale;
  int32_t x0 = r.x / s, y0 = r.y / s, x1 = (r.x + r.width) / s, y1 = (r.y + r.height) / s;
  x0 = x0 < 0 ? 0 : (x0 >= disp_.width ? disp_.width - 1 : x0);
  y0 = y0 < 0 ? 0 : (y0 >= disp_.height ? disp_.height - 1 : y0);
  x1 = x1 <= x0 ? x0 + 1 : (x1 > disp_.width ? disp_.width : x1);
  y1 = y1 <= y0 ? y0 + 1 : (y1 > disp_.height ? disp_.height : y1);
  // The focal disparity is the median of the region: robust to a few mislabelled pixels.
  for (int32_t i = 0; i < kHistBins; ++i) histogram_[i] = 0;
  int32_t total = 0;
  for (int32_t y = y0; y < y1; ++y) {
    for (int32_t x = x0; x < x1; ++x) {
      int32_t bin = disp_.Row(y)[x] >> 6;
      bin = bin >= kHistBins ? kHistBins - 1 : bin;
      if (histogram_[bin] < UINT16_MAX) ++histogram_[bin];
      ++total;
    }
  }
  int32_t seen = 0, median_bin = 0;
  for (; median_bin < kHistBins; ++median_bin) {
    seen += histogram_[median_bin];
    if (2 * seen >= total) break;
  }
  focus_disp_q8_ = (median_bin << 6) + 32;
  // Radius in full-resolution px per px of working disparity, fixed point (Q8 of px per Q8 px).
  const float diameter = kDiameterPerDispAtF28 * 2.8f / params.f_number * static_cast<float>(s);
  blur_per_disp_q8_ = static_cast<int32_t>(diameter * 0.5f * 256.0f + 0.5f);
  return Status::Ok();
}

int32_t RenderStage::RadiusQ8(int32_t disp_q8) const {
  const int64_t diff = std::abs(disp_q8 - focus_disp_q8_);
  int64_t r = (diff * blur_per_disp_q8_) >> 8;
  const int64_t cap = int64_t{config_.max_radius} << 8;
  return static_cast<int32_t>(r > cap ? cap : r);
}

Status RenderStage::NextStrip(ConstPlanarU8* strip, int32_t* y0, int32_t* rows) {
  const int32_t h = config_.height;
  *y0 = next_row_;
  *rows = h - next_row_ < RenderConfig::kStripRows ? h - next_row_ : RenderConfig::kStripRows;
  if (*rows <= 0) {
    *rows = 0;
    return Status::Ok();
  }
  const int32_t s = config_.working_scale;
  for (int32_t p = 0; p < 3; ++p) {
    const ConstImageU8& src = ref_.planes[p];
    const ImageU8& dst = strip_.planes[p];
    const int32_t sub = p == 0 ? 1 : 2;  // chroma is half size in both directions
    const int32_t py0 = *y0 / sub, prows = (*rows + sub - 1) / sub;
    for (int32_t yy = 0; yy < prows && py0 + yy < src.height; ++yy) {
      const int32_t y = py0 + yy;
      for (int32_t x = 0; x < src.width; ++x) {
        int32_t wx = x * sub / s, wy = y * sub / s;
        wx = wx >= disp_.width ? disp_.width - 1 : wx;
        wy = wy >= disp_.height ? disp_.height - 1 : wy;
        const int32_t radius = (RadiusQ8(disp_.Row(wy)[wx]) / sub + 128) >> 8;
        // Sparse box gather: at most 9x9 taps whatever the radius.
        const int32_t step = radius / 4 + 1;
        int32_t sum = 0, count = 0;
        for (int32_t dy = -radius; dy <= radius; dy += step) {
          int32_t sy = y + dy;
          sy = sy < 0 ? 0 : (sy >= src.height ? src.height - 1 : sy);
          const uint8_t* row = src.Row(sy);
          for (int32_t dx = -radius; dx <= radius; dx += step) {
            int32_t sx = x + dx;
            sx = sx < 0 ? 0 : (sx >= src.width ? src.width - 1 : sx);
            sum += row[sx];
            ++count;
          }
        }
        dst.Row(yy)[x] = static_cast<uint8_t>((sum + count / 2) / count);
      }
    }
  }
  next_row_ += *rows;
  *strip = strip_.AsConst();
  return Status::Ok();
}

}  // namespace lb
