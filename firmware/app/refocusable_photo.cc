#include "firmware/app/refocusable_photo.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "algo/core/color.h"
#include "firmware/app/focus.h"
#include "firmware/codecs/image_file.h"
#include "firmware/refocusable/depth_image.h"

namespace lb {
namespace {

// The all-in-focus original's rows, as an image reader streams them, into YCbCr 4:2:0 planes
// (the conversion the pipeline applies to a sensor's reference frame): `y` holds width x height
// bytes, `cb` and `cr` a quarter each (rounded up), `rgb` two rows of RGB8.
class Ycc420Sink final : public FrameSink {
 public:
  Ycc420Sink(uint8_t* y, uint8_t* cb, uint8_t* cr, uint8_t* rgb)
      : y_(y), cb_(cb), cr_(cr), rgb_(rgb) {}
  Status BeginFrame(const FrameInfo& info) override {
    frame_ = info;
    return Status::Ok();
  }
  Status Rows(const FrameRows& rows) override;
  Status EndFrame() override { return Status::Ok(); }

 private:
  FrameInfo frame_;
  uint8_t *y_, *cb_, *cr_, *rgb_;
};

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

}  // namespace

// Where the reader puts the extended XMP, the depth image, its confidence and GImage: the photo's
// buffers, at most their Configure sizes when fixed (a confidence without room is left out).
class RefocusablePhoto::Memory final : public RefocusableMemory {
 public:
  explicit Memory(RefocusablePhoto* photo) : photo_(photo) {}
  ExtendedXmpChunk* Chunks(size_t count) override {
    return photo_->Fit(&photo_->chunks_, count) ? photo_->chunks_.data() : nullptr;
  }
  uint8_t* Bytes(Part part, size_t count) override {
    std::vector<uint8_t>* v = part == Part::kExtendedXmp  ? &photo_->extended_
                              : part == Part::kDepthPng   ? &photo_->depth_image_
                              : part == Part::kImage      ? &photo_->original_
                              : part == Part::kConfidence ? &photo_->confidence_image_
                                                          : nullptr;
    return v != nullptr && photo_->Fit(v, count) ? v->data() : nullptr;
  }

 private:
  RefocusablePhoto* photo_;
};

template <typename T>
bool RefocusablePhoto::Fit(std::vector<T>* v, size_t count) {
  if (count <= v->size()) return true;
  if (count <= v->capacity()) {  // GImage, cut to its size by the last file: no reallocation
    v->resize(count);
    return true;
  }
  if (fixed_) return false;
  v->resize(count);
  return true;
}

Status RefocusablePhoto::Configure(const RefocusableLimits& limits) {
  const int32_t W = limits.max_width, H = limits.max_height;
  if (W < 16 || H < 16 || W > kMaxFrameSide || H > kMaxFrameSide) {
    return Status(Code::kInvalidArgument, "refocusable photo: size %dx%d outside 16..%d", W, H,
                  kMaxFrameSide);
  }
  max_side_ = std::max(W, H);
  const size_t pixels = static_cast<size_t>(W) * H;
  const size_t file = limits.max_file_bytes;
  const size_t cpx = static_cast<size_t>((W + 1) / 2) * ((H + 1) / 2);
  // As many chunks as the writer makes of a file this size (more: kOutOfMemory).
  chunks_.resize(file / kExtendedXmpChunk + 2);
  extended_.resize(file);
  // Base64 in the extended XMP: at most 3/4 of the file; a 16-bit depth PNG, at most its
  // values' bytes and a little (stored rows of 64 KiB deflate blocks).
  const size_t depth_px =
      std::min(pixels, static_cast<size_t>(std::max(1, limits.max_depth_pixels)));
  depth_image_.resize(std::min(file / 4 * 3, depth_px * 2 + depth_px / 64 + 65536));
  // The confidence, an 8-bit PNG the depth's size: its bytes, a filter byte a row and a little.
  confidence_image_.resize(std::min(file / 4 * 3, depth_px + depth_px / 16 + 65536));
  original_.reserve(file / 4 * 3);
  rgb_rows_.resize(static_cast<size_t>(max_side_) * 6);
  // The readers' strip: the original's RGB rows, then the depth image's.
  strip_.resize(
      std::max(ImageStripBytes(max_side_, PixelFormat::kRgb8), DepthStripBytes(max_side_)));
  y_.resize(pixels);
  cb_.resize(cpx);
  cr_.resize(cpx);
  depth_values_.resize(depth_px);
  depth_disp_.resize(depth_px);
  disp_q8_.resize(depth_px);
  confidence_.resize(depth_px);
  fixed_ = true;
  reserved_bytes_ = chunks_.size() * sizeof(ExtendedXmpChunk) + extended_.size() +
                    depth_image_.size() + confidence_image_.size() + original_.capacity() +
                    rgb_rows_.size() + strip_.size() + pixels + 2 * cpx + 7 * depth_px;
  return Status::Ok();
}

Status RefocusablePhoto::Decode(const uint8_t* bytes, size_t size, const char* name) {
  width_ = 0;  // nothing decoded until the end
  from_primary_ = has_file_focus_ = has_confidence_ = false;
  Memory memory(this);
  RefocusableFields f;
  LB_RETURN_IF_ERROR(ReadRefocusableFields(bytes, size, name, memory, &f));
  DepthFormat format;
  Status s = DepthFormatOf(f.depth_format, &format);
  if (!s.ok()) return s.Prefix("%s: ", name);
  // Without GImage the photo itself is all there is to refocus. A GImage may lie in the file's
  // bytes (Dynamic Depth): it is kept, as the caller may reuse them.
  from_primary_ = f.image == nullptr;
  if (from_primary_) {
    original_.clear();
  } else if (f.image != original_.data()) {
    if (!Fit(&original_, f.image_size)) {
      return Status(Code::kOutOfMemory, "%s: a GImage of %zu bytes, more than the %zu taken", name,
                    f.image_size, original_.capacity());
    }
    std::copy(f.image, f.image + f.image_size, original_.begin());
  }
  if (!from_primary_) original_.resize(f.image_size);
  LB_RETURN_IF_ERROR(DecodeDepth(f, name));
  const uint8_t* jpeg = from_primary_ ? bytes : f.image;
  LB_RETURN_IF_ERROR(DecodeOriginal(jpeg, from_primary_ ? size : f.image_size, name,
                                    from_primary_ ? "the photo" : "GImage"));

  // The render's working grid: the largest whole-number fraction of the original the depth map
  // covers; a map of another size (a phone's, at the photo's size or a fraction of it that is
  // not whole) is resampled onto it.
  const int32_t width = width_, height = height_;
  width_ = 0;
  const int32_t dw = depth_w_, dh = depth_h_;
  scale_ = std::max(1, std::min(width / dw, height / dh));
  const int32_t gw = width / scale_, gh = height / scale_;
  // Stretched onto the photo, a map of another shape would put depth where it does not belong.
  const double expected_h = static_cast<double>(dw) * height / width;
  if (std::abs(dh - expected_h) > 1.0 + 0.01 * dh) {
    return Status(Code::kUnsupported,
                  "%s: depth map %dx%d is not a whole-number fraction of the %dx%d original, "
                  "nor of its shape",
                  name, dw, dh, width, height);
  }
  const bool resample = dw != gw || dh != gh;
  if (!Fit(&disp_q8_, static_cast<size_t>(gw) * gh) ||
      (resample && !Fit(&depth_disp_, static_cast<size_t>(dw) * dh))) {
    return Status(Code::kOutOfMemory, "%s: a %dx%d depth grid, more than the %zu pixels taken",
                  name, gw, gh, disp_q8_.size());
  }
  const FileDepthUnits units = DepthUnitsOf(f, width, scale_);
  const ImageU16 decoded = MakeView(resample ? depth_disp_.data() : disp_q8_.data(), dw, dh);
  s = DepthValuesToDisparity(MakeView<const uint16_t>(depth_values_.data(), dw, dh), depth_bits_,
                             format, f.near_depth, f.far_depth, units.scale, decoded, &range_);
  if (!s.ok()) return s.Prefix("%s: ", name);
  depth_w_ = gw;
  depth_h_ = gh;
  if (resample) ResampleDisparity(decoded.AsConst(), MakeView(disp_q8_.data(), gw, gh));
  DecodeConfidence(f, name, dw, dh);
  width_ = width;
  orientation_ = f.orientation;
  has_file_focus_ = f.has_focus;
  if (has_file_focus_) {
    file_f_number_ = units.f_number;
    const GFocusInfo& g = f.focus;
    const double target = 256.0 * units.scale / std::max(g.focal_distance, 1e-9);
    file_focus_ = FocusNear(g.focal_point_x, g.focal_point_y, target);
  }
  return Status::Ok();
}

Status RefocusablePhoto::DecodeDepth(const RefocusableFields& f, const char* name) {
  char what[300];
  DepthPngName(name, what, sizeof(what));
  if (!fixed_) {
    // Room for what the header says, once it has passed the checks the decode makes.
    DepthImageHeader header;
    LB_RETURN_IF_ERROR(ProbeDepthImage(f.depth_png, f.depth_png_size, f.depth_mime, what, &header));
    if (header.width <= f.depth_max_side && header.height <= f.depth_max_side) {
      Fit(&depth_values_, static_cast<size_t>(header.width) * header.height);
      Fit(&strip_, DepthStripBytes(header.width));
    }
  }
  DepthImageBuffer depth;
  depth.values = depth_values_.data();
  depth.capacity = depth_values_.size();
  depth.strip = strip_.data();
  depth.strip_bytes = strip_.size();
  LB_RETURN_IF_ERROR(DecodeDepthImageInto(f.depth_png, f.depth_png_size, f.depth_mime, what,
                                          f.depth_max_side, f.depth_width, f.depth_height, &depth));
  depth_w_ = depth.width;
  depth_h_ = depth.height;
  depth_bits_ = depth.bits;
  return Status::Ok();
}

// The file's confidence (dw x dh, the depth image's size, as the reader checked) onto the working
// grid, decoded in the depth values' buffer, which the disparity no longer needs. Optional as
// the reader has it: pixels that do not decode leave the photo without one, and it still
// renders.
void RefocusablePhoto::DecodeConfidence(const RefocusableFields& f, const char* name, int32_t dw,
                                        int32_t dh) {
  const int32_t gw = depth_w_, gh = depth_h_;
  if (f.confidence == nullptr || !Fit(&confidence_, static_cast<size_t>(gw) * gh)) return;
  char what[320];
  snprintf(what, sizeof(what), "%s: %s", name,
           f.dynamic_depth ? "Dynamic Depth confidence item" : "GDepth:Confidence");
  DepthImageBuffer image;
  image.values = depth_values_.data();
  image.capacity = depth_values_.size();
  image.strip = strip_.data();
  image.strip_bytes = strip_.size();
  if (!DecodeDepthImageInto(f.confidence, f.confidence_size, f.confidence_mime, what,
                            f.depth_max_side, dw, dh, &image)
           .ok()) {
    return;
  }
  // A 16-bit map (another writer's) keeps its high byte. A depth map of another size than the
  // grid was resampled bilinearly; its confidence takes the nearest pixel's, centres aligned: a
  // mix of a sure pixel and an unsure one would be a measure of neither.
  const int shift = image.bits - 8;
  for (int32_t y = 0; y < gh; ++y) {
    const int64_t sy = (int64_t{2} * y + 1) * dh / (int64_t{2} * gh);
    const uint16_t* in = depth_values_.data() + static_cast<size_t>(sy) * dw;
    uint8_t* out = confidence_.data() + static_cast<size_t>(y) * gw;
    for (int32_t x = 0; x < gw; ++x) {
      const int64_t sx = (int64_t{2} * x + 1) * dw / (int64_t{2} * gw);
      out[x] = static_cast<uint8_t>(in[sx] >> shift);
    }
  }
  has_confidence_ = true;
}

Status RefocusablePhoto::DecodeOriginal(const uint8_t* jpeg, size_t size, const char* name,
                                        const char* what) {
  // The header first: a few bytes may claim gigabytes of pixels.
  ImageFileInfo info;
  Status s = ProbeImageMemory(jpeg, size, what, &info, ImageFileType::kJpeg);
  if (!s.ok()) return s.Prefix("%s: ", name);
  const int32_t w = info.width, h = info.height;
  if (w > kMaxFrameSide || h > kMaxFrameSide) {
    return Status(Code::kUnsupported,
                  "%s: %s: a %dx%d original, larger than the %dx%d refocus renders", name, what, w,
                  h, kMaxFrameSide, kMaxFrameSide);
  }
  if (w < 16 || h < 16) {
    return Status(Code::kUnsupported, "%s: %s: a %dx%d original is too small to render", name, what,
                  w, h);
  }
  const size_t pixels = static_cast<size_t>(w) * h;
  const size_t cpx = static_cast<size_t>((w + 1) / 2) * ((h + 1) / 2);
  if (fixed_ && (w > max_side_ || h > max_side_ || pixels > y_.size() || cpx > cb_.size())) {
    return Status(Code::kOutOfMemory, "%s: %s: a %dx%d original, larger than the %zu pixels taken",
                  name, what, w, h, y_.size());
  }
  Fit(&y_, pixels);
  Fit(&cb_, cpx);
  Fit(&cr_, cpx);
  Fit(&rgb_rows_, static_cast<size_t>(w) * 6);
  Fit(&strip_, ImageStripBytes(w, PixelFormat::kRgb8));
  // Straight into the planes, a strip at a time.
  ImageReadMemory memory;
  memory.strip = strip_.data();
  memory.strip_bytes = strip_.size();
  memory.max_width = w;
  memory.max_height = h;
  Ycc420Sink ycc(y_.data(), cb_.data(), cr_.data(), rgb_rows_.data());
  s = StreamImageMemory(jpeg, size, what, 0, ycc, memory, ImageFileType::kJpeg);
  if (!s.ok()) return s.Prefix("%s: ", name);
  width_ = w;
  height_ = h;
  return Status::Ok();
}

FileDepthUnits DepthUnitsOf(const RefocusableFields& file, int32_t width, int32_t working_scale) {
  const double scale = working_scale;
  FileDepthUnits u;
  const double blur_px = file.focus.blur_at_infinity * width, focal = file.focus.focal_distance;
  if (file.has_focus && blur_px > 0.0 && focal > 0.0) {
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
  } else if (1.0 / file.near_depth - 1.0 / file.far_depth < 1.0) {
    // Less than one working pixel of disparity from near to far: not the product's units. A
    // span of a hundredth of the working width gives a blur a phone's would.
    const double span = std::max(4.0, width / (100.0 * scale));
    u.scale = span / (1.0 / file.near_depth - 1.0 / file.far_depth);
  }
  // The stored map must still fit 16-bit Q8.8 disparities.
  u.scale = std::min(u.scale, 65535.0 * file.near_depth / 256.0);
  return u;
}

FocusRegion RefocusablePhoto::FocusNear(double point_x, double point_y, double target_q8) const {
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

ConstPlanarU8 RefocusablePhoto::reference() const {
  ConstPlanarU8 p;
  p.count = 3;
  const int32_t cw = (width_ + 1) / 2, ch = (height_ + 1) / 2;
  p.planes[0] = {y_.data(), width_, height_, 1, width_};
  p.planes[1] = {cb_.data(), cw, ch, 1, cw};
  p.planes[2] = {cr_.data(), cw, ch, 1, cw};
  return p;
}

ConstImageU16 RefocusablePhoto::disparity_q8() const {
  return {disp_q8_.data(), depth_w_, depth_h_, 1, depth_w_};
}

ConstImageU8 RefocusablePhoto::confidence() const {
  if (!has_confidence_) return ConstImageU8();
  return {confidence_.data(), depth_w_, depth_h_, 1, depth_w_};
}

RenderConfig RefocusablePhoto::RenderConfigFor(int32_t max_blur_radius, int32_t workers) const {
  return {.width = width_,
          .height = height_,
          .working_scale = scale_,
          .working_width = depth_w_,
          .working_height = depth_h_,
          .max_radius = max_blur_radius,
          .workers = workers};
}

Status RefocusablePhoto::BeginRender(const RenderConfig& config, Arena& arena, TaskRunner* runner,
                                     const RenderParams& params, RenderStage* stage) const {
  if (width_ == 0) return Status(Code::kInvalidArgument, "render before a photo was decoded");
  LB_RETURN_IF_ERROR(RenderStage::Validate(config));
  LB_RETURN_IF_ERROR(stage->Configure(config, arena));
  stage->SetRunner(runner);
  return stage->Begin(reference(), disparity_q8(), params);
}

}  // namespace lb
