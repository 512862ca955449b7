#include "firmware/app/refocus_engine.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>

#include "algo/pipeline/pipeline.h"
#include "firmware/app/focus.h"
#include "firmware/app/job.h"
#include "firmware/app/rerender.h"
#include "firmware/codecs/image_file.h"
#include "firmware/codecs/jpeg_writer.h"
#include "firmware/platform/worker_pool.h"
#include "firmware/storage/input_file.h"

namespace lb {

namespace {

// Mean of a step x step block of `src` (clamped at its edges) into each pixel of `dst`.
void BoxDown(const uint8_t* src, int32_t sw, int32_t sh, int32_t step, uint8_t* dst, int32_t dw,
             int32_t dh) {
  const uint32_t n = static_cast<uint32_t>(step * step);
  for (int32_t y = 0; y < dh; ++y) {
    for (int32_t x = 0; x < dw; ++x) {
      uint32_t sum = 0;
      for (int32_t j = 0; j < step; ++j) {
        const int32_t sy = std::min(y * step + j, sh - 1);
        const uint8_t* row = src + static_cast<size_t>(sy) * sw;
        for (int32_t i = 0; i < step; ++i) sum += row[std::min(x * step + i, sw - 1)];
      }
      dst[static_cast<size_t>(y) * dw + x] = static_cast<uint8_t>((sum + n / 2) / n);
    }
  }
}

// Waits while the camera works, between strips.
class CameraYield final : public StripObserver {
 public:
  CameraYield(const std::atomic<bool>* busy, int64_t* paused) : busy_(busy), paused_(paused) {}
  void OnStrip(const ConstPlanarU8&, int32_t, int32_t) override {
    if (busy_ == nullptr || !busy_->load(std::memory_order_acquire)) return;
    ++*paused_;
    const timespec nap = {0, 2 * 1000 * 1000};
    while (busy_->load(std::memory_order_acquire)) nanosleep(&nap, nullptr);
  }

 private:
  const std::atomic<bool>* busy_;
  int64_t* paused_;
};

}  // namespace

RefocusEngine::RefocusEngine() = default;
RefocusEngine::~RefocusEngine() = default;

Status RefocusEngine::Configure(const RefocusEngineConfig& config) {
  if (configured_) return Status(Code::kBusy, "refocus engine: configured twice");
  const int32_t W = config.max_width, H = config.max_height;
  if (W < 16 || H < 16 || W > kMaxFrameSide || H > kMaxFrameSide) {
    return Status(Code::kInvalidArgument, "refocus engine: photo size %dx%d outside 16..%d", W, H,
                  kMaxFrameSide);
  }
  if (config.preview_side < 64 || config.max_blur_radius < 1 || config.max_blur_radius > 128) {
    return Status(Code::kInvalidArgument, "refocus engine: preview side %d, blur radius %d",
                  config.preview_side, config.max_blur_radius);
  }
  config_ = config;
  const size_t pixels = static_cast<size_t>(W) * H;
  // The XMP a photo reassembles holds its original and depth once (GImage, GDepth); the file
  // holds them again after the image as Dynamic Depth's items, read whole but never copied.
  const size_t xmp_bytes = pixels + (size_t{1} << 20);
  const bool default_size = config_.max_file_bytes == 0;
  if (default_size) config_.max_file_bytes = xmp_bytes + pixels / 2;
  const size_t file = config_.max_file_bytes;
  const int32_t pw = std::min(W, config.preview_side), ph = std::min(H, config.preview_side);
  const size_t ppx = static_cast<size_t>(pw) * ph;
  const size_t pcpx = static_cast<size_t>((pw + 1) / 2) * ((ph + 1) / 2);
  scratch_.reserve(file);
  RefocusableLimits limits;
  limits.max_width = W;
  limits.max_height = H;
  limits.max_file_bytes = default_size ? xmp_bytes : file;
  // The camera's photos carry a map of at least half their side or 1 MP: more than 1 MP at some
  // sizes (12 MP among them).
  PipelineConfig camera;
  camera.width = W;
  camera.height = H;
  const int32_t map_scale = Pipeline::MapScale(camera);
  limits.max_depth_pixels = std::max(config.max_depth_pixels, (W / map_scale) * (H / map_scale));
  LB_RETURN_IF_ERROR(file_.Configure(limits));
  py_.resize(ppx);
  pcb_.resize(pcpx);
  pcr_.resize(pcpx);
  pdisp_q8_.resize(ppx);

  // The arenas: the largest any photo up to W x H needs, either way round (a portrait photo on
  // a landscape camera), whatever its depth map's scale.
  const int32_t workers = WorkerPool::CountFor(config.threads);
  const auto render_bytes = [&](int32_t w, int32_t h, int32_t max_scale) {
    size_t most = 0;
    for (int32_t s = 1; s <= max_scale; ++s) {
      const RenderConfig rc = {.width = w,
                               .height = h,
                               .working_scale = s,
                               .working_width = std::max(1, w / s),
                               .working_height = std::max(1, h / s),
                               .max_radius = config.max_blur_radius,
                               .workers = workers};
      most = std::max(most, Arena::RoundUp(RenderStage::RequiredBytes(rc)));
    }
    return most;
  };
  full_bytes_ = std::max(render_bytes(W, H, 16), render_bytes(H, W, 16));
  preview_bytes_ = std::max(render_bytes(pw, ph, 1), render_bytes(ph, pw, 1));
  LB_RETURN_IF_ERROR(full_block_.Reserve(full_bytes_, "for the refocus engine's render"));
  LB_RETURN_IF_ERROR(preview_block_.Reserve(preview_bytes_, "for the refocus engine's preview"));
  full_ = std::make_unique<RenderStage>();
  preview_ = std::make_unique<RenderStage>();
  writer_ = std::make_unique<JpegWriter>();
  pool_ = std::make_unique<WorkerPool>();
  LB_RETURN_IF_ERROR(pool_->Start(workers));
  reserved_bytes_ = scratch_.capacity() + file_.reserved_bytes() + ppx * 3 + 2 * pcpx +
                    full_bytes_ + preview_bytes_;
  configured_ = true;
  return Status::Ok();
}

Status RefocusEngine::LoadFile(const char* path) {
  // The web side checked the name without following links; a link swapped in since is refused.
  int fd = -1;
  int64_t length = 0;
  LB_RETURN_IF_ERROR(OpenInputFile(path, &fd, &length, O_NOFOLLOW));
  const size_t size = static_cast<size_t>(length);
  if (size > scratch_.capacity()) {
    close(fd);
    return Status(Code::kOutOfMemory, "%s: %zu bytes, more than the %zu the engine takes", path,
                  size, scratch_.capacity());
  }
  scratch_.resize(size);
  size_t done = 0;
  while (done < size) {
    const ssize_t n = read(fd, scratch_.data() + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    done += static_cast<size_t>(n);
  }
  close(fd);
  if (done != size) return Status(Code::kIoError, "%s: read %zu of %zu bytes", path, done, size);
  return Decode(path, size);
}

Status RefocusEngine::Load(const char* path) {
  if (!configured_) return Status(Code::kInvalidArgument, "refocus engine: Load before Configure");
  loaded_ = false;
  output_size_ = 0;
  WaitForCamera();  // reading and decoding a 12 MP photo takes about 0.1 s of a core
  Status s = LoadFile(path);
  scratch_.clear();  // the bytes are decoded; the buffer now holds outputs
  if (!s.ok()) return s;
  LB_RETURN_IF_ERROR(MakePreviewInputs());
  loaded_ = true;
  return Status::Ok();
}

Status RefocusEngine::Decode(const char* path, size_t size) {
  Status s = file_.Decode(scratch_.data(), size, path);
  // No XMP or no depth map: a photo, but not one to refocus (kNotFound is for missing files).
  if (s.code() == Code::kNotFound) return Status(Code::kUnsupported, "%s", s.message());
  LB_RETURN_IF_ERROR(s);
  photo_ = EnginePhoto();
  photo_.width = file_.width();
  photo_.height = file_.height();
  photo_.orientation = file_.orientation();
  photo_.working_scale = file_.working_scale();
  // What it was rendered with (GFocus), else the middle at f/2.8.
  RenderParams& cur = photo_.current;
  cur.focus = file_.has_file_focus() ? file_.file_focus()
                                     : FocusAtPoint(photo_.width / 2, photo_.height / 2);
  cur.f_number = file_.has_file_focus() ? file_.file_f_number() : 2.8f;
  const ConstImageU8 confidence = file_.confidence();
  photo_.guess_permille = confidence.data != nullptr ? Pipeline::GuessPermille(confidence) : -1;
  return Status::Ok();
}

Status RefocusEngine::MakePreviewInputs() {
  const int32_t w = photo_.width, h = photo_.height, side = config_.preview_side;
  int32_t step = 1;
  while ((std::max(w, h) + step - 1) / step > side) ++step;
  preview_step_ = step;
  const int32_t scale = photo_.working_scale;
  const ConstImageU16 disp = file_.disparity_q8();
  const int32_t depth_w = disp.width, depth_h = disp.height;
  int32_t pw, ph;
  if (scale % step == 0) {
    // The depth map as it is, upsampled by the render stage as at full size.
    preview_scale_ = scale / step;
    preview_dw_ = depth_w;
    preview_dh_ = depth_h;
    pw = depth_w * preview_scale_;
    ph = depth_h * preview_scale_;
    preview_disp_ = disp.data;
  } else {
    // Nearest depth per preview pixel, in preview pixels per view step.
    preview_scale_ = 1;
    pw = w / step;
    ph = h / step;
    preview_dw_ = pw;
    preview_dh_ = ph;
    for (int32_t y = 0; y < ph; ++y) {
      const int32_t sy = std::min((y * step + step / 2) / scale, depth_h - 1);
      for (int32_t x = 0; x < pw; ++x) {
        const int32_t sx = std::min((x * step + step / 2) / scale, depth_w - 1);
        const int64_t d = disp.Row(sy)[sx];
        pdisp_q8_[static_cast<size_t>(y) * pw + x] =
            static_cast<uint16_t>(std::min<int64_t>((d * scale + step / 2) / step, 65535));
      }
    }
    preview_disp_ = pdisp_q8_.data();
  }
  if (pw < 16 || ph < 16) {
    return Status(Code::kUnsupported, "a %dx%d photo is too small to preview", w, h);
  }
  photo_.preview_width = pw;
  photo_.preview_height = ph;
  if (step > 1) {
    const ConstPlanarU8 ref = file_.reference();
    BoxDown(ref.planes[0].data, w, h, step, py_.data(), pw, ph);
    const int32_t cw = (w + 1) / 2, ch = (h + 1) / 2;
    BoxDown(ref.planes[1].data, cw, ch, step, pcb_.data(), (pw + 1) / 2, (ph + 1) / 2);
    BoxDown(ref.planes[2].data, cw, ch, step, pcr_.data(), (pw + 1) / 2, (ph + 1) / 2);
  }
  return Status::Ok();
}

void RefocusEngine::WaitForCamera() {
  CameraYield yield(camera_busy_, &paused_strips_);
  yield.OnStrip(ConstPlanarU8(), 0, 0);
}

Status RefocusEngine::RenderInto(RenderStage* stage, const RenderParams& params, bool preview) {
  if (!loaded_) return Status(Code::kInvalidArgument, "refocus engine: render before Load");
  LB_RETURN_IF_ERROR(RenderStage::ValidateParams(params));
  const int32_t step = preview ? preview_step_ : 1;
  RenderConfig rc = file_.RenderConfigFor(std::max(1, (config_.max_blur_radius + step / 2) / step),
                                          pool_->workers());
  ConstPlanarU8 ref = file_.reference();
  ConstImageU16 disp = file_.disparity_q8();
  if (preview) {
    rc.width = photo_.preview_width;
    rc.height = photo_.preview_height;
    rc.working_scale = preview_scale_;
    rc.working_width = preview_dw_;
    rc.working_height = preview_dh_;
    // The original's own planes at step 1 (the preview may crop them), else the downscaled.
    const int32_t cw = (rc.width + 1) / 2, ch = (rc.height + 1) / 2;
    if (step > 1) {
      ref.planes[0] = {py_.data(), rc.width, rc.height, 1, rc.width};
      ref.planes[1] = {pcb_.data(), cw, ch, 1, cw};
      ref.planes[2] = {pcr_.data(), cw, ch, 1, cw};
    } else {
      ref.planes[0] = {ref.planes[0].data, rc.width, rc.height, 1, ref.planes[0].stride};
      ref.planes[1] = {ref.planes[1].data, cw, ch, 1, ref.planes[1].stride};
      ref.planes[2] = {ref.planes[2].data, cw, ch, 1, ref.planes[2].stride};
    }
    disp = {preview_disp_, rc.working_width, rc.working_height, 1, rc.working_width};
  }
  LB_RETURN_IF_ERROR(RenderStage::Validate(rc));
  const ArenaBlock& block = preview ? preview_block_ : full_block_;
  if (RenderStage::RequiredBytes(rc) > block.size()) {
    return Status(Code::kOutOfMemory, "refocus engine: render needs more than its %zu bytes",
                  block.size());
  }
  Arena arena = block.arena();
  WaitForCamera();
  if (!preview) return file_.BeginRender(rc, arena, pool_.get(), params, stage);
  RenderParams p = params;
  if (step > 1) {
    FocusRegion& f = p.focus;
    if (f.width > 0 && f.height > 0) {
      f = {f.x / step, f.y / step, std::max(1, f.width / step), std::max(1, f.height / step)};
    }
  }
  LB_RETURN_IF_ERROR(stage->Configure(rc, arena));
  stage->SetRunner(pool_.get());
  return stage->Begin(ref, disp, p);
}

Status RefocusEngine::RenderPreview(const RenderParams& params) {
  output_size_ = 0;
  LB_RETURN_IF_ERROR(RenderInto(preview_.get(), params, true));
  JpegMetadata meta;  // no EXIF (no allocation) unless the photo must be turned
  if (photo_.orientation > 1) meta.orientation = photo_.orientation;
  LB_RETURN_IF_ERROR(writer_->BeginMemory(&scratch_, photo_.preview_width, photo_.preview_height,
                                          config_.preview_quality, meta));
  CameraYield yield(camera_busy_, &paused_strips_);
  LB_RETURN_IF_ERROR(WriteStrips(preview_.get(), &yield, writer_.get()));
  output_size_ = scratch_.size();
  return Status::Ok();
}

Status RefocusEngine::RenderFull(const RenderParams& params) {
  output_size_ = 0;
  LB_RETURN_IF_ERROR(RenderInto(full_.get(), params, false));
  JpegMetadata meta;
  if (photo_.orientation > 1) meta.orientation = photo_.orientation;
  LB_RETURN_IF_ERROR(
      writer_->BeginMemory(&scratch_, photo_.width, photo_.height, config_.quality, meta));
  CameraYield yield(camera_busy_, &paused_strips_);
  LB_RETURN_IF_ERROR(WriteStrips(full_.get(), &yield, writer_.get()));
  output_size_ = scratch_.size();
  return Status::Ok();
}

Status RefocusEngine::Save(const RenderParams& params, const char* out_path) {
  output_size_ = 0;
  LB_RETURN_IF_ERROR(RenderInto(full_.get(), params, false));
  CameraYield yield(camera_busy_, &paused_strips_);
  // A new photo beside the others: never over one, however the name was chosen.
  return WriteRerendered(full_.get(), params, SourceOf(file_), config_.quality, "refocusd web",
                         &yield, nullptr, out_path, AtomicFile::Replace::kNever);
}

}  // namespace lb
