#include "algo/core/frame.h"

namespace lb {

const char* PixelFormatName(PixelFormat format) {
  switch (format) {
    case PixelFormat::kGray8:
      return "GRAY8";
    case PixelFormat::kRgb8:
      return "RGB8";
    case PixelFormat::kBgr8:
      return "BGR8";
    case PixelFormat::kGray16:
      return "GRAY16";
    case PixelFormat::kRgb16:
      return "RGB16";
    case PixelFormat::kYuyv:
      return "YUYV";
    case PixelFormat::kNv12:
      return "NV12";
    case PixelFormat::kI420:
      return "I420";
    case PixelFormat::kRgbx8:
      return "RGBX8";
    case PixelFormat::kBgrx8:
      return "BGRX8";
  }
  return "?";
}

int BytesPerPixel(PixelFormat format) {
  switch (format) {
    case PixelFormat::kGray8:
      return 1;
    case PixelFormat::kRgb8:
    case PixelFormat::kBgr8:
      return 3;
    case PixelFormat::kGray16:
      return 2;
    case PixelFormat::kRgb16:
      return 6;
    case PixelFormat::kYuyv:
      return 2;
    case PixelFormat::kNv12:
    case PixelFormat::kI420:
      return 1;
    case PixelFormat::kRgbx8:
    case PixelFormat::kBgrx8:
      return 4;
  }
  return 0;
}

int PlaneCount(PixelFormat format) {
  switch (format) {
    case PixelFormat::kNv12:
      return 2;
    case PixelFormat::kI420:
      return 3;
    case PixelFormat::kGray8:
    case PixelFormat::kRgb8:
    case PixelFormat::kBgr8:
    case PixelFormat::kGray16:
    case PixelFormat::kRgb16:
    case PixelFormat::kYuyv:
    case PixelFormat::kRgbx8:
    case PixelFormat::kBgrx8:
      return 1;
  }
  return 1;
}

}  // namespace lb
