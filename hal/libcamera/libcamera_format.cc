#include "hal/libcamera/libcamera_format.h"

#include <libcamera/formats.h>

namespace lb {

bool LibcameraToPixelFormat(const libcamera::PixelFormat& format, PixelFormat* out) {
  namespace f = libcamera::formats;
  if (format == f::YUYV) {
    *out = PixelFormat::kYuyv;
  } else if (format == f::NV12) {
    *out = PixelFormat::kNv12;
  } else if (format == f::YUV420) {
    *out = PixelFormat::kI420;
  } else if (format == f::BGR888) {
    *out = PixelFormat::kRgb8;
  } else if (format == f::RGB888) {
    *out = PixelFormat::kBgr8;
  } else if (format == f::XBGR8888) {
    *out = PixelFormat::kRgbx8;
  } else if (format == f::XRGB8888) {
    *out = PixelFormat::kBgrx8;
  } else {
    return false;
  }
  return true;
}

libcamera::PixelFormat ChooseLibcameraFormat(const libcamera::PixelFormat& current,
                                             const std::vector<libcamera::PixelFormat>& offered) {
  PixelFormat unused;
  if (current.isValid() && LibcameraToPixelFormat(current, &unused)) return current;
  namespace f = libcamera::formats;
  for (const libcamera::PixelFormat& wanted :
       {f::YUYV, f::NV12, f::YUV420, f::BGR888, f::RGB888, f::XBGR8888, f::XRGB8888}) {
    for (const libcamera::PixelFormat& format : offered) {
      if (format == wanted) return format;
    }
  }
  return libcamera::PixelFormat();
}

YuvRange LibcameraYuvRange(const std::optional<libcamera::ColorSpace>& color_space) {
  if (color_space && color_space->range == libcamera::ColorSpace::Range::Full) {
    return YuvRange::kFull;
  }
  return YuvRange::kLimited;
}

}  // namespace lb
