#include "firmware/app/rerender.h"

#include <cstdlib>
#include <memory>
#include <vector>

#include "algo/core/color.h"
#include "firmware/app/refocusable.h"
#include "firmware/codecs/image_file.h"
#include "firmware/codecs/jpeg_writer.h"
#include "firmware/platform/worker_pool.h"
#include "firmware/refocusable/refocusable_reader.h"
#include "firmware/storage/atomic_file.h"
#include "firmware/storage/input_file.h"

namespace lb {
namespace {

// A refocusable JPEG is read whole; larger than any the product writes at 8192x8192.
constexpr size_t kMaxFileBytes = size_t{512} << 20;

}  // namespace

Status Rerenderer::Load(const char* path) {
  std::vector<uint8_t> bytes;
  LB_RETURN_IF_ERROR(ReadInputFile(path, kMaxFileBytes, &bytes));
  RefocusableImage file;
  LB_RETURN_IF_ERROR(ReadRefocusable(bytes.data(), bytes.size(), path, &file));
  bytes = std::vector<uint8_t>();  // the parts are copied out; the file's bytes are not needed
  if (file.xmp.image.empty()) {
    return Status(Code::kUnsupported, "%s: no all-in-focus original (GImage) to re-render from",
                  path);
  }
  Status s = DisparityFromDepth(file, &disp_q8_, &range_);
  if (!s.ok()) return s.Prefix("%s: ", path);
  // The original's header first: a few bytes may claim gigabytes of pixels.
  ImageFileInfo info;
  s = ProbeImageMemory(file.xmp.image.data(), file.xmp.image.size(), "GImage", &info,
                       ImageFileType::kJpeg);
  if (!s.ok()) return s.Prefix("%s: ", path);
  if (info.width > PipelineConfig::kMaxWidth || info.height > PipelineConfig::kMaxHeight) {
    return Status(Code::kUnsupported,
                  "%s: GImage: a %dx%d original, larger than the %dx%d refocus renders", path,
                  info.width, info.height, PipelineConfig::kMaxWidth, PipelineConfig::kMaxHeight);
  }
  // Straight into the planes, a strip at a time (the same reader and conversion as the web
  // page's engine).
  width_ = info.width;
  height_ = info.height;
  const int32_t cw = (width_ + 1) / 2, ch = (height_ + 1) / 2;
  y_.assign(static_cast<size_t>(width_) * height_, 0);
  cb_.assign(static_cast<size_t>(cw) * ch, 0);
  cr_.assign(static_cast<size_t>(cw) * ch, 0);
  std::vector<uint8_t> rgb(static_cast<size_t>(width_) * 3 * 2);
  std::vector<uint8_t> strip(ImageStripBytes(width_, PixelFormat::kRgb8));
  ImageReadMemory memory;
  memory.strip = strip.data();
  memory.strip_bytes = strip.size();
  memory.max_width = width_;
  memory.max_height = height_;
  Ycc420Sink ycc(y_.data(), cb_.data(), cr_.data(), rgb.data());
  s = StreamImageMemory(file.xmp.image.data(), file.xmp.image.size(), "GImage", 0, ycc, memory,
                        ImageFileType::kJpeg);
  if (!s.ok()) {
    width_ = 0;  // nothing loaded: Render refuses
    return s.Prefix("%s: ", path);
  }
  orientation_ = file.orientation;
  depth_w_ = file.depth.width;
  depth_h_ = file.depth.height;
  scale_ = depth_w_ > 0 ? width_ / depth_w_ : 0;
  if (scale_ < 1 || depth_h_ * scale_ > height_ || depth_w_ * scale_ > width_ ||
      height_ / scale_ != depth_h_) {
    const Status refused(Code::kUnsupported,
                         "%s: depth map %dx%d is not a whole-number fraction of the %dx%d original",
                         path, depth_w_, depth_h_, width_, height_);
    width_ = 0;  // nothing loaded: Render refuses
    return refused;
  }
  original_jpeg_ = std::move(file.xmp.image);
  return Status::Ok();
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
    RowToRgb8(frame_.format, rows.planes[0] + i * rows.strides[0], nullptr, w, row);
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
  const size_t bytes = RenderStage::RequiredBytes(rc);
  std::unique_ptr<void, decltype(&free)> block(aligned_alloc(Arena::kAlign, Arena::RoundUp(bytes)),
                                               &free);
  if (!block) return Status(Code::kOutOfMemory, "cannot allocate %zu bytes to render", bytes);
  Arena arena(block.get(), Arena::RoundUp(bytes));
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
