#include "hal/v4l2/v4l2_format.h"

#include <cstdio>

namespace lb {

FourccText FourccName(uint32_t fourcc) {
  FourccText name;
  for (int i = 0; i < 4; ++i) {
    char c = static_cast<char>((fourcc >> (8 * i)) & 0xff);
    name.text[i] = (c >= 0x20 && c < 0x7f) ? c : '?';
  }
  name.text[4] = '\0';
  return name;
}

bool IsJpegFourcc(uint32_t fourcc) {
  return fourcc == V4L2_PIX_FMT_MJPEG || fourcc == V4L2_PIX_FMT_JPEG;
}

bool FourccToPixelFormat(uint32_t fourcc, PixelFormat* format) {
  switch (fourcc) {
    case V4L2_PIX_FMT_YUYV:
      *format = PixelFormat::kYuyv;
      return true;
    case V4L2_PIX_FMT_NV12:
      *format = PixelFormat::kNv12;
      return true;
    case V4L2_PIX_FMT_RGB24:
      *format = PixelFormat::kRgb8;
      return true;
    case V4L2_PIX_FMT_BGR24:
      *format = PixelFormat::kBgr8;
      return true;
    case V4L2_PIX_FMT_MJPEG:
    case V4L2_PIX_FMT_JPEG:
      *format = PixelFormat::kRgb8;
      return true;
    default:
      return false;
  }
}

Status ChooseFourcc(const char* device, const uint32_t* listed, const bool* at_size, size_t count,
                    uint32_t wanted, uint32_t* chosen) {
  // Whether `fourcc` is listed, and if `sized`, offered at the wanted size too.
  auto offered = [&](uint32_t fourcc, bool sized) {
    for (size_t i = 0; i < count; ++i) {
      if (listed[i] == fourcc && (!sized || at_size == nullptr || at_size[i])) return true;
    }
    return false;
  };
  PixelFormat unused;
  if (wanted != 0) {
    if (!FourccToPixelFormat(wanted, &unused)) {
      return Status(Code::kUnsupported, "%s: format %s is not one the pipeline reads", device,
                    FourccName(wanted).text);
    }
    if (!offered(wanted, false)) {
      return Status(Code::kUnsupported, "%s: the device does not offer format %s", device,
                    FourccName(wanted).text);
    }
    *chosen = wanted;
    return Status::Ok();
  }
  for (int pass = 0; pass < 2; ++pass) {
    const bool sized = pass == 0;
    for (uint32_t fourcc : kV4l2Preferred) {
      if (offered(fourcc, sized)) {
        *chosen = fourcc;
        return Status::Ok();
      }
    }
    for (uint32_t fourcc : kV4l2Compressed) {
      if (offered(fourcc, sized)) {
        *chosen = fourcc;
        return Status::Ok();
      }
    }
  }
  char offers[96] = "nothing";
  size_t used = 0;
  for (size_t i = 0; i < count && used + 6 < sizeof(offers); ++i) {
    used += static_cast<size_t>(snprintf(offers + used, sizeof(offers) - used, "%s%s", i ? " " : "",
                                         FourccName(listed[i]).text));
  }
  return Status(Code::kUnsupported,
                "%s: offers %s; the pipeline reads YUYV, NV12, RGB3 (RGB24), BGR3 (BGR24), MJPG "
                "or JPEG",
                device, offers);
}

Status LayoutFromFormat(const char* device, const v4l2_pix_format& pix, uint32_t requested,
                        V4l2Layout* layout) {
  if (pix.pixelformat != requested) {
    return Status(Code::kUnsupported, "%s: asked for %s, the driver chose %s", device,
                  FourccName(requested).text, FourccName(pix.pixelformat).text);
  }
  PixelFormat format;
  if (!FourccToPixelFormat(pix.pixelformat, &format)) {
    return Status(Code::kUnsupported, "%s: format %s is not one the pipeline reads", device,
                  FourccName(pix.pixelformat).text);
  }
  if (pix.field != V4L2_FIELD_NONE && pix.field != V4L2_FIELD_ANY) {
    return Status(Code::kUnsupported, "%s: interlaced field order %u, progressive needed", device,
                  pix.field);
  }
  if (pix.width == 0 || pix.height == 0 || pix.width > kMaxFrameSide ||
      pix.height > kMaxFrameSide) {
    return Status(Code::kUnsupported, "%s: frame size %ux%u outside 1x1..%dx%d", device, pix.width,
                  pix.height, kMaxFrameSide, kMaxFrameSide);
  }
  if (IsJpegFourcc(pix.pixelformat)) {
    // Rows come from the decoder, not from the buffer; bytesused says how long each frame is.
    layout->format = format;
    layout->width = static_cast<int32_t>(pix.width);
    layout->height = static_cast<int32_t>(pix.height);
    layout->stride = 0;
    layout->uv_offset = 0;
    layout->min_bytes = kMinJpegBytes;
    layout->compressed = true;
    return Status::Ok();
  }
  if (format == PixelFormat::kYuyv && pix.width % 2 != 0) {
    return Status(Code::kUnsupported, "%s: YUYV with odd width %u", device, pix.width);
  }
  if (format == PixelFormat::kNv12 && (pix.width % 2 != 0 || pix.height % 2 != 0)) {
    return Status(Code::kUnsupported, "%s: NV12 with odd size %ux%u", device, pix.width,
                  pix.height);
  }
  // Sizes are at most 8192 and bytesperline is checked below, so these products fit in 32 bits.
  uint32_t row_bytes = pix.width * static_cast<uint32_t>(BytesPerPixel(format));
  uint32_t stride = pix.bytesperline == 0 ? row_bytes : pix.bytesperline;
  if (stride < row_bytes || stride > 4 * row_bytes) {
    return Status(Code::kCorruptData, "%s: %u bytes per line for %u %s pixels", device, stride,
                  pix.width, FourccName(pix.pixelformat).text);
  }
  size_t plane0 = static_cast<size_t>(stride) * pix.height;
  size_t need = format == PixelFormat::kNv12 ? plane0 + plane0 / 2 : plane0;
  if (pix.sizeimage != 0 && pix.sizeimage < need) {
    return Status(Code::kCorruptData, "%s: image size %u bytes, a %ux%u %s frame needs %zu", device,
                  pix.sizeimage, pix.width, pix.height, FourccName(pix.pixelformat).text, need);
  }
  layout->format = format;
  layout->width = static_cast<int32_t>(pix.width);
  layout->height = static_cast<int32_t>(pix.height);
  layout->stride = static_cast<ptrdiff_t>(stride);
  layout->uv_offset = format == PixelFormat::kNv12 ? plane0 : 0;
  layout->min_bytes = need;
  layout->compressed = false;
  return Status::Ok();
}

}  // namespace lb
