#include "firmware/codecs/image_file.h"

#include <unistd.h>

#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>

#include "firmware/codecs/decoder.h"
#include "firmware/storage/input_file.h"

namespace lb {

namespace {

using codecs::ByteSource;

Status Detect(ByteSource& src, const char* name, ImageFileType* type) {
  static constexpr uint8_t kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  uint8_t magic[8] = {};
  const size_t n = src.Peek(magic, sizeof(magic));
  if (src.error() != 0) {
    return Status(Code::kIoError, "%s: read error: %s", name, strerror(src.error()));
  }
  if (n == 0) return Status(Code::kCorruptData, "%s: empty file", name);
  if (n >= 2 && magic[0] == 'P' && magic[1] >= '1' && magic[1] <= '7') {
    *type = ImageFileType::kPnm;
  } else if (n == 8 && memcmp(magic, kPng, 8) == 0) {
    *type = ImageFileType::kPng;
  } else if (n >= 3 && magic[0] == 0xff && magic[1] == 0xd8 && magic[2] == 0xff) {
    *type = ImageFileType::kJpeg;
  } else {
    return Status(Code::kUnsupported,
                  "%s: not a PPM, PGM, PNG or JPEG file (starts %02x %02x %02x %02x)", name,
                  magic[0], magic[1], magic[2], magic[3]);
  }
  return Status::Ok();
}

Status Decode(ByteSource& src, ImageFileType type, const codecs::DecodeRequest& request) {
  if (type == ImageFileType::kAuto) LB_RETURN_IF_ERROR(Detect(src, request.name, &type));
  switch (type) {
    case ImageFileType::kPnm:
      return codecs::DecodePnm(src, request);
    case ImageFileType::kPng:
      return codecs::DecodePng(src, request);
    case ImageFileType::kJpeg:
      return codecs::DecodeJpeg(src, request);
    case ImageFileType::kAuto:
      break;
  }
  return Status(Code::kInternal, "%s: no decoder", request.name);
}

// Gathers the strips of one frame into a packed buffer.
class CollectSink final : public FrameSink {
 public:
  CollectSink(const char* name, ImageFileInfo* info, std::vector<uint8_t>* pixels)
      : name_(name), info_(info), pixels_(pixels) {}

  Status BeginFrame(const FrameInfo& info) override {
    info_->format = info.format;
    info_->width = info.width;
    info_->height = info.height;
    row_bytes_ = static_cast<size_t>(info.width) * static_cast<size_t>(BytesPerPixel(info.format));
    next_row_ = 0;
    pixels_->clear();
    return Status::Ok();
  }
  Status Rows(const FrameRows& rows) override {
    if (rows.y0 != next_row_ || rows.height <= 0 || rows.y0 + rows.height > info_->height) {
      return Status(Code::kInternal, "%s: decoder delivered rows %d..%d out of order", name_,
                    rows.y0, rows.y0 + rows.height);
    }
    for (int32_t y = 0; y < rows.height; ++y) {
      const uint8_t* row = rows.planes[0] + y * rows.strides[0];
      pixels_->insert(pixels_->end(), row, row + row_bytes_);
    }
    next_row_ += rows.height;
    return Status::Ok();
  }
  Status EndFrame() override {
    if (next_row_ != info_->height) {
      return Status(Code::kInternal, "%s: decoder ended the frame after %d of %d rows", name_,
                    next_row_, info_->height);
    }
    return Status::Ok();
  }

 private:
  const char* name_;
  ImageFileInfo* info_;
  std::vector<uint8_t>* pixels_;
  size_t row_bytes_ = 0;
  int32_t next_row_ = 0;
};

struct FileCloser {
  void operator()(FILE* f) const { fclose(f); }
};
using FilePtr = std::unique_ptr<FILE, FileCloser>;

Status OpenFile(const char* path, FilePtr* out) {
  int fd = -1;
  LB_RETURN_IF_ERROR(OpenInputFile(path, &fd));
  FILE* f = fdopen(fd, "rb");
  if (f == nullptr) {
    const int err = errno;
    close(fd);
    return Status(Code::kIoError, "%s: cannot open: %s", path, strerror(err));
  }
  out->reset(f);
  return Status::Ok();
}

Status DecodeFile(const char* path, const codecs::DecodeRequest& request) {
  FilePtr file;
  LB_RETURN_IF_ERROR(OpenFile(path, &file));
  codecs::FileSource src(file.get());
  return Decode(src, ImageFileType::kAuto, request);
}

}  // namespace

Status ProbeImageFile(const char* path, ImageFileInfo* info) {
  codecs::DecodeRequest request;
  request.name = path;
  request.info = info;
  return DecodeFile(path, request);
}

Status StreamImageFile(const char* path, int32_t index, FrameSink& sink) {
  ImageFileInfo info;
  return DecodeFile(path, codecs::StreamRequest(path, &info, &sink, index));
}

Status StreamImageDescriptor(int fd, const char* name, int32_t min_width, FrameSink& sink) {
  const int own = dup(fd);
  FilePtr file(own >= 0 ? fdopen(own, "rb") : nullptr);
  if (file == nullptr) {
    const int err = errno;
    if (own >= 0) close(own);
    return Status(Code::kIoError, "%s: cannot read: %s", name, strerror(err));
  }
  ImageFileInfo info;
  codecs::DecodeRequest request = codecs::StreamRequest(name, &info, &sink);
  request.min_width = min_width;
  codecs::FileSource src(file.get());
  return Decode(src, ImageFileType::kAuto, request);
}

Status ReadImageFile(const char* path, ImageFileInfo* info, std::vector<uint8_t>* pixels) {
  CollectSink collect(path, info, pixels);
  Status s = StreamImageFile(path, 0, collect);
  if (!s.ok()) pixels->clear();
  return s;
}

Status ReadImageMemory(const uint8_t* data, size_t size, const char* name, ImageFileInfo* info,
                       std::vector<uint8_t>* pixels, ImageFileType type) {
  CollectSink collect(name, info, pixels);
  codecs::MemorySource src(data, size);
  Status s = Decode(src, type, codecs::StreamRequest(name, info, &collect));
  if (!s.ok()) pixels->clear();
  return s;
}

Status StreamImageMemory(const uint8_t* data, size_t size, const char* name, int32_t index,
                         FrameSink& sink, const ImageReadMemory& memory, ImageFileType type) {
  codecs::MemorySource src(data, size);
  ImageFileInfo info;
  codecs::DecodeRequest request = codecs::StreamRequest(name, &info, &sink, index);
  request.memory = &memory;
  return Decode(src, type, request);
}

Status ProbeImageMemory(const uint8_t* data, size_t size, const char* name, ImageFileInfo* info,
                        ImageFileType type) {
  codecs::MemorySource src(data, size);
  codecs::DecodeRequest request;
  request.name = name;
  request.info = info;
  return Decode(src, type, request);
}

}  // namespace lb
