// PNG through libpng. libpng reports errors by longjmp: everything that must survive one (the
// png structs, the row buffers) lives in PngReader, so nothing with a destructor is skipped.
#include "firmware/codecs/png_reader.h"

#include <png.h>

#include <cinttypes>
#include <csetjmp>
#include <cstring>

#include "firmware/codecs/decoder.h"

namespace lb {
namespace codecs {
namespace {

class PngReader {
 public:
  PngReader(ByteSource& src, const DecodeRequest& request) : src_(src), request_(request) {}
  ~PngReader() {
    if (png_ != nullptr) png_destroy_read_struct(&png_, &info_, nullptr);
  }

  Status Run();

 private:
  static void OnError(png_structp png, png_const_charp message) {
    auto* self = static_cast<PngReader*>(png_get_error_ptr(png));
    snprintf(self->message_, sizeof(self->message_), "%s", message);
    png_longjmp(png, 1);
  }
  static void OnWarning(png_structp, png_const_charp) {}  // benign: unknown chunks, sRGB quirks
  static void OnRead(png_structp png, png_bytep data, size_t size) {
    auto* self = static_cast<PngReader*>(png_get_io_ptr(png));
    if (self->src_.Read(data, size) != size) {
      self->ended_ = true;
      png_error(png, "truncated");
    }
  }

  Status Decode();
  Status CheckPlainGray(png_uint_32 width, png_uint_32 height, int color, int interlace) const;

  ByteSource& src_;
  const DecodeRequest& request_;
  png_structp png_ = nullptr;
  png_infop info_ = nullptr;
  Buffer rows_;
  size_t row_bytes_ = 0;
  bool ended_ = false;
  char message_[160] = {};
};

Status PngReader::Run() {
  const char* name = request_.name;
  png_ = png_create_read_struct(PNG_LIBPNG_VER_STRING, this, OnError, OnWarning);
  if (png_ == nullptr) return Status(Code::kOutOfMemory, "%s: cannot create a PNG reader", name);
  info_ = png_create_info_struct(png_);
  if (info_ == nullptr) return Status(Code::kOutOfMemory, "%s: cannot create a PNG reader", name);
  png_set_read_fn(png_, this, OnRead);
  // By default libpng only warns about a bad CRC in an ancillary chunk; corruption is corruption.
  png_set_crc_action(png_, PNG_CRC_ERROR_QUIT, PNG_CRC_ERROR_QUIT);

  if (setjmp(png_jmpbuf(png_)) != 0) {
    if (ended_ && src_.error() != 0) {
      return Status(Code::kIoError, "%s: read error: %s", name, strerror(src_.error()));
    }
    if (ended_) {
      return Status(Code::kCorruptData, "%s: truncated: PNG data ends after %" PRIu64 " bytes",
                    name, src_.consumed());
    }
    // libpng's own messages often start with "PNG" already.
    const bool named = strncmp(message_, "PNG ", 4) == 0;
    return Status(Code::kCorruptData, "%s: %s%s", name, named ? "" : "PNG ", message_);
  }
  // Decode() may longjmp back here: it keeps only trivially destructible locals.
  return Decode();
}

Status PngReader::Decode() {
  const char* name = request_.name;
  png_read_info(png_, info_);
  png_uint_32 width = 0, height = 0;
  int depth = 0, color = 0, interlace = 0;
  png_get_IHDR(png_, info_, &width, &height, &depth, &color, &interlace, nullptr, nullptr);
  LB_RETURN_IF_ERROR(CheckImageSize(name, width, height, request_.max_side));
  if (request_.plain_gray) LB_RETURN_IF_ERROR(CheckPlainGray(width, height, color, interlace));
  const bool gray = (color & PNG_COLOR_MASK_COLOR) == 0;
  const bool wide = depth == 16;
  const PixelFormat format = gray ? (wide ? PixelFormat::kGray16 : PixelFormat::kGray8)
                                  : (wide ? PixelFormat::kRgb16 : PixelFormat::kRgb8);
  const int32_t rows = static_cast<int32_t>(height);
  if (!SetHeader(request_, format, static_cast<int32_t>(width), rows)) return Status::Ok();

  if (color == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png_);
  if (gray && depth < 8) png_set_expand_gray_1_2_4_to_8(png_);
  // Unconditional: palette expansion turns a tRNS chunk into an alpha channel too.
  png_set_strip_alpha(png_);
  if (wide && HostIsLittleEndian()) png_set_swap(png_);
  const int passes = png_set_interlace_handling(png_);
  png_read_update_info(png_, info_);

  row_bytes_ = png_get_rowbytes(png_, info_);
  const size_t expect = static_cast<size_t>(width) * static_cast<size_t>(BytesPerPixel(format));
  if (row_bytes_ != expect || png_get_channels(png_, info_) != (gray ? 1 : 3)) {
    return Status(Code::kInternal, "%s: PNG rows are %zu bytes, expected %zu", name, row_bytes_,
                  expect);
  }
  // Interlaced images need every pass before any row is final: hold the whole image then.
  const int32_t buffer_rows = passes > 1 ? static_cast<int32_t>(height) : kImageStripRows;
  uint8_t* buffer = nullptr;
  LB_RETURN_IF_ERROR(
      RowBuffer(request_, static_cast<uint64_t>(row_bytes_) * static_cast<uint64_t>(buffer_rows),
                &rows_, &buffer));

  LB_RETURN_IF_ERROR(BeginFrame(request_));
  if (passes > 1) {
    for (int pass = 0; pass < passes; ++pass) {
      for (int32_t y = 0; y < rows; ++y) {
        png_read_row(png_, buffer + row_bytes_ * static_cast<size_t>(y), nullptr);
      }
    }
    for (int32_t y0 = 0; y0 < rows; y0 += kImageStripRows) {
      const uint8_t* strip = buffer + row_bytes_ * static_cast<size_t>(y0);
      LB_RETURN_IF_ERROR(DeliverRows(request_, strip, row_bytes_, y0, StripRows(y0, rows)));
    }
  } else {
    for (int32_t y0 = 0; y0 < rows; y0 += kImageStripRows) {
      const int32_t n = StripRows(y0, rows);
      for (int32_t y = 0; y < n; ++y) {
        png_read_row(png_, buffer + row_bytes_ * static_cast<size_t>(y), nullptr);
      }
      LB_RETURN_IF_ERROR(DeliverRows(request_, buffer, row_bytes_, y0, n));
    }
  }
  // Reads up to IEND, so a broken CRC after the image data is still an error.
  png_read_end(png_, nullptr);
  return request_.sink->EndFrame();
}

Status PngReader::CheckPlainGray(png_uint_32 width, png_uint_32 height, int color,
                                 int interlace) const {
  const char* name = request_.name;
  if (color != PNG_COLOR_TYPE_GRAY) {
    return Status(Code::kCorruptData, "%s: PNG: not a greyscale image without alpha", name);
  }
  if (interlace != PNG_INTERLACE_NONE)
    return Status(Code::kCorruptData, "%s: PNG: interlaced", name);
  if ((request_.width > 0 && width != static_cast<png_uint_32>(request_.width)) ||
      (request_.height > 0 && height != static_cast<png_uint_32>(request_.height))) {
    return Status(Code::kCorruptData, "%s: PNG: image is %ux%u, expected %dx%d", name,
                  static_cast<unsigned>(width), static_cast<unsigned>(height), request_.width,
                  request_.height);
  }
  return Status::Ok();
}

// Gathers grey rows (8 or 16 bits, native-endian) as 16-bit values: into the caller's fixed
// array (checked against the header), or growing a vector with the rows actually decoded so a
// header that lies about its size costs nothing.
class GrayValues final : public FrameSink {
 public:
  GrayValues(const char* name, std::vector<uint16_t>* grow, uint16_t* fixed, size_t capacity)
      : name_(name), grow_(grow), fixed_(fixed), capacity_(capacity) {}
  Status BeginFrame(const FrameInfo& info) override {
    width = info.width;
    height = info.height;
    bits = info.format == PixelFormat::kGray16 ? 16 : 8;
    if (grow_ == nullptr && static_cast<uint64_t>(width) * height > capacity_) {
      return Status(Code::kOutOfMemory, "%s: a %dx%d PNG, more than the %zu values it may fill",
                    name_, width, height, capacity_);
    }
    return Status::Ok();
  }
  Status Rows(const FrameRows& rows) override {
    for (int32_t y = 0; y < rows.height; ++y) {
      const uint8_t* row = rows.planes[0] + y * rows.strides[0];
      uint16_t* out = fixed_ ? fixed_ + static_cast<size_t>(rows.y0 + y) * width : nullptr;
      for (int32_t x = 0; x < width; ++x) {
        uint16_t v = row[x];
        if (bits == 16) memcpy(&v, row + 2 * x, 2);
        if (grow_ != nullptr) {
          grow_->push_back(v);
        } else {
          out[x] = v;
        }
      }
    }
    return Status::Ok();
  }
  Status EndFrame() override { return Status::Ok(); }

  int32_t width = 0, height = 0;  // the frame's, once it has begun
  int bits = 0;

 private:
  const char* name_;
  std::vector<uint16_t>* grow_;
  uint16_t* fixed_;
  size_t capacity_;
};

Status DecodeGray(const uint8_t* data, size_t size, const char* name, int32_t max_side,
                  int32_t width, int32_t height, const ImageReadMemory* memory,
                  GrayValues* values) {
  if (size < 8 || png_sig_cmp(data, 0, 8) != 0) {
    return Status(Code::kCorruptData, "%s: not a PNG", name);
  }
  MemorySource src(data, size);
  ImageFileInfo info;
  DecodeRequest request = StreamRequest(name, &info, values);
  request.max_side = max_side;
  request.width = width;
  request.height = height;
  request.plain_gray = true;
  request.memory = memory;
  return DecodePng(src, request);
}

}  // namespace

Status DecodePng(ByteSource& src, const DecodeRequest& request) {
  PngReader reader(src, request);
  return reader.Run();
}

}  // namespace codecs

Status DecodeGrayPng(const uint8_t* data, size_t size, const char* name, int32_t max_side,
                     int32_t width, int32_t height, GrayPng* out) {
  *out = GrayPng();
  codecs::GrayValues values(name, &out->values, nullptr, 0);
  Status s = codecs::DecodeGray(data, size, name, max_side, width, height, nullptr, &values);
  if (!s.ok()) {
    *out = GrayPng();
    return s;
  }
  out->width = values.width;
  out->height = values.height;
  out->bits = values.bits;
  return s;
}

Status DecodeGrayPngInto(const uint8_t* data, size_t size, const char* name, int32_t max_side,
                         int32_t width, int32_t height, GrayPngBuffer* out) {
  out->width = out->height = out->bits = 0;
  ImageReadMemory memory;
  memory.strip = out->strip;
  memory.strip_bytes = out->strip_bytes;
  memory.max_width = memory.max_height = max_side;
  codecs::GrayValues values(name, nullptr, out->values, out->capacity);
  LB_RETURN_IF_ERROR(
      codecs::DecodeGray(data, size, name, max_side, width, height, &memory, &values));
  out->width = values.width;
  out->height = values.height;
  out->bits = values.bits;
  return Status::Ok();
}

}  // namespace lb
