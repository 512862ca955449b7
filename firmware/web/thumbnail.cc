#include "firmware/web/thumbnail.h"

#include "algo/core/color.h"
#include "algo/core/frame.h"
#include "firmware/codecs/exif.h"
#include "firmware/codecs/image_file.h"
#include "firmware/codecs/jpeg_writer.h"

namespace lb {
namespace {

constexpr int32_t kStripRows = JpegWriter::kStripRows;

// Takes the decoded rows (already shrunk by the decoder to at least the thumbnail's width) the
// rest of the way by area averages: input row y belongs to output row y * out_h / in_h, column x
// to x * out_w / in_w, and an output pixel is the mean of its own. Finished rows go to the JPEG
// writer a strip at a time, as YCbCr 4:2:0.
class ShrinkSink final : public FrameSink {
 public:
  ShrinkSink(int32_t width, int quality, int32_t orientation, std::vector<uint8_t>* out,
             const std::function<Status()>& between_strips)
      : width_(width),
        quality_(quality),
        orientation_(orientation),
        out_(out),
        between_strips_(between_strips) {}

  Status BeginFrame(const FrameInfo& info) override {
    if (info.format != PixelFormat::kRgb8 && info.format != PixelFormat::kGray8) {
      return Status(Code::kUnsupported, "thumbnail: %s pixels", PixelFormatName(info.format));
    }
    channels_ = info.format == PixelFormat::kGray8 ? 1 : 3;
    in_w_ = info.width;
    in_h_ = info.height;
    out_w_ = in_w_ < width_ ? in_w_ : width_;
    out_h_ = static_cast<int32_t>((static_cast<int64_t>(in_h_) * out_w_ + in_w_ / 2) / in_w_);
    out_h_ = out_h_ < 1 ? 1 : out_h_;
    column_.resize(static_cast<size_t>(in_w_));
    column_count_.assign(static_cast<size_t>(out_w_), 0);
    for (int32_t x = 0; x < in_w_; ++x) {
      column_[x] = static_cast<int32_t>(static_cast<int64_t>(x) * out_w_ / in_w_);
      ++column_count_[column_[x]];
    }
    sums_.assign(static_cast<size_t>(out_w_) * 3, 0);
    rgb_.resize(static_cast<size_t>(out_w_) * 3 * kStripRows);
    const int32_t cw = (out_w_ + 1) / 2;
    y_.resize(static_cast<size_t>(out_w_) * kStripRows);
    cb_.resize(static_cast<size_t>(cw) * kStripRows / 2);
    cr_.resize(cb_.size());
    JpegMetadata meta;
    // The photo's orientation on the thumbnail too, so the gallery turns it as the browser turns
    // the photo itself.
    if (orientation_ > 1) meta.orientation = orientation_;
    return writer_.BeginMemory(out_, out_w_, out_h_, quality_, meta);
  }

  Status Rows(const FrameRows& rows) override {
    if (between_strips_) LB_RETURN_IF_ERROR(between_strips_());
    for (int32_t i = 0; i < rows.height; ++i) {
      const int32_t y = rows.y0 + i;
      const int32_t oy = static_cast<int32_t>(static_cast<int64_t>(y) * out_h_ / in_h_);
      if (oy != current_) {
        LB_RETURN_IF_ERROR(EmitRow());
        current_ = oy;
      }
      const uint8_t* p = rows.planes[0] + rows.strides[0] * i;
      for (int32_t x = 0; x < in_w_; ++x) {
        uint32_t* s = sums_.data() + column_[x] * 3;
        const uint8_t* px = p + x * channels_;
        s[0] += px[0];
        s[1] += px[channels_ == 3 ? 1 : 0];
        s[2] += px[channels_ == 3 ? 2 : 0];
      }
      ++rows_in_;
    }
    return Status::Ok();
  }

  Status EndFrame() override {
    LB_RETURN_IF_ERROR(EmitRow());
    LB_RETURN_IF_ERROR(WriteStrip());
    return writer_.Finish();
  }

 private:
  // The finished output row into the strip; a full strip to the writer.
  Status EmitRow() {
    if (rows_in_ == 0) return Status::Ok();
    uint8_t* out = rgb_.data() + static_cast<size_t>(strip_rows_) * out_w_ * 3;
    for (int32_t x = 0; x < out_w_ * 3; ++x) {
      const uint32_t n = static_cast<uint32_t>(column_count_[x / 3] * rows_in_);
      out[x] = static_cast<uint8_t>((sums_[x] + n / 2) / n);
      sums_[x] = 0;
    }
    rows_in_ = 0;
    return ++strip_rows_ == kStripRows ? WriteStrip() : Status::Ok();
  }

  Status WriteStrip() {
    if (strip_rows_ == 0) return Status::Ok();
    const int32_t w = out_w_, cw = (w + 1) / 2;
    const size_t row = static_cast<size_t>(w) * 3;
    for (int32_t y = 0; y < strip_rows_; ++y) RowRgb8ToY(rgb_.data() + row * y, w, &y_[y * w]);
    for (int32_t y = 0; y < strip_rows_; y += 2) {
      const uint8_t* r0 = rgb_.data() + row * y;
      const uint8_t* r1 = y + 1 < strip_rows_ ? r0 + row : r0;
      RowsRgb8ToCbCr420(r0, r1, w, &cb_[y / 2 * cw], &cr_[y / 2 * cw]);
    }
    ConstPlanarU8 strip;
    strip.count = 3;
    const int32_t crows = (strip_rows_ + 1) / 2;
    strip.planes[0] = MakeView(static_cast<const uint8_t*>(y_.data()), w, strip_rows_);
    strip.planes[1] = MakeView(static_cast<const uint8_t*>(cb_.data()), cw, crows);
    strip.planes[2] = MakeView(static_cast<const uint8_t*>(cr_.data()), cw, crows);
    const int32_t rows = strip_rows_;
    strip_rows_ = 0;
    return writer_.WriteStrip(strip, rows);
  }

  const int32_t width_;
  const int quality_;
  const int32_t orientation_;
  std::vector<uint8_t>* out_;
  const std::function<Status()>& between_strips_;
  JpegWriter writer_;
  int32_t channels_ = 3, in_w_ = 0, in_h_ = 0, out_w_ = 0, out_h_ = 0;
  int32_t current_ = 0, rows_in_ = 0, strip_rows_ = 0;
  std::vector<int32_t> column_, column_count_;
  std::vector<uint32_t> sums_;
  std::vector<uint8_t> rgb_, y_, cb_, cr_;
};

}  // namespace

Status MakeThumbnail(int fd, int32_t width, int quality, std::vector<uint8_t>* out,
                     const std::function<Status()>& between_strips) {
  out->clear();
  if (width < 1) return Status(Code::kInvalidArgument, "thumbnail width %d", width);
  ShrinkSink shrink(width, quality, ExifOrientationAt(fd), out, between_strips);
  const Status s = StreamImageDescriptor(fd, "thumbnail", width, shrink);
  if (!s.ok()) out->clear();
  return s;
}

}  // namespace lb
