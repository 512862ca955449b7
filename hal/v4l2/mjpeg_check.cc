#include "hal/v4l2/mjpeg_check.h"

#include <cstring>

#include "hal/v4l2/v4l2_format.h"

namespace lb {
namespace {

constexpr uint8_t kSoi = 0xD8, kEoi = 0xD9, kSos = 0xDA;

bool IsRestartOrTem(uint8_t code) { return code == 0x01 || (code >= 0xD0 && code <= 0xD7); }

// SOF0..SOF15 less the three codes in that range that are no frame headers (DHT, JPG, DAC).
bool IsFrameHeader(uint8_t code) {
  return code >= 0xC0 && code <= 0xCF && code != 0xC4 && code != 0xC8 && code != 0xCC;
}

const char* FrameKind(uint8_t code) {
  switch (code) {
    case 0xC2:
    case 0xC6:
    case 0xCA:
    case 0xCE:
      return "progressive";
    case 0xC3:
    case 0xC7:
    case 0xCB:
    case 0xCF:
      return "lossless";
    default:
      return "arithmetic-coded or hierarchical";
  }
}

Status Truncated(const char* where, size_t size) {
  return Status(Code::kCorruptData, "truncated: the data ends %s after %zu bytes", where, size);
}

// Moves past a marker's 0xFF and any fill bytes (0xFF) before its code; false at the end.
bool SkipFill(const uint8_t* data, size_t size, size_t* pos) {
  while (*pos < size && data[*pos] == 0xFF) ++*pos;
  return *pos < size;
}

}  // namespace

Status CheckMjpegFrame(const uint8_t* data, size_t size, int32_t width, int32_t height) {
  if (data == nullptr || size < kMinJpegBytes) {
    return Status(Code::kCorruptData, "empty frame (%zu bytes)", size);
  }
  if (data[0] != 0xFF || data[1] != kSoi) {
    return Status(Code::kCorruptData, "no JPEG start marker (the frame begins %02x %02x)", data[0],
                  data[1]);
  }
  size_t pos = 2;
  int components = 0;
  // The header segments, up to and including the scan header.
  for (;;) {
    if (pos >= size) return Truncated("before its scan", size);
    if (data[pos] != 0xFF) {
      return Status(Code::kCorruptData, "byte 0x%02x at %zu where a marker belongs", data[pos],
                    pos);
    }
    const size_t at = pos;
    if (!SkipFill(data, size, &pos)) return Truncated("before its scan", size);
    const uint8_t code = data[pos++];
    if (IsRestartOrTem(code)) continue;  // no length follows
    if (code == kSoi || code == kEoi || code == 0x00) {
      return Status(Code::kCorruptData, "marker 0xff%02x before the scan at byte %zu", code, at);
    }
    if (pos + 2 > size) return Truncated("in a marker's length", size);
    const size_t length = (size_t{data[pos]} << 8) | data[pos + 1];
    if (length < 2 || length > size - pos) {
      return Status(Code::kCorruptData,
                    "truncated: the 0xff%02x segment at byte %zu claims %zu bytes, %zu are left",
                    code, at, length, size - pos);
    }
    const uint8_t* seg = data + pos + 2;
    const size_t seg_bytes = length - 2;
    pos += length;
    if (IsFrameHeader(code)) {
      if (code != 0xC0 && code != 0xC1) {
        return Status(Code::kUnsupported, "%s JPEG (SOF%d); MJPEG frames must be baseline",
                      FrameKind(code), code - 0xC0);
      }
      if (seg_bytes < 6) return Status(Code::kCorruptData, "frame header of %zu bytes", seg_bytes);
      const int precision = seg[0];
      const int h = (seg[1] << 8) | seg[2];
      const int w = (seg[3] << 8) | seg[4];
      const int n = seg[5];
      if (w != width || h != height) {
        return Status(Code::kCorruptData, "the frame header says %dx%d, the mode is %dx%d", w, h,
                      width, height);
      }
      if (precision != 8) return Status(Code::kUnsupported, "%d-bit samples, 8 needed", precision);
      if (n != 1 && n != 3) return Status(Code::kUnsupported, "%d colour components", n);
      if (seg_bytes < 6 + 3 * static_cast<size_t>(n)) {
        return Status(Code::kCorruptData, "frame header of %zu bytes for %d components", seg_bytes,
                      n);
      }
      components = n;
    } else if (code == kSos) {
      if (components == 0) {
        return Status(Code::kCorruptData, "a scan at byte %zu before any frame header", at);
      }
      if (seg_bytes < 1 || seg[0] != components) {
        return Status(Code::kUnsupported,
                      "a first scan over %d of %d components: a multi-scan JPEG needs a "
                      "whole-frame buffer",
                      seg_bytes < 1 ? 0 : seg[0], components);
      }
      break;
    }
  }
  // The entropy-coded data: 0xFF only before a stuffed zero, a restart marker or, after fill
  // bytes, the end marker. Any other marker means lost or foreign bytes.
  for (;;) {
    const void* ff = memchr(data + pos, 0xFF, size - pos);
    if (ff == nullptr) return Truncated("inside the scan, with no end marker,", size);
    const size_t at = static_cast<size_t>(static_cast<const uint8_t*>(ff) - data);
    pos = at;
    if (!SkipFill(data, size, &pos)) return Truncated("inside the scan, with no end marker,", size);
    const uint8_t code = data[pos++];
    if (code == 0x00 || (code >= 0xD0 && code <= 0xD7)) continue;
    if (code == kEoi) return Status::Ok();
    return Status(Code::kCorruptData, "marker 0xff%02x inside the scan at byte %zu", code, at);
  }
}

}  // namespace lb
