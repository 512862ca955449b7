// Internal to firmware/codecs: the byte sources the readers read from (a file or bytes in memory)
// and the one entry point of each format's reader.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>

#include "algo/core/frame.h"
#include "algo/core/status.h"
#include "firmware/codecs/image_file.h"

namespace lb::codecs {

// Sequential bytes with a little look-ahead, so the format can be detected without consuming
// the signature the decoder then checks again.
class ByteSource {
 public:
  virtual ~ByteSource() = default;
  // Reads up to `n` bytes; fewer only at the end of the data or on a read error (see error()).
  size_t Read(void* dst, size_t n);
  // Copies the next `n` (<= kMaxPeek) bytes without consuming them; returns how many there were.
  size_t Peek(uint8_t* dst, size_t n);
  // 0, or the errno of a failed read.
  int error() const { return error_; }
  // Bytes consumed so far (for "ends after N bytes" messages).
  uint64_t consumed() const { return consumed_; }

  static constexpr size_t kMaxPeek = 16;

 protected:
  virtual size_t ReadRaw(uint8_t* dst, size_t n) = 0;
  int error_ = 0;

 private:
  uint8_t ahead_[kMaxPeek] = {};
  size_t ahead_begin_ = 0;
  size_t ahead_end_ = 0;
  uint64_t consumed_ = 0;
};

class MemorySource final : public ByteSource {
 public:
  MemorySource(const uint8_t* data, size_t size) : data_(data), size_(size) {}

 private:
  size_t ReadRaw(uint8_t* dst, size_t n) override;
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
};

// Borrows an open FILE (the caller closes it).
class FileSource final : public ByteSource {
 public:
  explicit FileSource(FILE* file) : file_(file) {}

 private:
  size_t ReadRaw(uint8_t* dst, size_t n) override;
  FILE* file_;
};

// A heap buffer without exceptions: Allocate fails by returning false.
class Buffer {
 public:
  Buffer() = default;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  ~Buffer();
  bool Allocate(uint64_t bytes);
  uint8_t* data() const { return data_; }

 private:
  uint8_t* data_ = nullptr;
};

// What a decoder is asked to do: with `sink` null it reads only the header into `info`;
// otherwise it also streams the pixels into `sink` as frame `index`, ending with EndFrame.
struct DecodeRequest {
  const char* name = "";
  ImageFileInfo* info = nullptr;
  FrameSink* sink = nullptr;
  int32_t index = 0;
  // Narrower than any image file (the depth image of a refocusable JPEG), checked on the header
  // before anything is allocated: a side limit, and when non-zero the only size accepted.
  int32_t max_side = kMaxImageSide;
  int32_t width = 0;
  int32_t height = 0;
  bool plain_gray = false;  // PNG only: grey without alpha, not interlaced
  // JPEG only, when non-zero: decoded at libjpeg's smallest scale M/8 (M = 1..8) that is still at
  // least this wide (or whole), the header recorded at that size.
  int32_t min_width = 0;
  // The caller's memory (StreamImageMemory): no heap buffer, and a size limit. Null: allocate.
  const ImageReadMemory* memory = nullptr;
};

// A request to stream the pixels into `sink` as frame `index`, the header recorded in `info`.
inline DecodeRequest StreamRequest(const char* name, ImageFileInfo* info, FrameSink* sink,
                                   int32_t index = 0) {
  DecodeRequest request;
  request.name = name;
  request.info = info;
  request.sink = sink;
  request.index = index;
  return request;
}

Status DecodePnm(ByteSource& src, const DecodeRequest& request);
Status DecodePng(ByteSource& src, const DecodeRequest& request);
Status DecodeJpeg(ByteSource& src, const DecodeRequest& request);

// Records the header in request.info; true when the pixels are wanted too (a sink is given).
bool SetHeader(const DecodeRequest& request, PixelFormat format, int32_t width, int32_t height);
// Starts frame request.index in the sink with the header SetHeader recorded.
Status BeginFrame(const DecodeRequest& request);
// Hands rows y0 .. y0 + count - 1, `row_bytes` apart from `rows`, to the sink.
Status DeliverRows(const DecodeRequest& request, const uint8_t* rows, size_t row_bytes, int32_t y0,
                   int32_t count);
// How many rows the strip starting at row y0 of a `height`-row image has.
inline int32_t StripRows(int32_t y0, int32_t height) {
  return height - y0 < kImageStripRows ? height - y0 : kImageStripRows;
}

// The buffer of `bytes` a reader decodes rows into: the caller's strip when it gave one (after
// checking the header's size against its limits), else `heap`. kOutOfMemory when neither fits.
Status RowBuffer(const DecodeRequest& request, uint64_t bytes, Buffer* heap, uint8_t** rows);

// Checks the header's size against `max_side` (kMaxImageSide for a file).
Status CheckImageSize(const char* name, int64_t width, int64_t height,
                      int32_t max_side = kMaxImageSide);

// True on a little-endian host (the readers deliver native-endian 16-bit samples).
inline bool HostIsLittleEndian() {
  const uint16_t probe = 1;
  uint8_t first = 0;
  __builtin_memcpy(&first, &probe, 1);
  return first == 1;
}

}  // namespace lb::codecs
