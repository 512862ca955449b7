#include "hal/libcamera/libcamera_format.h"

#include <libcamera/formats.h>

namespace lb {

bool LibcameraToPixelFormat(const libcamera::PixelFormat& format, PixelFormat* out) {
  namespace f = libcamera::formats;
  if (format == f::YUYV) {
    *out = PixelFormat::kYuyv;
  } else if (format == f::NV12) {
    *out = PixelFormat::kNv12;
  } else if (format == f::BGR888) {
    *out = PixelFormat::kRgb8;
  } else if (format == f::RGB888) {
    *out = PixelFormat::kBgr8;
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
  for (const libcamera::PixelFormat& wanted : {f::YUYV, f::NV12, f::BGR888, f::RGB888}) {
    for (const libcamera::PixelFormat& format : offered) {
      if (format == wanted) return format;
    }
  }
  return libcamera::PixelFormat();
}

}  // namespace lb
