// Where a frame's planes lie in a libcamera FrameBuffer. A buffer holds 1 to 3 planes, and
// several may share one dmabuf at different offsets; a format with more planes than the buffer
// (a one-plane NV12 or I420 buffer) has the rest packed after the last, as V4L2's single-planar
// formats lay them out. Chroma strides follow V4L2: NV12's UV rows are as long as the luma's,
// I420's U and V rows half as long. Plain data, no libcamera types, so it is tested without a
// camera.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/frame.h"
#include "algo/core/status.h"

namespace lb {

// One FrameBuffer::Plane.
struct BufferPlane {
  int fd = -1;
  size_t offset = 0;  // bytes from the start of the dmabuf
  size_t length = 0;
};

struct PlaneLayout {
  int32_t count = 0;              // the format's planes (PlaneCount)
  int32_t source[3] = {0, 0, 0};  // the buffer plane whose dmabuf holds each
  size_t offset[3] = {0, 0, 0};   // bytes from the start of that dmabuf
  ptrdiff_t stride[3] = {0, 0, 0};
};

// Lays out a width x height frame whose first plane's rows are `stride` bytes apart over the
// buffer's `n` planes: kUnsupported for 0 or more than 3 planes, kCorruptData when a plane is too
// short for the rows the format puts there.
Status LayOutPlanes(PixelFormat format, int32_t width, int32_t height, ptrdiff_t stride,
                    const BufferPlane* planes, size_t n, PlaneLayout* layout);

// How many bytes of its dmabuf plane `i`'s mapping must cover: the furthest end of any buffer
// plane on the same dmabuf. Mapping each dmabuf once over that extent reaches every plane on it.
size_t MappedExtent(const BufferPlane* planes, size_t n, size_t i);

}  // namespace lb
