#include "firmware/app/rerender.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <vector>

#include "algo/core/color.h"
#include "firmware/app/focus.h"
#include "firmware/app/refocusable.h"
#include "firmware/codecs/image_file.h"
#include "firmware/codecs/jpeg_writer.h"
#include "firmware/platform/arena_block.h"
#include "firmware/platform/worker_pool.h"
#include "firmware/refocusable/depth_image.h"
#include "firmware/refocusable/refocusable_reader.h"
#include "firmware/storage/atomic_file.h"
#include "firmware/storage/input_file.h"

namespace lb {
namespace {

// A refocusable JPEG is read whole; larger than any the product writes at 8192x8192.
constexpr size_t kMaxFileBytes = size_t{512} << 20;

}  // namespace

Status Rerenderer::Load(const char* path) {
  width_ = 0;  // nothing loaded until the end: Render refuses
  from_primary_ = has_file_focus_ = false;
  std::vector<uint8_t> bytes;
  LB_RETURN_IF_ERROR(ReadInputFile(path, kMaxFileBytes, &bytes));
  RefocusableImage file;
  LB_RETURN_IF_ERROR(ReadRefocusable(bytes.data(), bytes.size(), path, &file));
  // Without GImage the photo itself is all there is to refocus; otherwise its bytes are not
  // needed once the parts are copied out.
  from_primary_ = file.xmp.image.empty();
  std::vector<uint8_t> original = from_primary_ ? std::move(bytes) : std::move(file.xmp.image);
  bytes = std::vector<uint8_t>();
  const char* what = from_primary_ ? "the photo" : "GImage";
  // The original's header first: a few bytes may claim gigabytes of pixels.
  ImageFileInfo info;
  Status s = ProbeImageMemory(original.data(), original.size(), what, &info, ImageFileType::kJpeg);
  if (!s.ok()) return s.Prefix("%s: ", path);
  if (info.width > PipelineConfig::kMaxWidth || info.height > PipelineConfig::kMaxHeight) {
    return Status(Code::kUnsupported,
                  "%s: %s: a %dx%d original, larger than the %dx%d refocus renders", path, what,
                  info.width, info.height, PipelineConfig::kMaxWidth, PipelineConfig::kMaxHeight);
  }
  // Straight into the planes, a strip at a time (the same reader and conversion as the web
  // page's engine).
  const int32_t width = info.width, height = info.height;
  const int32_t cw = (width + 1) / 2, ch = (height + 1) / 2;
  y_.assign(static_cast<size_t>(width) * height, 0);
  cb_.assign(static_cast<size_t>(cw) * ch, 0);
  cr_.assign(static_cast<size_t>(cw) * ch, 0);
  std::vector<uint8_t> rgb(static_cast<size_t>(width) * 3 * 2);
  std::vector<uint8_t> strip(ImageStripBytes(width, PixelFormat::kRgb8));
  ImageReadMemory memory;
  memory.strip = strip.data();
  memory.strip_bytes = strip.size();
  memory.max_width = width;
  memory.max_height = height;
  Ycc420Sink ycc(y_.data(), cb_.data(), cr_.data(), rgb.data());
  s = StreamImageMemory(original.data(), original.size(), what, 0, ycc, memory,
                        ImageFileType::kJpeg);
  if (!s.ok()) return s.Prefix("%s: ", path);

  // The render's working grid: the largest whole-number fraction of the original the depth map
  // covers; a map of another size (a phone's, at the photo's size or a fraction of it that is
  // not whole) is resampled onto it.
  const int32_t dw = file.depth.width, dh = file.depth.height;
  scale_ = std::max(1, std::min(width / dw, height / dh));
  depth_w_ = width / scale_;
  depth_h_ = height / scale_;
  // Stretched onto the photo, a map of another shape would put depth where it does not belong.
  const double expected_h = static_cast<double>(dw) * height / width;
  if (std::abs(dh - expected_h) > 1.0 + 0.01 * dh) {
    return Status(Code::kUnsupported,
                  "%s: depth map %dx%d is not a whole-number fraction of the %dx%d original, "
                  "nor of its shape",
                  path, dw, dh, width, height);
  }
  const FileDepthUnits units = DepthUnitsOf(file.xmp, width, scale_);
  std::vector<uint16_t> disp;
  s = ScaledDisparityFromDepth(file, units.scale, &disp, &range_);
  if (!s.ok()) return s.Prefix("%s: ", path);
  if (dw == depth_w_ && dh == depth_h_) {
    disp_q8_ = std::move(disp);
  } else {
    disp_q8_.assign(static_cast<size_t>(depth_w_) * depth_h_, 0);
    ResampleDisparity(MakeView(disp.data(), dw, dh), MakeView(disp_q8_.data(), depth_w_, depth_h_));
  }
  width_ = width;
  height_ = height;
  has_file_focus_ = file.xmp.has_focus;
  if (has_file_focus_) {
    file_f_number_ = units.f_number;
    const GFocusInfo& g = file.xmp.focus;
    const double target = 256.0 * units.scale / std::max(g.focal_distance, 1e-9);
    file_focus_ = FocusNear(g.focal_point_x, g.focal_point_y, target);
  }
  orientation_ = file.orientation;
  original_jpeg_ = from_primary_ ? std::vector<uint8_t>() : std::move(original);
  return Status::Ok();
}

FileDepthUnits DepthUnitsOf(const RefocusableXmp& xmp, int32_t width, int32_t working_scale) {
  const double scale = working_scale;
  FileDepthUnits u;
  const GDepthInfo& d = xmp.depth;
  const double blur_px = xmp.focus.blur_at_infinity * width, focal = xmp.focus.focal_distance;
  if (xmp.has_focus && blur_px > 0.0 && focal > 0.0) {
    // The lens model: blur = 2 * (2.8 / f) * scale * |disparity - focus disparity|, disparity in
    // working px. The product's own files store depth as 1 / that disparity, so the f-number
    // that gives the file's blur at infinity is the one it was rendered with; when that is no
    // f-number a lens has, the depth is in the writer's own units (a phone's): then the
    // disparity is scaled so that f/2.8 gives the file's blur, and f-numbers keep their meaning
    // relative to it.
    const double f = 2.0 * 2.8 * scale / (blur_px * focal);
    if (f >= RenderParams::kMinFNumber && f <= RenderParams::kMaxFNumber) {
      u.f_number = static_cast<float>(std::round(f * 100.0) / 100.0);
    } else {
      u.scale = blur_px * focal / (2.0 * scale);
    }
  } else if (1.0 / d.near_depth - 1.0 / d.far_depth < 1.0) {
    // Less than one working pixel of disparity from near to far: not the product's units. A
    // span of a hundredth of the working width gives a blur a phone's would.
    const double span = std::max(4.0, width / (100.0 * scale));
    u.scale = span / (1.0 / d.near_depth - 1.0 / d.far_depth);
  }
  // The stored map must still fit 16-bit Q8.8 disparities.
  u.scale = std::min(u.scale, 65535.0 * d.near_depth / 256.0);
  return u;
}

FocusRegion Rerenderer::FocusNear(double point_x, double point_y, double target_q8) const {
  const int32_t px = std::clamp(static_cast<int32_t>(point_x * depth_w_), 0, depth_w_ - 1);
  const int32_t py = std::clamp(static_cast<int32_t>(point_y * depth_h_), 0, depth_h_ - 1);
  // GFocus names both a point and a distance; a tap near an edge may land just off the object
  // the writer focused on. The nearest pixel at that distance (within a tenth of the image)
  // keeps both.
  const double tolerance = std::max(4.0, (range_.max_q8 - range_.min_q8) / 50.0);
  const int32_t reach = std::max(depth_w_, depth_h_) / 10;
  int32_t best_x = px, best_y = py;
  int64_t best = -1;
  for (int32_t y = std::max(0, py - reach); y <= std::min(depth_h_ - 1, py + reach); ++y) {
    for (int32_t x = std::max(0, px - reach); x <= std::min(depth_w_ - 1, px + reach); ++x) {
      const double d = disp_q8_[static_cast<size_t>(y) * depth_w_ + x];
      if (std::abs(d - target_q8) > tolerance) continue;
      const int64_t dist = int64_t{x - px} * (x - px) + int64_t{y - py} * (y - py);
      if (best < 0 || dist < best) {
        best = dist;
        best_x = x;
        best_y = y;
      }
    }
  }
  return FocusAtPoint(best_x * scale_ + scale_ / 2, best_y * scale_ + scale_ / 2);
}

void Rerenderer::StartFromFile(RenderParams* params, bool keep_focus, bool keep_f_number) const {
  if (!has_file_focus_) return;
  if (!keep_focus) params->focus = file_focus_;
  if (!keep_f_number) params->f_number = file_f_number_;
}

Status Ycc420Sink::BeginFrame(const FrameInfo& info) {
  frame_ = info;
  return Status::Ok();
}

Status Ycc420Sink::Rows(const FrameRows& rows) {
  const int32_t w = frame_.width, cw = (w + 1) / 2;
  for (int32_t i = 0; i < rows.height; ++i) {
    const int32_t y = rows.y0 + i;
    uint8_t* row = rgb_ + static_cast<size_t>(y & 1) * w * 3;
    RowToRgb8(frame_.format, frame_.range, rows.planes[0] + i * rows.strides[0], nullptr, nullptr,
              w, row);
    RowRgb8ToY(row, w, y_ + static_cast<size_t>(y) * w);
    if ((y & 1) || y == frame_.height - 1) {
      const uint8_t* above = (y & 1) ? rgb_ : row;
      RowsRgb8ToCbCr420(above, row, w, cb_ + static_cast<size_t>(y / 2) * cw,
                        cr_ + static_cast<size_t>(y / 2) * cw);
    }
  }
  return Status::Ok();
}

ConstPlanarU8 Rerenderer::reference() const {
  ConstPlanarU8 p;
  p.count = 3;
  const int32_t cw = (width_ + 1) / 2, ch = (height_ + 1) / 2;
  p.planes[0] = {y_.data(), width_, height_, 1, width_};
  p.planes[1] = {cb_.data(), cw, ch, 1, cw};
  p.planes[2] = {cr_.data(), cw, ch, 1, cw};
  return p;
}

ConstImageU16 Rerenderer::disparity_q8() const {
  return {disp_q8_.data(), depth_w_, depth_h_, 1, depth_w_};
}

Status Rerenderer::Render(const RerenderOptions& options, const char* out_path,
                          StripObserver* observer) {
  if (width_ == 0) return Status(Code::kInvalidArgument, "rerender before a file was loaded");
  RenderConfig rc;
  rc.width = width_;
  rc.height = height_;
  rc.working_scale = scale_;
  rc.working_width = depth_w_;
  rc.working_height = depth_h_;
  rc.max_radius = options.max_blur_radius;
  rc.workers = WorkerPool::CountFor(options.threads);
  LB_RETURN_IF_ERROR(RenderStage::Validate(rc));
  ArenaBlock block;
  LB_RETURN_IF_ERROR(block.Reserve(RenderStage::RequiredBytes(rc), "to render"));
  Arena arena = block.arena();
  RenderStage render;
  LB_RETURN_IF_ERROR(render.Configure(rc, arena));
  WorkerPool pool;
  LB_RETURN_IF_ERROR(pool.Start(rc.workers));
  render.SetRunner(&pool);
  LB_RETURN_IF_ERROR(render.Begin(reference(), disparity_q8(), options.render));

  RerenderSource source;
  source.disp_q8 = disparity_q8();
  source.range = range_;
  source.original_jpeg = &original_jpeg_;
  source.orientation = orientation_;
  source.width = width_;
  source.height = height_;
  return WriteRerendered(&render, options.render, source, options.quality, "refocus rerender",
                         observer, options.progress, out_path);
}

Status WriteRerendered(RenderStage* render, const RenderParams& params,
                       const RerenderSource& source, int quality, const char* software,
                       StripObserver* observer, Progress* progress, const char* out_path,
                       AtomicFile::Replace replace) {
  AtomicFile file;
  LB_RETURN_IF_ERROR(file.Open(out_path));
  JpegMetadata meta;
  meta.make = "LensBlur";
  meta.model = "Re-rendered";
  meta.software = software;
  meta.f_number = params.f_number;
  meta.orientation = source.orientation;
  LB_RETURN_IF_ERROR(BuildRefocusableSegments(source.disp_q8, source.range, *source.original_jpeg,
                                              FocusOf(*render, params, source.width, source.height),
                                              source.width, &meta.extra_segments));
  JpegWriter writer;
  LB_RETURN_IF_ERROR(writer.Begin(&file, source.width, source.height, quality, meta));
  LB_RETURN_IF_ERROR(WriteStrips(render, observer, &writer, progress));
  return file.Commit(replace);
}

}  // namespace lb
