#include "algo/pipeline/pipeline.h"

#include <algorithm>
#include <cstring>

#include "algo/core/color.h"
#include "algo/depth/depth_order.h"
#include "algo/pipeline/auto_geometry.h"
#include "algo/pipeline/ingest.h"

namespace lb {

// Plan's scale is at most kMaxWidth / 8 (the smallest working bound RequiredBytes accepts), so
// the box sums of the ingest fit their uint32 accumulator (ingest.h).
static_assert(PipelineConfig::kMaxWidth / 8 <= ingest::kMaxBoxScale &&
                  PipelineConfig::kMaxHeight / 8 <= ingest::kMaxBoxScale,
              "the ingest's box sums could overflow uint32");

Pipeline::Layout Pipeline::Plan(const PipelineConfig& c) {
  // The bound is a budget of pixels, whichever way the frame is turned: a square or portrait
  // frame gets as many working pixels as a landscape one (512x512 into 640x480 stays whole).
  const int64_t budget = int64_t{c.max_working_width} * c.max_working_height;
  const int32_t longest = std::max(c.max_working_width, c.max_working_height);
  int32_t s = 1;
  while (int64_t{c.width / s} * (c.height / s) > budget ||
         std::max(c.width / s, c.height / s) > longest) {
    ++s;
  }
  // A frame far thinner than the bound (16x8192 into 640x480) would shrink below one pixel: it
  // gets no depth (ComputeDepth says so) and a scale that keeps a pixel for its flat map.
  const int32_t thin = c.width < c.height ? c.width : c.height;
  if (s > thin) s = thin;
  return {s, c.width / s, c.height / s, DepthRefiner::MapScale(c.width, c.height, s)};
}

// Working images smaller than the depth stage takes give a flat map and a warning.
static bool HasDepth(int32_t work_w, int32_t work_h) {
  return work_w >= DepthConfig::kMinSize && work_h >= DepthConfig::kMinSize;
}

static DepthConfig MakeDepthConfig(const PipelineConfig& c, int32_t w, int32_t h) {
  DepthConfig d;
  d.width = w;
  d.height = h;
  d.views = c.frames;
  d.reference = c.reference;
  d.labels = c.labels;
  d.disp_min_q8 = c.disp_min_q8;
  d.disp_max_q8 = c.disp_max_q8;
  d.workers = c.workers;
  d.smooth_weight = c.smooth_weight;
  d.max_cycles = c.max_cycles;
  d.subpixel = c.subpixel;
  d.confidence = c.confidence;
  if (c.geometry == ViewGeometry::kAuto) d.geometry = ViewGeometry::kKnownPoses;
  if (c.geometry == ViewGeometry::kAuto && c.plan_range) {
    // Placeholder range for sizing; every burst sets its own (auto_geometry.h).
    d.disp_min_q8 = 0;
    d.disp_max_q8 = 16 << 8;
  }
  return d;
}

// Frames too small to follow get no motion stage: ComputeDepth reports them as degenerate.
static bool UsesMotion(const PipelineConfig& c, int32_t work_w, int32_t work_h) {
  return c.geometry == ViewGeometry::kAuto && work_w >= MotionConfig::kMinSize &&
         work_h >= MotionConfig::kMinSize;
}

static MotionConfig MakeMotionConfig(const PipelineConfig& c, int32_t w, int32_t h) {
  MotionConfig m;
  m.width = w;
  m.height = h;
  m.views = c.frames;
  m.estimate_focal = !(c.focal_px > 0);  // nobody told the lens: the frames may
  m.workers = c.workers;
  return m;
}

// The render reads the map, not the depth stage's grid.
static RenderConfig MakeRenderConfig(const PipelineConfig& c, int32_t map_scale) {
  RenderConfig r;
  r.width = c.width;
  r.height = c.height;
  r.working_scale = map_scale;
  r.working_width = c.width / map_scale;
  r.working_height = c.height / map_scale;
  r.max_radius = c.max_blur_radius;
  r.workers = c.workers;
  return r;
}

int32_t Pipeline::GuessPermille(ConstImageU8 confidence) {
  if (confidence.data == nullptr || confidence.width <= 0 || confidence.height <= 0) return 0;
  int64_t guesses = 0;
  for (int32_t y = 0; y < confidence.height; ++y) {
    const uint8_t* row = confidence.Row(y);
    for (int32_t x = 0; x < confidence.width; ++x) guesses += row[x] < kGuessConfidence;
  }
  return static_cast<int32_t>(guesses * 1000 / (int64_t{confidence.width} * confidence.height));
}

Status Pipeline::RequiredBytes(const PipelineConfig& c, size_t* bytes) {
  *bytes = 0;
  const int32_t min_side = c.render ? 16 : DepthConfig::kMinSize;
  if (c.width < min_side || c.height < min_side || c.width > PipelineConfig::kMaxWidth ||
      c.height > PipelineConfig::kMaxHeight) {
    return Status(Code::kInvalidArgument, "frame size %dx%d outside %dx%d .. %dx%d", c.width,
                  c.height, min_side, min_side, PipelineConfig::kMaxWidth,
                  PipelineConfig::kMaxHeight);
  }
  if (c.frames < 2) {
    return Status(Code::kInvalidArgument, "a burst of %d frame%s: depth needs at least 2", c.frames,
                  c.frames == 1 ? "" : "s");
  }
  if (c.frames > PipelineConfig::kMaxFrames) {
    return Status(Code::kInvalidArgument, "a burst of %d frames: at most %d are used", c.frames,
                  PipelineConfig::kMaxFrames);
  }
  if (c.geometry != ViewGeometry::kRectified && c.geometry != ViewGeometry::kAuto) {
    // The pipeline takes no poses, and a handheld burst's are unknown to it: kAuto finds them.
    return Status(Code::kInvalidArgument, "geometry %d is neither rectified nor auto",
                  static_cast<int>(c.geometry));
  }
  if (c.max_working_width < 8 || c.max_working_height < 8) {
    return Status(Code::kInvalidArgument, "working size bound %dx%d is below 8x8",
                  c.max_working_width, c.max_working_height);
  }
  if (c.workers < 1 || c.workers > kMaxWorkers) {
    return Status(Code::kInvalidArgument, "%d worker threads: 1 to %d are supported", c.workers,
                  kMaxWorkers);
  }
  const Layout l = Plan(c);
  if (HasDepth(l.work_w, l.work_h)) {
    LB_RETURN_IF_ERROR(DepthStage::Validate(MakeDepthConfig(c, l.work_w, l.work_h)));
  }
  if (c.render) {
    LB_RETURN_IF_ERROR(RenderStage::Validate(MakeRenderConfig(c, l.map_scale)));
  }
  if (UsesMotion(c, l.work_w, l.work_h)) {
    LB_RETURN_IF_ERROR(MotionStage::Validate(MakeMotionConfig(c, l.work_w, l.work_h)));
    if (!(c.focal_px >= 0)) {
      return Status(Code::kInvalidArgument, "focal length %g px is negative", c.focal_px);
    }
  }
  Pipeline planner;
  planner.config_ = c;
  planner.scale_ = l.scale;
  planner.work_w_ = l.work_w;
  planner.work_h_ = l.work_h;
  planner.map_scale_ = l.map_scale;
  Arena plan;
  LB_RETURN_IF_ERROR(planner.Carve(plan));
  *bytes = plan.used();
  return Status::Ok();
}

Status Pipeline::Carve(Arena& arena) {
  const PipelineConfig& c = config_;
  ref_.count = 3;
  ref_.planes[0] = arena.AllocateImage<uint8_t>(c.width, c.height);
  ref_.planes[1] = arena.AllocateImage<uint8_t>((c.width + 1) / 2, (c.height + 1) / 2);
  ref_.planes[2] = arena.AllocateImage<uint8_t>((c.width + 1) / 2, (c.height + 1) / 2);
  for (int32_t i = 0; i < c.frames; ++i)
    working_[i] = arena.AllocateImage<uint8_t>(work_w_, work_h_, 3);
  disp_q8_ = arena.AllocateImage<uint16_t>(work_w_, work_h_);
  confidence_ = c.confidence ? arena.AllocateImage<uint8_t>(work_w_, work_h_) : ImageU8{};
  const RefineConfig fc = MakeRefineConfig();
  rgb_rows_[0] = arena.Allocate<uint8_t>(static_cast<size_t>(c.width) * 3);
  rgb_rows_[1] = arena.Allocate<uint8_t>(static_cast<size_t>(c.width) * 3);
  cols_ = arena.Allocate<uint32_t>(static_cast<size_t>(work_w_) * scale_ * 3);
  trim_.Carve(arena, work_w_, c.workers);
  const bool depth = HasDepth(work_w_, work_h_), motion = UsesMotion(c, work_w_, work_h_);
  if (motion) planes_ = arena.Allocate<PlaneHomography>(static_cast<size_t>(c.frames) * c.labels);
  // The stages share one region, each in memory the one before is done with: the depth stage
  // first, the motion stage after it (its points stay readable until the render begins), the
  // refinement after both. The motion stage's pyramids and the depth order's vote use the
  // depth stage's census, which Compute writes only after the first and reads only before the
  // second; the map the refinement writes lies over the depth stage, and the render follows the
  // map (it keeps nothing between renders that it does not rebuild at Begin).
  const DepthConfig dc = MakeDepthConfig(c, work_w_, work_h_);
  const MotionConfig mc = MakeMotionConfig(c, work_w_, work_h_);
  const RenderConfig rc = MakeRenderConfig(c, map_scale_);
  // Each stage starts on a fresh alignment boundary: kAlign of slack per stage.
  const size_t depth_bytes = depth ? DepthStage::RequiredBytes(dc) + Arena::kAlign : 0;
  const size_t spare = depth ? DepthStage::SpareBytes(dc) : 0;
  const bool motion_scratch_shared = motion && depth && MotionStage::ScratchBytes(mc) <= spare;
  const size_t analysis =
      depth_bytes +
      (motion ? MotionStage::RequiredBytes(mc, motion_scratch_shared) + Arena::kAlign : 0);
  const size_t refine = depth ? DepthRefiner::RequiredBytes(fc) + Arena::kAlign : 0;
  Arena map_plan;
  CarveMap(fc, map_plan);
  const size_t map = map_plan.used() + Arena::kAlign;
  const bool map_shared = depth && map <= depth_bytes;
  if (!map_shared) CarveMap(fc, arena);
  const size_t render = c.render ? RenderStage::RequiredBytes(rc) + Arena::kAlign : 0;
  const size_t after_map = (map_shared ? map : 0) + render;
  const size_t shared = analysis + refine > after_map ? analysis + refine : after_map;
  uint8_t* region = arena.Allocate<uint8_t>(shared);
  region_ = region;
  region_bytes_ = shared;
  analysis_bytes_ = analysis;
  if (arena.planning()) return Status::Ok();
  if (arena.overflowed()) {
    return Status(Code::kOutOfMemory, "pipeline arena of %zu bytes is too small (needs %zu)",
                  arena.size(), arena.used());
  }
  Arena analysis_arena(region, shared);
  if (depth) LB_RETURN_IF_ERROR(depth_.Configure(dc, analysis_arena));
  if (motion) {
    Arena scratch(depth_.spare(), spare);
    LB_RETURN_IF_ERROR(
        motion_.Configure(mc, analysis_arena, motion_scratch_shared ? &scratch : nullptr));
  }
  order_scratch_ = nullptr;
  if (depth && motion) {
    if (spare < DepthOrderScratchBytes(work_w_, work_h_)) {
      return Status(Code::kInternal, "depth order: the depth stage's spare memory is too small");
    }
    order_scratch_ = depth_.spare();
  }
  if (depth) {
    Arena refine_arena(region + analysis, shared - analysis);
    refine_.Carve(fc, refine_arena);
  }
  if (map_shared) {
    Arena map_arena(region, map);
    CarveMap(fc, map_arena);
  }
  if (!c.render) return Status::Ok();
  const size_t render_at = map_shared ? map : 0;
  Arena render_arena(region + render_at, shared - render_at);
  return render_.Configure(rc, render_arena);
}

void Pipeline::CarveMap(const RefineConfig& fc, Arena& arena) {
  map_q8_ = arena.AllocateImage<uint16_t>(fc.map_width, fc.map_height);
  map_confidence_ =
      config_.confidence ? arena.AllocateImage<uint8_t>(fc.map_width, fc.map_height) : ImageU8{};
}

void Pipeline::SetRunner(TaskRunner* runner) {
  runner_ = runner != nullptr && runner->workers() <= config_.workers ? runner : &inline_;
  depth_.SetRunner(runner);
  motion_.SetRunner(runner);
  render_.SetRunner(runner);
  refine_.SetRunner(runner);
  trim_.SetRunner(runner);
}

RefineConfig Pipeline::MakeRefineConfig() const {
  RefineConfig r;
  r.width = config_.width;
  r.height = config_.height;
  r.work_scale = scale_;
  r.work_width = work_w_;
  r.work_height = work_h_;
  r.map_scale = map_scale_;
  r.map_width = config_.width / map_scale_;
  r.map_height = config_.height / map_scale_;
  r.workers = config_.workers;
  return r;
}

void Pipeline::MakeMap(bool flat) {
  if (!flat) {
    refine_.Run(ref_.AsConst(), disp_q8_.AsConst(), confidence_.AsConst(), map_q8_,
                map_confidence_);
    return;
  }
  const uint16_t value = static_cast<uint16_t>(ToMapQ8(disp_min_q8_));
  for (int32_t y = 0; y < map_q8_.height; ++y) {
    uint16_t* row = map_q8_.Row(y);
    for (int32_t x = 0; x < map_q8_.width; ++x) row[x] = value;
  }
  for (int32_t y = 0; y < map_confidence_.height; ++y)
    memset(map_confidence_.Row(y), 0, static_cast<size_t>(map_confidence_.width));
}

Status Pipeline::Configure(const PipelineConfig& config, void* arena, size_t bytes) {
  size_t needed = 0;
  LB_RETURN_IF_ERROR(RequiredBytes(config, &needed));
  if (bytes < needed) {
    return Status(Code::kOutOfMemory, "pipeline needs %zu arena bytes, got %zu", needed, bytes);
  }
  if (reinterpret_cast<uintptr_t>(arena) % Arena::kAlign != 0) {
    return Status(Code::kInvalidArgument, "pipeline arena is not %zu-byte aligned", Arena::kAlign);
  }
  config_ = config;
  runner_ = &inline_;
  const Layout l = Plan(config);
  scale_ = l.scale;
  work_w_ = l.work_w;
  work_h_ = l.work_h;
  map_scale_ = l.map_scale;
  Arena a(arena, bytes);
  LB_RETURN_IF_ERROR(Carve(a));
  ResetBurst();
  return Status::Ok();
}

void Pipeline::ResetBurst() {
  depth_warning_ = Status::Ok();
  received_mask_ = 0;
  in_frame_ = false;
  depth_ready_ = false;
  render_started_ = false;
}

Status Pipeline::BeginFrame(const FrameInfo& info) {
  if (in_frame_)
    return Status(Code::kInvalidArgument, "frame %d began before frame %d ended", info.index,
                  frame_.index);
  if (info.index < 0 || info.index >= config_.frames) {
    return Status(Code::kInvalidArgument, "frame index %d outside the burst of %d", info.index,
                  config_.frames);
  }
  if (received_mask_ & (1u << info.index)) {
    return Status(Code::kInvalidArgument, "frame %d delivered twice", info.index);
  }
  if (info.width != config_.width || info.height != config_.height) {
    return Status(Code::kInvalidArgument, "frame %d is %dx%d, the burst is %dx%d", info.index,
                  info.width, info.height, config_.width, config_.height);
  }
  if (BytesPerPixel(info.format) == 0) {
    return Status(Code::kUnsupported, "frame %d: pixel format %s", info.index,
                  PixelFormatName(info.format));
  }
  frame_ = info;
  in_frame_ = true;
  next_row_ = 0;
  depth_ready_ = false;
  memset(cols_, 0, static_cast<size_t>(work_w_) * scale_ * 3 * sizeof(uint32_t));
  return Status::Ok();
}

Status Pipeline::Rows(const FrameRows& rows) {
  if (!in_frame_) return Status(Code::kInvalidArgument, "rows delivered outside a frame");
  if (rows.y0 != next_row_ || rows.height < 0 || rows.y0 + rows.height > frame_.height) {
    return Status(Code::kInvalidArgument, "frame %d: rows %d..%d out of order (expected row %d)",
                  frame_.index, rows.y0, rows.y0 + rows.height - 1, next_row_);
  }
  const int32_t planes = PlaneCount(frame_.format);
  for (int32_t k = 0; k < planes; ++k) {
    if (rows.planes[k] == nullptr && rows.height > 0) {
      return Status(Code::kInvalidArgument, "frame %d: %s rows without plane %d", frame_.index,
                    PixelFormatName(frame_.format), k);
    }
  }
  if (planes > 1 && rows.y0 % 2 != 0) {
    return Status(Code::kInvalidArgument, "frame %d: a %s strip starts on odd row %d", frame_.index,
                  PixelFormatName(frame_.format), rows.y0);
  }
  // Bands of columns, each a whole number of boxes starting on an even column (a YUYV or NV12
  // pair, a 4:2:0 chroma sample), so every task writes columns of its own: the same bytes for
  // any number of workers.
  const int32_t bands = runner_->workers() > 1 ? runner_->workers() : 1;
  ParallelFor(*runner_, bands, [&](int32_t band, int32_t) {
    const int32_t unit = scale_ % 2 == 0 ? 1 : 2;  // working columns a band boundary moves by
    auto edge = [&](int32_t b) { return work_w_ * b / bands / unit * unit; };
    const int32_t wx0 = edge(band), wx1 = band + 1 == bands ? work_w_ : edge(band + 1);
    const int32_t x0 = wx0 * scale_, x1 = band + 1 == bands ? config_.width : wx1 * scale_;
    if (x1 <= x0) return;
    for (int32_t i = 0; i < rows.height; ++i) {
      const uint8_t* src = rows.planes[0] + rows.strides[0] * i;
      // 4:2:0: one chroma row for two rows, the strip's first at its own start.
      const ptrdiff_t c = (rows.y0 + i) / 2 - rows.y0 / 2;
      const uint8_t* u = planes > 1 ? rows.planes[1] + rows.strides[1] * c : nullptr;
      const uint8_t* v = planes > 2 ? rows.planes[2] + rows.strides[2] * c : nullptr;
      IngestRow(src, u, v, rows.y0 + i, {x0, x1, wx0, wx1});
    }
  });
  next_row_ += rows.height;
  return Status::Ok();
}

void Pipeline::IngestRow(const uint8_t* src, const uint8_t* u, const uint8_t* v, int32_t y,
                         const Columns& c) {
  const int32_t n = c.x1 - c.x0;
  uint8_t* rgb = rgb_rows_[y & 1] + 3 * c.x0;
  // x0 is even: a YUYV pair or a 4:2:0 chroma sample starts there (NV12's UV pair at byte x0,
  // I420's U and V at x0 / 2).
  const ptrdiff_t cx = frame_.format == PixelFormat::kNv12 ? c.x0 : c.x0 / 2;
  RowToRgb8(frame_.format, frame_.range,
            src + static_cast<ptrdiff_t>(c.x0) * BytesPerPixel(frame_.format),
            u != nullptr ? u + cx : nullptr, v != nullptr ? v + cx : nullptr, n, rgb);
  if (frame_.index == config_.reference) {
    RowRgb8ToY(rgb, n, ref_.planes[0].Row(y) + c.x0);
    if ((y & 1) || y == config_.height - 1) FlushChroma(y, c);
  }
  // Integer box downscale: `scale_` rows into the column sums, then each box's mean (rounded).
  const int32_t s = scale_;
  if (y >= work_h_ * s || c.wx1 <= c.wx0) return;
  uint32_t* cols = cols_ + 3 * static_cast<ptrdiff_t>(c.wx0) * s;
  ingest::ColumnAccumulateRowC(rgb, 3 * (c.wx1 - c.wx0) * s, cols);
  if ((y + 1) % s == 0) {
    ingest::BoxEmitColumnsC(cols, c.wx1 - c.wx0, s, working_[frame_.index].Row(y / s) + 3 * c.wx0);
  }
}

void Pipeline::FlushChroma(int32_t y, const Columns& c) {
  const uint8_t* row0 = rgb_rows_[(y & 1) ? 0 : 1] + 3 * c.x0;
  const uint8_t* row1 = rgb_rows_[y & 1] + 3 * c.x0;
  if (!(y & 1)) row0 = row1;  // a lone last row
  RowsRgb8ToCbCr420(row0, row1, c.x1 - c.x0, ref_.planes[1].Row(y / 2) + c.x0 / 2,
                    ref_.planes[2].Row(y / 2) + c.x0 / 2);
}

Status Pipeline::EndFrame() {
  if (!in_frame_) return Status(Code::kInvalidArgument, "EndFrame without BeginFrame");
  in_frame_ = false;
  if (next_row_ != frame_.height) {
    return Status(Code::kCorruptData, "frame %d ended after %d of %d rows", frame_.index, next_row_,
                  frame_.height);
  }
  received_mask_ |= 1u << frame_.index;
  return Status::Ok();
}

Status Pipeline::ComputeDepth() {
  const uint32_t all = (config_.frames >= 32) ? ~0u : ((1u << config_.frames) - 1);
  if ((received_mask_ & all) != all) {
    for (int32_t i = 0; i < config_.frames; ++i) {
      if (!(received_mask_ & (1u << i))) {
        return Status(Code::kNotFound, "frame %d of the burst of %d is missing", i, config_.frames);
      }
    }
  }
  ConstImageU8 views[PipelineConfig::kMaxFrames];
  for (int32_t i = 0; i < config_.frames; ++i) views[i] = working_[i].AsConst();
  depth_warning_ = Status::Ok();
  const int32_t config_bias = DepthStage::MapBiasQ8(config_.disp_min_q8);
  disp_min_q8_ = config_.disp_min_q8 + config_bias;
  disp_max_q8_ = config_.disp_max_q8 + config_bias;
  Status geometry = Status::Ok();
  if (!HasDepth(work_w_, work_h_)) {
    geometry = Status(Code::kDegenerate,
                      "frames of %dx%d are too thin for depth: within the working size bound "
                      "%dx%d they shrink below %dx%d (take frames of a less extreme shape)",
                      config_.width, config_.height, config_.max_working_width,
                      config_.max_working_height, DepthConfig::kMinSize, DepthConfig::kMinSize);
  } else if (config_.geometry == ViewGeometry::kAuto) {
    geometry = EstimateGeometry(views);
  }
  if (geometry.code() == Code::kDegenerate) {
    // Everything at one depth: the render keeps the whole picture sharp.
    depth_warning_ = geometry;
    for (int32_t y = 0; y < work_h_; ++y) {
      uint16_t* row = disp_q8_.Row(y);
      for (int32_t x = 0; x < work_w_; ++x) row[x] = static_cast<uint16_t>(disp_min_q8_);
    }
    for (int32_t y = 0; y < confidence_.height; ++y)
      memset(confidence_.Row(y), 0, static_cast<size_t>(work_w_));
    low_confidence_permille_ = config_.confidence ? 1000 : 0;
    MakeMap(true);
    depth_ready_ = true;
    return Status::Ok();
  }
  LB_RETURN_IF_ERROR(geometry);
  LB_RETURN_IF_ERROR(depth_.Compute(views, disp_q8_));
  low_confidence_permille_ = 0;
  if (depth_.confidence() != nullptr && confidence_.data != nullptr) {
    // Out of the stage's memory, which the render takes over.
    for (int32_t y = 0; y < work_h_; ++y) {
      const uint8_t* row = depth_.confidence() + static_cast<size_t>(y) * work_w_;
      memcpy(confidence_.Row(y), row, static_cast<size_t>(work_w_));
    }
    low_confidence_permille_ = GuessPermille(confidence_.AsConst());
  }
  if (config_.geometry == ViewGeometry::kAuto) {
    // SetDepthGeometry rebuilds the planes for every burst, so they are still this one's.
    LB_RETURN_IF_ERROR(OrderDepth(views, planes_, order_scratch_, &depth_, &motion_,
                                  &motion_result_, disp_q8_, nullptr));
  }
  // Near and far are settled: the near side's overreach goes back (fattening_trim.h), from a
  // copy in the depth stage's census, which is free until the next burst.
  const DepthConfig& d = depth_.config();
  const ImageU16 copy = MakeView(reinterpret_cast<uint16_t*>(depth_.spare()), work_w_, work_h_);
  for (int32_t y = 0; y < work_h_; ++y)
    memcpy(copy.Row(y), disp_q8_.Row(y), static_cast<size_t>(work_w_) * sizeof(uint16_t));
  trim_.Run(views[config_.reference], copy.AsConst(), disp_q8_, FatteningTrim::LabelStepQ8(d));
  // The map's own range: a signed one is lifted by the stage's bias (depth_stage.h).
  disp_min_q8_ = d.disp_min_q8 + DepthStage::MapBiasQ8(d);
  disp_max_q8_ = d.disp_max_q8 + DepthStage::MapBiasQ8(d);
  MakeMap(false);
  depth_ready_ = true;
  return Status::Ok();
}

// Poses, then the burst's label range and the planes' homographies for the depth stage.
Status Pipeline::EstimateGeometry(const ConstImageU8* views) {
  if (!UsesMotion(config_, work_w_, work_h_)) {
    if (config_.max_working_width < MotionConfig::kMinSize ||
        config_.max_working_height < MotionConfig::kMinSize) {
      return Status(Code::kDegenerate,
                    "the working size bound %dx%d is below the %dx%d the camera's motion needs: "
                    "raise it",
                    config_.max_working_width, config_.max_working_height, MotionConfig::kMinSize,
                    MotionConfig::kMinSize);
    }
    return Status(Code::kDegenerate,
                  "frames of %dx%d are too small to follow the camera's motion (at least %dx%d "
                  "at the working resolution): take the burst at a higher resolution",
                  config_.width, config_.height, MotionConfig::kMinSize, MotionConfig::kMinSize);
  }
  CameraIntrinsics k = DefaultIntrinsics(work_w_, work_h_);
  if (config_.focal_px > 0) k.fx = k.fy = config_.focal_px / scale_;
  LB_RETURN_IF_ERROR(motion_.Estimate(views, config_.reference, k, &motion_result_));
  LabelRange range;
  return SetDepthGeometry(motion_result_, !config_.plan_range, &depth_, planes_, &range);
}

Status Pipeline::BeginRender(const RenderParams& params) {
  if (!config_.render)
    return Status(Code::kInvalidArgument, "a depth-only pipeline renders no photo");
  if (!depth_ready_) return Status(Code::kInvalidArgument, "render before depth was computed");
  LB_RETURN_IF_ERROR(render_.Begin(ref_.AsConst(), map_q8_.AsConst(), params));
  render_started_ = true;
  return Status::Ok();
}

Status Pipeline::NextStrip(ConstPlanarU8* strip, int32_t* y0, int32_t* rows) {
  if (!render_started_) return Status(Code::kInvalidArgument, "NextStrip before BeginRender");
  return render_.NextStrip(strip, y0, rows);
}

}  // namespace lb
