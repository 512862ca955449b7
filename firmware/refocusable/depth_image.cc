#include "firmware/refocusable/depth_image.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <utility>

#include "algo/core/frame.h"
#include "firmware/codecs/image_file.h"

namespace lb {
namespace {

// A grey image stored as colour JPEG comes back with its channels a step or two apart (chroma is
// quantised and upsampled); further apart is colour. PNG is lossless: equal means equal.
constexpr int32_t kJpegChannelSlack = 3;

uint32_t BigEndian32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | p[3];
}

Status TypeOf(std::string_view mime, const char* name, ImageFileType* type) {
  if (mime == "image/png") {
    *type = ImageFileType::kPng;
  } else if (mime == "image/jpeg") {
    *type = ImageFileType::kJpeg;
  } else {
    return Status(Code::kUnsupported, "%s: mime '%.*s' (image/png or image/jpeg)", name,
                  static_cast<int>(std::min<size_t>(mime.size(), 32)), mime.data());
  }
  return Status::Ok();
}

// Grey values out of grey or colour rows, into the caller's array.
class DepthSink final : public FrameSink {
 public:
  // `grow` (may be null): the values go there, grown with the rows actually decoded, instead of
  // into out->values.
  DepthSink(const char* name, bool lossy, DepthImageBuffer* out, std::vector<uint16_t>* grow)
      : name_(name), slack_(lossy ? kJpegChannelSlack : 0), out_(out), grow_(grow) {}

  Status BeginFrame(const FrameInfo& info) override {
    const PixelFormat f = info.format;
    if (f != PixelFormat::kGray8 && f != PixelFormat::kGray16 && f != PixelFormat::kRgb8 &&
        f != PixelFormat::kRgb16) {
      return Status(Code::kUnsupported, "%s: pixel format %s", name_, PixelFormatName(f));
    }
    width_ = info.width;
    channels_ = f == PixelFormat::kRgb8 || f == PixelFormat::kRgb16 ? 3 : 1;
    wide_ = f == PixelFormat::kGray16 || f == PixelFormat::kRgb16;
    if (grow_ == nullptr &&
        static_cast<uint64_t>(info.width) * static_cast<uint64_t>(info.height) > out_->capacity) {
      return Status(Code::kOutOfMemory, "%s: a %dx%d depth image, more than the %zu values given",
                    name_, info.width, info.height, out_->capacity);
    }
    out_->width = info.width;
    out_->height = info.height;
    out_->bits = wide_ ? 16 : 8;
    return Status::Ok();
  }

  Status Rows(const FrameRows& rows) override {
    // A header that claims more rows than the data holds costs only the rows decoded.
    if (grow_ != nullptr) grow_->resize(static_cast<size_t>(rows.y0 + rows.height) * width_);
    uint16_t* values = grow_ != nullptr ? grow_->data() : out_->values;
    for (int32_t y = 0; y < rows.height; ++y) {
      const uint8_t* row = rows.planes[0] + y * rows.strides[0];
      uint16_t* out = values + static_cast<size_t>(rows.y0 + y) * width_;
      for (int32_t x = 0; x < width_; ++x) {
        int32_t c[3];
        for (int32_t k = 0; k < channels_; ++k) c[k] = Sample(row, x * channels_ + k);
        if (channels_ == 1) {
          out[x] = static_cast<uint16_t>(c[0]);
          continue;
        }
        if (std::abs(c[0] - c[1]) > slack_ || std::abs(c[1] - c[2]) > slack_ ||
            std::abs(c[0] - c[2]) > slack_) {
          return Status(Code::kUnsupported,
                        "%s: a colour image, not a depth map: R, G and B differ (%d, %d, %d at "
                        "%d,%d)",
                        name_, c[0], c[1], c[2], x, rows.y0 + y);
        }
        out[x] = static_cast<uint16_t>((c[0] + c[1] + c[2] + 1) / 3);
      }
    }
    return Status::Ok();
  }

  Status EndFrame() override { return Status::Ok(); }

 private:
  int32_t Sample(const uint8_t* row, int32_t i) const {
    if (!wide_) return row[i];
    uint16_t v;
    memcpy(&v, row + 2 * i, 2);  // the readers deliver native-endian samples
    return v;
  }

  const char* name_;
  int32_t slack_;
  DepthImageBuffer* out_;
  std::vector<uint16_t>* grow_;
  int32_t width_ = 0, channels_ = 1;
  bool wide_ = false;
};

}  // namespace

size_t DepthStripBytes(int32_t max_width) {
  return ImageStripBytes(max_width, PixelFormat::kRgb16);
}

Status ProbeDepthImage(const uint8_t* data, size_t size, std::string_view mime, const char* name,
                       DepthImageHeader* header) {
  *header = DepthImageHeader();
  ImageFileType type = ImageFileType::kAuto;
  LB_RETURN_IF_ERROR(TypeOf(mime, name, &type));
  ImageFileInfo info;
  LB_RETURN_IF_ERROR(ProbeImageMemory(data, size, name, &info, type));
  header->width = info.width;
  header->height = info.height;
  header->is_jpeg = type == ImageFileType::kJpeg;
  const bool grey = info.format == PixelFormat::kGray8 || info.format == PixelFormat::kGray16;
  header->bits = info.format == PixelFormat::kGray16 || info.format == PixelFormat::kRgb16 ? 16 : 8;
  header->colour = grey ? "grey" : "RGB";
  // The codec reports what it delivers (alpha stripped): the stored colour type is in IHDR,
  // which the probe has just found where the PNG signature puts it.
  if (type == ImageFileType::kPng && size >= 26 && memcmp(data + 12, "IHDR", 4) == 0 &&
      BigEndian32(data + 16) == static_cast<uint32_t>(info.width)) {
    header->bits = data[24];
    switch (data[25]) {
      case 0:
        header->colour = "grey";
        break;
      case 2:
        header->colour = "RGB";
        break;
      case 3:
        header->colour = "palette";
        break;
      case 4:
        header->colour = "grey+alpha";
        break;
      case 6:
        header->colour = "RGBA";
        break;
      default:
        break;
    }
  }
  return Status::Ok();
}

namespace {

Status Decode(const uint8_t* data, size_t size, std::string_view mime, const char* name,
              int32_t max_side, int32_t width, int32_t height, DepthImageBuffer* out,
              std::vector<uint16_t>* grow) {
  out->width = out->height = out->bits = 0;
  DepthImageHeader header;
  LB_RETURN_IF_ERROR(ProbeDepthImage(data, size, mime, name, &header));
  if (header.width > max_side || header.height > max_side) {
    return Status(Code::kCorruptData, "%s: a %dx%d depth image, larger than %d a side", name,
                  header.width, header.height, max_side);
  }
  if ((width > 0 && header.width != width) || (height > 0 && header.height != height)) {
    return Status(Code::kCorruptData,
                  "%s: the depth image is %dx%d, expected %dx%d (GDepth:ImageWidth/Height)", name,
                  header.width, header.height, width, height);
  }
  ImageReadMemory memory;
  memory.strip = out->strip;
  memory.strip_bytes = out->strip_bytes;
  memory.max_width = header.width;
  memory.max_height = header.height;
  DepthSink sink(name, header.is_jpeg, out, grow);
  const Status s = StreamImageMemory(data, size, name, 0, sink, memory,
                                     header.is_jpeg ? ImageFileType::kJpeg : ImageFileType::kPng);
  if (!s.ok()) out->width = out->height = out->bits = 0;
  return s;
}

}  // namespace

Status DecodeDepthImageInto(const uint8_t* data, size_t size, std::string_view mime,
                            const char* name, int32_t max_side, int32_t width, int32_t height,
                            DepthImageBuffer* out) {
  return Decode(data, size, mime, name, max_side, width, height, out, nullptr);
}

Status DecodeDepthImage(const uint8_t* data, size_t size, std::string_view mime, const char* name,
                        int32_t max_side, int32_t width, int32_t height, GrayPng* out) {
  *out = GrayPng();
  DepthImageHeader header;
  LB_RETURN_IF_ERROR(ProbeDepthImage(data, size, mime, name, &header));
  // The strip only once the header has passed the same checks the decode makes.
  if (header.width > max_side || header.height > max_side) {
    return Status(Code::kCorruptData, "%s: a %dx%d depth image, larger than %d a side", name,
                  header.width, header.height, max_side);
  }
  std::vector<uint8_t> strip(DepthStripBytes(header.width));
  DepthImageBuffer buffer;
  buffer.strip = strip.data();
  buffer.strip_bytes = strip.size();
  std::vector<uint16_t> values;
  LB_RETURN_IF_ERROR(Decode(data, size, mime, name, max_side, width, height, &buffer, &values));
  if (values.size() != static_cast<size_t>(buffer.width) * static_cast<size_t>(buffer.height)) {
    return Status(Code::kCorruptData, "%s: the depth image ends after %zu of %d rows", name,
                  values.size() / static_cast<size_t>(std::max(buffer.width, 1)), buffer.height);
  }
  out->width = buffer.width;
  out->height = buffer.height;
  out->bits = buffer.bits;
  out->values = std::move(values);
  return Status::Ok();
}

void ResampleDisparity(ConstImageU16 in, ImageU16 out) {
  if (in.empty() || out.empty()) return;
  // Pixel centres aligned: out x maps to (x + 0.5) * in.width / out.width - 0.5, in Q16.
  const int64_t sx = (int64_t{in.width} << 16) / out.width;
  const int64_t sy = (int64_t{in.height} << 16) / out.height;
  for (int32_t y = 0; y < out.height; ++y) {
    int64_t fy = ((2 * y + 1) * sy) / 2 - (1 << 15);
    fy = std::clamp<int64_t>(fy, 0, (int64_t{in.height - 1}) << 16);
    const int32_t y0 = static_cast<int32_t>(fy >> 16);
    const int32_t y1 = std::min(y0 + 1, in.height - 1);
    const int64_t wy = fy & 0xFFFF;
    const uint16_t* r0 = in.Row(y0);
    const uint16_t* r1 = in.Row(y1);
    uint16_t* o = out.Row(y);
    for (int32_t x = 0; x < out.width; ++x) {
      int64_t fx = ((2 * x + 1) * sx) / 2 - (1 << 15);
      fx = std::clamp<int64_t>(fx, 0, (int64_t{in.width - 1}) << 16);
      const int32_t x0 = static_cast<int32_t>(fx >> 16);
      const int32_t x1 = std::min(x0 + 1, in.width - 1);
      const int64_t wx = fx & 0xFFFF;
      const int64_t top = r0[x0] * (65536 - wx) + r0[x1] * wx;
      const int64_t bottom = r1[x0] * (65536 - wx) + r1[x1] * wx;
      const int64_t v = top * (65536 - wy) + bottom * wy;
      o[x] = static_cast<uint16_t>((v + (int64_t{1} << 31)) >> 32);
    }
  }
}

}  // namespace lb
