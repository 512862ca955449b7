// Binary netpbm: P5 (PGM) and P6 (PPM), maxval 1..65535, comments between header fields.
#include <cinttypes>
#include <cstring>

#include "firmware/codecs/decoder.h"

namespace lb::codecs {
namespace {

class PnmHeader {
 public:
  PnmHeader(ByteSource& src, const char* name) : src_(src), name_(name) {}

  // Reads one decimal header field, skipping the whitespace and comments before it.
  Status Field(const char* what, uint32_t* value) {
    int c = Next();
    bool separated = false;
    for (;;) {
      if (c == '#') {
        while (c != '\n' && c != '\r' && c >= 0) c = Next();
        separated = true;
      } else if (IsSpace(c)) {
        separated = true;
        c = Next();
      } else {
        break;
      }
    }
    if (c < 0) return Ended(what);
    if (!separated || c < '0' || c > '9') {
      return Status(Code::kCorruptData, "%s: bad PNM header: byte 0x%02x where the %s should be",
                    name_, c, what);
    }
    uint32_t v = 0;
    while (c >= '0' && c <= '9') {
      v = v * 10 + static_cast<uint32_t>(c - '0');
      if (v > 1000000) return Status(Code::kCorruptData, "%s: PNM %s is absurd", name_, what);
      c = Next();
    }
    if (c < 0) return Ended(what);
    pending_ = c;
    *value = v;
    return Status::Ok();
  }

  // The byte that ended the last field: one whitespace byte must separate maxval and the data.
  int pending() const { return pending_; }

 private:
  static bool IsSpace(int c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
  }
  int Next() {
    if (pending_ >= 0) {
      const int c = pending_;
      pending_ = -1;
      return c;
    }
    uint8_t b = 0;
    return src_.Read(&b, 1) == 1 ? b : -1;
  }
  Status Ended(const char* what) const {
    if (src_.error() != 0) {
      return Status(Code::kIoError, "%s: read error: %s", name_, strerror(src_.error()));
    }
    return Status(Code::kCorruptData, "%s: truncated PNM header (no %s)", name_, what);
  }

  ByteSource& src_;
  const char* name_;
  int pending_ = -1;
};

// Converts one row in place: big-endian 16-bit to native, and maxval to full scale.
Status ConvertRow(uint8_t* row, size_t samples, uint32_t maxval, const char* name, int32_t y) {
  if (maxval == 255) return Status::Ok();
  if (maxval < 256) {
    for (size_t i = 0; i < samples; ++i) {
      const uint32_t v = row[i];
      if (v > maxval) {
        return Status(Code::kCorruptData, "%s: sample %u exceeds maxval %u in row %d", name, v,
                      maxval, y);
      }
      row[i] = static_cast<uint8_t>((v * 255 + maxval / 2) / maxval);
    }
    return Status::Ok();
  }
  for (size_t i = 0; i < samples; ++i) {
    uint32_t v = (static_cast<uint32_t>(row[2 * i]) << 8) | row[2 * i + 1];
    if (v > maxval) {
      return Status(Code::kCorruptData, "%s: sample %u exceeds maxval %u in row %d", name, v,
                    maxval, y);
    }
    if (maxval != 65535) v = (v * 65535 + maxval / 2) / maxval;  // < 2^32: v <= maxval < 2^16
    const uint16_t native = static_cast<uint16_t>(v);
    memcpy(row + 2 * i, &native, 2);
  }
  return Status::Ok();
}

}  // namespace

Status DecodePnm(ByteSource& src, const DecodeRequest& request) {
  const char* name = request.name;
  uint8_t magic[2] = {};
  if (src.Read(magic, 2) != 2 || magic[0] != 'P') {
    return Status(Code::kCorruptData, "%s: not a PPM/PGM file (bad magic)", name);
  }
  int32_t channels = 0;
  if (magic[1] == '5') {
    channels = 1;
  } else if (magic[1] == '6') {
    channels = 3;
  } else if (magic[1] >= '1' && magic[1] <= '7') {
    return Status(Code::kUnsupported, "%s: netpbm P%c is not supported (only binary P5 and P6)",
                  name, magic[1]);
  } else {
    return Status(Code::kCorruptData, "%s: not a PPM/PGM file (bad magic)", name);
  }

  PnmHeader header(src, name);
  uint32_t width = 0, height = 0, maxval = 0;
  LB_RETURN_IF_ERROR(header.Field("width", &width));
  LB_RETURN_IF_ERROR(header.Field("height", &height));
  LB_RETURN_IF_ERROR(CheckImageSize(name, width, height));
  LB_RETURN_IF_ERROR(header.Field("maxval", &maxval));
  if (maxval < 1 || maxval > 65535) {
    return Status(Code::kCorruptData, "%s: PNM maxval %u is outside 1..65535", name, maxval);
  }
  const int c = header.pending();
  if (c != ' ' && c != '\t' && c != '\n' && c != '\r' && c != '\v' && c != '\f') {
    return Status(Code::kCorruptData, "%s: bad PNM header: byte 0x%02x after maxval", name, c);
  }

  const bool wide = maxval > 255;
  const PixelFormat format = channels == 1 ? (wide ? PixelFormat::kGray16 : PixelFormat::kGray8)
                                           : (wide ? PixelFormat::kRgb16 : PixelFormat::kRgb8);
  const int32_t height_rows = static_cast<int32_t>(height);
  if (!SetHeader(request, format, static_cast<int32_t>(width), height_rows)) return Status::Ok();

  const size_t samples = static_cast<size_t>(width) * static_cast<size_t>(channels);
  const size_t row_bytes = samples * (wide ? 2 : 1);
  const uint64_t total = static_cast<uint64_t>(row_bytes) * height;
  Buffer heap;
  uint8_t* strip = nullptr;
  LB_RETURN_IF_ERROR(
      RowBuffer(request, static_cast<uint64_t>(row_bytes) * kImageStripRows, &heap, &strip));

  LB_RETURN_IF_ERROR(BeginFrame(request));
  for (int32_t y0 = 0; y0 < height_rows; y0 += kImageStripRows) {
    const int32_t rows = StripRows(y0, height_rows);
    const size_t want = row_bytes * static_cast<size_t>(rows);
    const size_t got = src.Read(strip, want);
    if (got != want) {
      if (src.error() != 0) {
        return Status(Code::kIoError, "%s: read error: %s", name, strerror(src.error()));
      }
      return Status(Code::kCorruptData, "%s: truncated: %" PRIu64 " of %" PRIu64 " pixel bytes",
                    name, static_cast<uint64_t>(row_bytes) * static_cast<uint64_t>(y0) + got,
                    total);
    }
    for (int32_t y = 0; y < rows; ++y) {
      LB_RETURN_IF_ERROR(
          ConvertRow(strip + row_bytes * static_cast<size_t>(y), samples, maxval, name, y0 + y));
    }
    LB_RETURN_IF_ERROR(DeliverRows(request, strip, row_bytes, y0, rows));
  }
  return request.sink->EndFrame();
}

}  // namespace lb::codecs
