// Strided image views: non-owning windows onto pixel memory owned by an arena, a sensor buffer or
// a decoder. Stride is in elements (not bytes) so a view of uint16_t samples cannot be misaligned.
#pragma once

#include <cstddef>
#include <cstdint>

namespace lb {

// Interleaved samples: `channels` samples per pixel, rows `stride` elements apart.
template <typename T>
struct ImageView {
  T* data = nullptr;
  int32_t width = 0;
  int32_t height = 0;
  int32_t channels = 1;
  ptrdiff_t stride = 0;

  T* Row(int32_t y) const { return data + static_cast<ptrdiff_t>(y) * stride; }
  T* At(int32_t x, int32_t y) const { return Row(y) + static_cast<ptrdiff_t>(x) * channels; }
  bool empty() const { return data == nullptr || width <= 0 || height <= 0; }

  ImageView<const T> AsConst() const { return {data, width, height, channels, stride}; }
  operator ImageView<const T>() const { return AsConst(); }  // NOLINT: views convert like pointers

  // A window of this view; the caller keeps it inside the bounds.
  ImageView Crop(int32_t x, int32_t y, int32_t w, int32_t h) const {
    return {At(x, y), w, h, channels, stride};
  }
};

using ImageU8 = ImageView<uint8_t>;
using ImageU16 = ImageView<uint16_t>;
using ImageS16 = ImageView<int16_t>;
using ConstImageU8 = ImageView<const uint8_t>;
using ConstImageU16 = ImageView<const uint16_t>;

// Planar image: up to three single-channel planes that may differ in size (YCbCr 4:2:0).
template <typename T>
struct PlanarView {
  static constexpr int kMaxPlanes = 3;
  ImageView<T> planes[kMaxPlanes];
  int32_t count = 0;

  PlanarView<const T> AsConst() const {
    PlanarView<const T> out;
    out.count = count;
    for (int i = 0; i < count; ++i) out.planes[i] = planes[i].AsConst();
    return out;
  }
};

using PlanarU8 = PlanarView<uint8_t>;
using ConstPlanarU8 = PlanarView<const uint8_t>;

// Wraps a tightly packed buffer.
template <typename T>
ImageView<T> MakeView(T* data, int32_t width, int32_t height, int32_t channels = 1) {
  return {data, width, height, channels, static_cast<ptrdiff_t>(width) * channels};
}

}  // namespace lb
