#include "hal/libcamera/buffer_layout.h"

namespace lb {

Status LayOutPlanes(PixelFormat format, int32_t width, int32_t height, ptrdiff_t stride,
                    const BufferPlane* planes, size_t n, PlaneLayout* layout) {
  *layout = PlaneLayout();
  if (n < 1 || n > 3) {
    return Status(Code::kUnsupported, "a %s buffer in %zu planes (1 to 3 are read)",
                  PixelFormatName(format), n);
  }
  const int32_t count = PlaneCount(format);
  const bool i420 = format == PixelFormat::kI420;
  const ptrdiff_t row = static_cast<ptrdiff_t>(width) * BytesPerPixel(format);
  if (width <= 0 || height <= 0 || stride < row || (i420 && stride % 2 != 0)) {
    return Status(Code::kCorruptData, "a %dx%d %s frame with rows %td bytes apart", width, height,
                  PixelFormatName(format), stride);
  }
  layout->count = count;
  size_t end = 0;  // where the last laid-out plane ends in its dmabuf
  for (int32_t k = 0; k < count; ++k) {
    const ptrdiff_t s = k == 0 ? stride : (i420 ? stride / 2 : stride);
    const int32_t rows = k == 0 ? height : (height + 1) / 2;
    const size_t bytes = static_cast<size_t>(s) * static_cast<size_t>(rows);
    // A plane the buffer lists starts where the buffer says; one it lacks follows the previous
    // plane in the previous plane's buffer plane.
    const size_t source = static_cast<size_t>(k) < n ? static_cast<size_t>(k) : n - 1;
    const size_t offset = static_cast<size_t>(k) < n ? planes[k].offset : end;
    const BufferPlane& p = planes[source];
    if (offset < p.offset || offset - p.offset + bytes > p.length) {
      return Status(Code::kCorruptData,
                    "a %dx%d %s frame's plane %d needs %zu bytes at offset %zu; buffer plane %zu "
                    "has %zu at %zu",
                    width, height, PixelFormatName(format), k, bytes, offset, source, p.length,
                    p.offset);
    }
    layout->source[k] = static_cast<int32_t>(source);
    layout->offset[k] = offset;
    layout->stride[k] = s;
    end = offset + bytes;
  }
  return Status::Ok();
}

size_t MappedExtent(const BufferPlane* planes, size_t n, size_t i) {
  size_t extent = 0;
  for (size_t j = 0; j < n; ++j) {
    if (planes[j].fd != planes[i].fd) continue;
    const size_t end = planes[j].offset + planes[j].length;
    if (end > extent) extent = end;
  }
  return extent;
}

}  // namespace lb
