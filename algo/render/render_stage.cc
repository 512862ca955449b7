
#include "algo/render/render_stage.h"

#include <cmath>

#include "algo/core/clones.h"
#include "algo/core/int_math.h"

namespace lb {
namespace {

// Largest |value| in a plane after the highlight boost, and the shift of c = (v * a) >> shift
// that keeps a whole kernel's sum ((2 half + 1)^2 cells x 256 x c) below 2^31.
int32_t ShiftFor(int32_t max_value, int32_t half) {
  int32_t shift = 0;
  const int64_t cells = (2 * int64_t{half} + 1) * (2 * int64_t{half} + 1);
  while (cells * 256 * ((int64_t{max_value} * 256) >> shift) >= (int64_t{1} << 31)) ++shift;
  return shift;
}

// The signed blur radii of a row of disparities. Its own function so that it is also compiled
// for AVX2 (clones.h), whose 32 x 32 -> 64-bit multiply the lens model's products take.
LB_CLONES_AVX2 void RadiusRow(const LensModel& lens, const uint16_t* disp, int32_t n, int16_t* s) {
  for (int32_t x = 0; x < n; ++x) s[x] = static_cast<int16_t>(lens.SignedRadiusQ4(disp[x]));
}

// The chroma radii: each the rounded mean of its 2x2 luma block's, for n whole blocks.
LB_CLONES_AVX2 void MeanRadiusRow(const int16_t* s0, const int16_t* s1, int32_t n, int16_t* s) {
  for (int32_t x = 0; x < n; ++x) {
    s[x] = static_cast<int16_t>((s0[2 * x] + s0[2 * x + 1] + s1[2 * x] + s1[2 * x + 1] + 2) >> 2);
  }
}

}  // namespace

int32_t RenderStage::LayerRadiiQ4(int32_t max_radius, int32_t* out) {
  // Half-pixel steps up to 3 px and whole pixels up to 8 px, where a step is visible; then
  // about 15% apart, where a relative change in blur is what the eye sees.
  const int32_t cap = max_radius * 16;
  int32_t n = 0, r = 0;
  while (r < cap && n < kMaxRadii - 1) {
    if (out) out[n] = r;
    ++n;
    r = r < 48 ? r + 8 : (r < 128 ? r + 16 : Max(r + 16, r * 115 / 100));
  }
  if (out) out[n] = cap;
  return n + 1;
}

Status RenderStage::Validate(const RenderConfig& c) {
  if (c.width < 16 || c.height < 16) {
    return Status(Code::kInvalidArgument, "render: output %dx%d is below 16x16", c.width, c.height);
  }
  if (c.width > 16384 || c.height > 16384) {
    return Status(Code::kInvalidArgument, "render: output %dx%d is above 16384x16384", c.width,
                  c.height);
  }
  if (c.working_scale < 1 || c.working_width * c.working_scale > c.width ||
      c.working_height * c.working_scale > c.height || c.working_width < 1 ||
      c.working_height < 1) {
    return Status(Code::kInvalidArgument, "render: working size %dx%d x%d does not fit %dx%d",
                  c.working_width, c.working_height, c.working_scale, c.width, c.height);
  }
  if (c.workers < 1 || c.workers > kMaxWorkers) {
    return Status(Code::kInvalidArgument, "render: %d workers outside 1..%d", c.workers,
                  kMaxWorkers);
  }
  if (c.max_radius < 0 || c.max_radius > 128) {
    return Status(Code::kInvalidArgument, "render: largest blur radius %d outside 0..128",
                  c.max_radius);
  }
  return Status::Ok();
}

Status RenderStage::ValidateParams(const RenderParams& p) {
  if (!(p.f_number >= RenderParams::kMinFNumber && p.f_number <= RenderParams::kMaxFNumber)) {
    return Status(Code::kInvalidArgument, "render: f-number %.2f outside f/%g .. f/%g",
                  static_cast<double>(p.f_number), static_cast<double>(RenderParams::kMinFNumber),
                  static_cast<double>(RenderParams::kMaxFNumber));
  }
  if (p.aperture.blades != 0 && (p.aperture.blades < 3 || p.aperture.blades > 12)) {
    return Status(Code::kInvalidArgument, "render: %d aperture blades (0 for a disc, or 3..12)",
                  p.aperture.blades);
  }
  if (!(p.aperture.curvature >= 0.0f && p.aperture.curvature <= 1.0f)) {
    return Status(Code::kInvalidArgument, "render: blade curvature %.2f outside 0..1",
                  static_cast<double>(p.aperture.curvature));
  }
  if (!(p.aperture.rotation_deg >= -3600.0f && p.aperture.rotation_deg <= 3600.0f)) {
    return Status(Code::kInvalidArgument,
                  "render: aperture rotation %.1f deg is not a finite angle",
                  static_cast<double>(p.aperture.rotation_deg));
  }
  if (!(p.highlight_gain >= 1.0f && p.highlight_gain <= 8.0f)) {
    return Status(Code::kInvalidArgument, "render: highlight gain %.2f outside 1..8",
                  static_cast<double>(p.highlight_gain));
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
  const RenderConfig& c = config_;
  const int32_t cw = (c.width + 1) / 2, ch = (c.height + 1) / 2;
  for (int32_t i = 0; i < c.workers; ++i) {
    PlanarU8& strip = strips_[i];
    strip.count = 3;
    strip.planes[0] = arena.AllocateImage<uint8_t>(c.width, RenderConfig::kStripRows);
    strip.planes[1] = arena.AllocateImage<uint8_t>(cw, RenderConfig::kStripRows / 2);
    strip.planes[2] = arena.AllocateImage<uint8_t>(cw, RenderConfig::kStripRows / 2);
  }
  int32_t radii_q4[kMaxRadii];
  radii_ = LayerRadiiQ4(c.max_radius, radii_q4);
  layers_ = 2 * radii_ - 1;
  luma_reach_ = LayerPlane::Reach(1, radii_q4, radii_);
  chroma_reach_ = LayerPlane::Reach(2, radii_q4, radii_);
  radii_q4_ = arena.Allocate<int32_t>(static_cast<size_t>(radii_));
  radius_of_layer_ = arena.Allocate<int32_t>(static_cast<size_t>(layers_));
  layer_of_ = arena.Allocate<uint16_t>(static_cast<size_t>(c.max_radius) * 32 + 1);
  for (int32_t i = 0; i < c.workers; ++i) {
    disp_row_[i] = arena.Allocate<uint16_t>(static_cast<size_t>(c.width));
  }
  boost_q8_ = arena.Allocate<uint16_t>(256);
  histogram_ = arena.Allocate<uint32_t>(256);
  upsampler_.Carve(arena, c.width, c.height, c.working_scale, c.working_width, c.working_height,
                   c.workers);
  // The luma ring also serves the chroma rows that the next chroma strip reads ahead.
  const int32_t look_ahead = Max(0, 2 * chroma_reach_ - luma_reach_) + 2;
  LB_RETURN_IF_ERROR(luma_.Carve(arena, c.width, c.height, 1, RenderConfig::kStripRows, 1, radii_q4,
                                 radii_, layers_, look_ahead, c.workers));
  LB_RETURN_IF_ERROR(chroma_.Carve(arena, cw, ch, 2, RenderConfig::kStripRows / 2, 2, radii_q4,
                                   radii_, layers_, 0, c.workers));
  if (arena.overflowed()) {
    return Status(Code::kOutOfMemory, "render: arena of %zu bytes is too small (%zu needed)",
                  arena.size(), arena.used());
  }
  return Status::Ok();
}

// The layers' tables, filled at each Begin rather than at Carve: the pipeline lends the render's
// memory to the depth stages between renders.
void RenderStage::FillTables() {
  const RenderConfig& c = config_;
  // Layers far to near: signed radii -r[n-1] .. -r[1], 0, r[1] .. r[n-1].
  LayerRadiiQ4(c.max_radius, radii_q4_);
  for (int32_t k = 0; k < layers_; ++k)
    radius_of_layer_[k] = k < radii_ ? radii_ - 1 - k : k - radii_ + 1;
  // Each signed radius to its layer and the weight of the next layer, linear in between.
  const int32_t offset = c.max_radius * 16;
  for (int32_t s = -offset; s <= offset; ++s) {
    int32_t k = 0;
    auto signed_q4 = [&](int32_t layer) {
      return layer < radii_ - 1 ? -radii_q4_[radii_ - 1 - layer] : radii_q4_[layer - radii_ + 1];
    };
    while (k + 1 < layers_ && signed_q4(k + 1) <= s) ++k;
    int32_t frac = 0;
    if (k + 1 < layers_) {
      const int32_t span = signed_q4(k + 1) - signed_q4(k);
      frac = ((s - signed_q4(k)) * 256 + span / 2) / span;
      if (frac >= 256) ++k, frac = 0;
    }
    layer_of_[s + offset] = static_cast<uint16_t>(k << 8 | frac);
  }
}

Status RenderStage::Configure(const RenderConfig& config, Arena& arena) {
  LB_RETURN_IF_ERROR(Validate(config));
  config_ = config;
  begun_ = false;
  runner_ = &inline_;
  return Carve(arena);
}

void RenderStage::SetRunner(TaskRunner* runner) {
  runner_ = runner != nullptr && runner->workers() <= config_.workers ? runner : &inline_;
}

Status RenderStage::Begin(const ConstPlanarU8& ref, ConstImageU16 disp_q8,
                          const RenderParams& params) {
  const int32_t cw = (config_.width + 1) / 2, ch = (config_.height + 1) / 2;
  if (ref.count != 3 || ref.planes[0].width != config_.width ||
      ref.planes[0].height != config_.height || ref.planes[1].width != cw ||
      ref.planes[1].height != ch || ref.planes[2].width != cw || ref.planes[2].height != ch ||
      ref.planes[0].data == nullptr || ref.planes[1].data == nullptr ||
      ref.planes[2].data == nullptr) {
    return Status(Code::kInvalidArgument, "render: reference is not %dx%d YCbCr 4:2:0",
                  config_.width, config_.height);
  }
  if (disp_q8.width != config_.working_width || disp_q8.height != config_.working_height ||
      disp_q8.data == nullptr) {
    return Status(Code::kInvalidArgument, "render: disparity is %dx%d, expected %dx%d",
                  disp_q8.width, disp_q8.height, config_.working_width, config_.working_height);
  }
  LB_RETURN_IF_ERROR(ValidateParams(params));
  FillTables();
  ref_ = ref;
  disp_ = disp_q8;
  params_ = params;
  next_row_ = 0;
  batch_y0_ = batch_count_ = batch_next_ = 0;

  const FocusRegion& r = params.focus;
  const int32_t focus =
      FocusDisparityQ8(disp_, config_.working_scale, r.x, r.y, r.width, r.height, histogram_);
  lens_.Set(params.f_number, config_.working_scale, config_.max_radius, focus);

  const ApertureShape shape(params.aperture);
  // Highlight gain ramps from 1 at the threshold to the full gain at 255.
  const int32_t threshold = params.highlight_threshold;
  for (int32_t y = 0; y < 256; ++y) {
    double gain = 1.0;
    if (y >= threshold && params.highlight_gain > 1.0f) {
      gain += (params.highlight_gain - 1.0) * (y - threshold + 1) / (256 - threshold);
    }
    boost_q8_[y] = static_cast<uint16_t>(std::lround(gain * 256.0));
  }
  int32_t max_luma = 0, max_gain = 0;
  for (int32_t y = 0; y < 256; ++y) {
    max_luma = Max(max_luma, (y * boost_q8_[y] + 128) >> 8);
    max_gain = Max(max_gain, boost_q8_[y]);
  }
  luma_.Begin(shape, ShiftFor(max_luma, luma_.max_half()));
  chroma_.Begin(shape, ShiftFor((128 * max_gain + 128) >> 8, chroma_.max_half()));
  upsampler_.Begin(ref, disp_q8);
  luma_stale_ = false;
  begun_ = true;
  return Status::Ok();
}

void RenderStage::FillLumaRow(int32_t y, int32_t worker) {
  uint16_t* disp_row = disp_row_[worker];
  upsampler_.Row(y, disp_row, worker);
  int16_t* s = luma_.RadiusRow(y);
  int16_t* v = luma_.ValueRow(y, 0);
  const uint8_t* luma = ref_.planes[0].Row(y);
  // Two loops: the radii's vectorise, the boost's table lookups do not.
  RadiusRow(lens_, disp_row, config_.width, s);
  for (int32_t x = 0; x < config_.width; ++x) {
    v[x] = static_cast<int16_t>((luma[x] * boost_q8_[luma[x]] + 128) >> 8);
  }
  luma_.CommitRowShared(y, layer_of_, config_.max_radius * 16);
}

void RenderStage::FillChromaRow(int32_t cy) {
  // The chroma sample's radius is the mean of its 2x2 luma block's; its boost follows the
  // block's mean luma, applied to the chroma's distance from grey.
  const int32_t y0 = 2 * cy, y1 = Min(2 * cy + 1, config_.height - 1);
  const int16_t* s0 = luma_.RadiusRow(y0);
  const int16_t* s1 = luma_.RadiusRow(y1);
  const uint8_t* l0 = ref_.planes[0].Row(y0);
  const uint8_t* l1 = ref_.planes[0].Row(y1);
  const uint8_t* cb = ref_.planes[1].Row(cy);
  const uint8_t* cr = ref_.planes[2].Row(cy);
  int16_t* s = chroma_.RadiusRow(cy);
  int16_t* vb = chroma_.ValueRow(cy, 0);
  int16_t* vr = chroma_.ValueRow(cy, 1);
  const int32_t cw = (config_.width + 1) / 2;
  // Two loops, as FillLumaRow's: the radii's vectorise.
  const int32_t pairs = config_.width / 2;  // chroma samples with two luma columns
  MeanRadiusRow(s0, s1, pairs, s);
  if (pairs < cw) {
    const int32_t a = 2 * pairs;
    s[pairs] = static_cast<int16_t>((2 * s0[a] + 2 * s1[a] + 2) >> 2);
  }
  for (int32_t x = 0; x < cw; ++x) {
    const int32_t a = 2 * x, b = Min(2 * x + 1, config_.width - 1);
    const int32_t gain = boost_q8_[(l0[a] + l0[b] + l1[a] + l1[b] + 2) >> 2];
    vb[x] = static_cast<int16_t>(((cb[x] - 128) * gain + 128) >> 8);
    vr[x] = static_cast<int16_t>(((cr[x] - 128) * gain + 128) >> 8);
  }
  chroma_.CommitRowShared(cy, layer_of_, config_.max_radius * 16);
}

void RenderStage::FillRows(int32_t luma_end, int32_t chroma_end) {
  // Contiguous runs of rows, one per worker: a worker's guide rows (depth_upsample.h) serve the
  // rows next to each other. Every row's values depend on the row alone.
  const int32_t tasks = runner_->workers();
  const int32_t luma_begin = luma_.next_row();
  if (luma_end > luma_begin) {
    const int32_t n = luma_end - luma_begin;
    ParallelFor(*runner_, Min(tasks, n), [&](int32_t t, int32_t worker) {
      const int32_t parts = Min(tasks, n);
      for (int32_t y = luma_begin + n * t / parts; y < luma_begin + n * (t + 1) / parts; ++y) {
        FillLumaRow(y, worker);
      }
    });
    luma_.Advance(luma_end);
  }
  const int32_t chroma_begin = chroma_.next_row();
  if (chroma_end > chroma_begin) {
    // A chroma row reads its two luma rows from the ring: they must still be there.
    for (int32_t cy = chroma_begin; cy < chroma_end; ++cy) {
      const int32_t y0 = 2 * cy, y1 = Min(2 * cy + 1, config_.height - 1);
      if (!luma_.Holds(y0) || !luma_.Holds(y1)) luma_stale_ = true;
    }
    const int32_t n = chroma_end - chroma_begin;
    ParallelFor(*runner_, Min(tasks, n), [&](int32_t t, int32_t) {
      const int32_t parts = Min(tasks, n);
      for (int32_t cy = chroma_begin + n * t / parts; cy < chroma_begin + n * (t + 1) / parts;
           ++cy) {
        FillChromaRow(cy);
      }
    });
    chroma_.Advance(chroma_end);
  }
}

Status RenderStage::NextStrip(ConstPlanarU8* strip, int32_t* y0, int32_t* rows) {
  if (!begun_) return Status(Code::kInvalidArgument, "render: NextStrip before Begin");
  if (batch_next_ == batch_count_) LB_RETURN_IF_ERROR(RenderBatch());
  if (batch_count_ == 0) {
    *y0 = next_row_;
    *rows = 0;
    return Status::Ok();
  }
  const int32_t i = batch_next_++;
  *y0 = batch_y0_ + i * RenderConfig::kStripRows;
  *rows = Min(RenderConfig::kStripRows, config_.height - *y0);
  next_row_ = *y0 + *rows;
  *strip = strips_[i].AsConst();
  return Status::Ok();
}

// The next config.workers strips (fewer at the bottom): the ring rows they read are filled in
// order, then each strip renders from them on a worker of its own.
Status RenderStage::RenderBatch() {
  constexpr int32_t kStrip = RenderConfig::kStripRows;
  const int32_t h = config_.height, ch = (h + 1) / 2;
  batch_y0_ = next_row_;
  batch_count_ = Min(config_.workers, (h - next_row_ + kStrip - 1) / kStrip);
  batch_next_ = 0;
  if (batch_count_ <= 0) {
    batch_count_ = 0;
    return Status::Ok();
  }
  const int32_t last_y0 = batch_y0_ + (batch_count_ - 1) * kStrip;
  const int32_t last_rows = Min(kStrip, h - last_y0);
  const int32_t chroma_end = Min(ch, last_y0 / 2 + (last_rows + 1) / 2 + chroma_reach_);
  const int32_t luma_end = Min(h, Max(last_y0 + last_rows + luma_reach_, 2 * chroma_end));
  FillRows(luma_end, chroma_end);
  const int32_t offset = config_.max_radius * 16;
  ParallelFor(*runner_, batch_count_, [&](int32_t i, int32_t worker) {
    const int32_t y0 = batch_y0_ + i * kStrip, rows = Min(kStrip, h - y0);
    luma_.RenderStrip(worker, y0, rows, layer_of_, offset, radius_of_layer_, 0,
                      &strips_[i].planes[0]);
    chroma_.RenderStrip(worker, y0 / 2, (rows + 1) / 2, layer_of_, offset, radius_of_layer_, 128,
                        &strips_[i].planes[1]);
  });
  if (luma_stale_ || luma_.stale() || chroma_.stale()) {
    return Status(Code::kInternal, "render: a strip at rows %d..%d read a recycled ring row",
                  batch_y0_, last_y0 + last_rows - 1);
  }
  return Status::Ok();
}

}  // namespace lb
