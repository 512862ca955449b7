#include "firmware/codecs/decoder.h"

#include <cerrno>
#include <cinttypes>
#include <cstdlib>
#include <cstring>

namespace lb::codecs {

size_t ByteSource::Read(void* dst, size_t n) {
  uint8_t* out = static_cast<uint8_t*>(dst);
  size_t got = 0;
  while (got < n && ahead_begin_ < ahead_end_) out[got++] = ahead_[ahead_begin_++];
  if (got < n) got += ReadRaw(out + got, n - got);
  consumed_ += got;
  return got;
}

size_t ByteSource::Peek(uint8_t* dst, size_t n) {
  if (n > kMaxPeek) n = kMaxPeek;
  if (ahead_end_ - ahead_begin_ < n) {
    memmove(ahead_, ahead_ + ahead_begin_, ahead_end_ - ahead_begin_);
    ahead_end_ -= ahead_begin_;
    ahead_begin_ = 0;
    ahead_end_ += ReadRaw(ahead_ + ahead_end_, n - ahead_end_);
  }
  const size_t have = ahead_end_ - ahead_begin_ < n ? ahead_end_ - ahead_begin_ : n;
  memcpy(dst, ahead_ + ahead_begin_, have);
  return have;
}

size_t MemorySource::ReadRaw(uint8_t* dst, size_t n) {
  const size_t left = size_ - pos_;
  if (n > left) n = left;
  if (n > 0) memcpy(dst, data_ + pos_, n);
  pos_ += n;
  return n;
}

size_t FileSource::ReadRaw(uint8_t* dst, size_t n) {
  const size_t got = fread(dst, 1, n, file_);
  if (got < n && ferror(file_) && error_ == 0) error_ = errno != 0 ? errno : EIO;
  return got;
}

Buffer::~Buffer() { free(data_); }

bool Buffer::Allocate(uint64_t bytes) {
  free(data_);
  data_ = nullptr;
  if (bytes == 0 || bytes > SIZE_MAX / 2) return false;
  data_ = static_cast<uint8_t*>(malloc(static_cast<size_t>(bytes)));
  return data_ != nullptr;
}

bool SetHeader(const DecodeRequest& request, PixelFormat format, int32_t width, int32_t height) {
  request.info->format = format;
  request.info->width = width;
  request.info->height = height;
  return request.sink != nullptr;
}

Status BeginFrame(const DecodeRequest& request) {
  FrameInfo frame;
  frame.index = request.index;
  frame.format = request.info->format;
  frame.width = request.info->width;
  frame.height = request.info->height;
  return request.sink->BeginFrame(frame);
}

Status DeliverRows(const DecodeRequest& request, const uint8_t* rows, size_t row_bytes, int32_t y0,
                   int32_t count) {
  FrameRows strip;
  strip.y0 = y0;
  strip.height = count;
  strip.planes[0] = rows;
  strip.strides[0] = static_cast<ptrdiff_t>(row_bytes);
  return request.sink->Rows(strip);
}

Status RowBuffer(const DecodeRequest& request, uint64_t bytes, Buffer* heap, uint8_t** rows) {
  const ImageFileInfo& info = *request.info;
  const ImageReadMemory* memory = request.memory;
  if (memory == nullptr) {
    if (!heap->Allocate(bytes)) {
      return Status(Code::kOutOfMemory, "%s: no memory for %" PRIu64 " bytes of %dx%d rows",
                    request.name, bytes, info.width, info.height);
    }
    *rows = heap->data();
    return Status::Ok();
  }
  if (info.width > memory->max_width || info.height > memory->max_height) {
    return Status(Code::kOutOfMemory, "%s: a %dx%d image, larger than the %dx%d this reader takes",
                  request.name, info.width, info.height, memory->max_width, memory->max_height);
  }
  if (bytes > memory->strip_bytes) {
    return Status(Code::kOutOfMemory, "%s: %" PRIu64 " bytes of rows, more than the %zu given",
                  request.name, bytes, memory->strip_bytes);
  }
  *rows = memory->strip;
  return Status::Ok();
}

Status CheckImageSize(const char* name, int64_t width, int64_t height, int32_t max_side) {
  if (width <= 0 || height <= 0) {
    return Status(Code::kCorruptData, "%s: bad image size %" PRId64 "x%" PRId64, name, width,
                  height);
  }
  if (width > max_side || height > max_side) {
    return Status(Code::kUnsupported, "%s: %" PRId64 "x%" PRId64 " is larger than %dx%d", name,
                  width, height, max_side, max_side);
  }
  return Status::Ok();
}

}  // namespace lb::codecs
