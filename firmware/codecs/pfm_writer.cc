#include "firmware/codecs/pfm_writer.h"

#include <cstdio>
#include <cstring>

namespace lb {

Status PfmWriter::Begin(AtomicFile* out, int32_t width, int32_t height) {
  if (width <= 0 || height <= 0) {
    return Status(Code::kInvalidArgument, "%s: cannot write a %dx%d PFM", out->path(), width,
                  height);
  }
  out_ = out;
  width_ = width;
  rows_left_ = height;
  row_.resize(static_cast<size_t>(width) * 4);
  char header[64];
  const int n = snprintf(header, sizeof(header), "Pf\n%d %d\n-1.0\n", width, height);
  return out_->Write(header, static_cast<size_t>(n));
}

Status PfmWriter::WriteRow(const float* values) {
  if (out_ == nullptr || rows_left_ <= 0) {
    return Status(Code::kInternal, "pfm writer: a row past the end of the map");
  }
  // Little-endian whatever the host: the byte order the header's negative scale promises.
  for (int32_t x = 0; x < width_; ++x) {
    uint32_t bits;
    memcpy(&bits, &values[x], 4);
    for (int b = 0; b < 4; ++b) row_[4 * x + b] = static_cast<uint8_t>(bits >> (8 * b));
  }
  --rows_left_;
  return out_->Write(row_.data(), row_.size());
}

}  // namespace lb
