// Small rectified bursts for the depth tests, made with integer arithmetic only (the same bytes on
// every target): a textured background plane and a textured foreground rectangle, each at a whole
// disparity in px per view step, seen from `views` equally spaced cameras.
#pragma once

#include <cstdint>
#include <vector>

#include "algo/core/image.h"
#include "algo/depth/depth_config.h"

namespace lb::synth {

struct Burst {
  int32_t width = 0, height = 0, reference = 0;
  std::vector<std::vector<uint8_t>> pixels;  // RGB8 per view
  std::vector<ConstImageU8> views;
  std::vector<int32_t> truth;  // disparity of each reference pixel, px per view step
};

// Foreground rectangle [fx0, fx1) x [fy0, fy1) in reference coordinates.
inline Burst MakeBurst(int32_t w, int32_t h, int32_t views, int32_t reference, int32_t disp_back,
                       int32_t disp_front, int32_t fx0, int32_t fx1, int32_t fy0, int32_t fy1,
                       uint32_t seed) {
  Burst b;
  b.width = w;
  b.height = h;
  b.reference = reference;
  auto texture = [seed](int32_t x, int32_t y, int32_t layer, int32_t c) {
    // Hash of the scene coordinate: blocky 2x2 so colour varies but is locally coherent.
    uint32_t v =
        static_cast<uint32_t>(x >> 1) * 73856093u ^ static_cast<uint32_t>(y >> 1) * 19349663u ^
        static_cast<uint32_t>(layer) * 83492791u ^ static_cast<uint32_t>(c) * 2654435761u ^ seed;
    v ^= v >> 13;
    v *= 0x5bd1e995u;
    v ^= v >> 15;
    return static_cast<uint8_t>(40 + (v & 0x7f) + ((x + y) & 7) * 8);
  };
  for (int32_t k = 0; k < views; ++k) {
    const int32_t step = k - reference;
    std::vector<uint8_t> img(static_cast<size_t>(w) * h * 3);
    for (int32_t y = 0; y < h; ++y) {
      for (int32_t x = 0; x < w; ++x) {
        // The view `step` to the right sees reference point xr at xr - step * d.
        const int32_t xf = x + step * disp_front;
        const bool front = xf >= fx0 && xf < fx1 && y >= fy0 && y < fy1;
        const int32_t xs = front ? xf : x + step * disp_back;
        for (int32_t c = 0; c < 3; ++c) {
          img[(static_cast<size_t>(y) * w + x) * 3 + c] = texture(xs + 64, y, front ? 1 : 0, c);
        }
      }
    }
    b.pixels.push_back(std::move(img));
  }
  for (const auto& p : b.pixels) b.views.push_back(MakeView(p.data(), w, h, 3));
  for (int32_t y = 0; y < h; ++y) {
    for (int32_t x = 0; x < w; ++x) {
      const bool front = x >= fx0 && x < fx1 && y >= fy0 && y < fy1;
      b.truth.push_back(front ? disp_front : disp_back);
    }
  }
  return b;
}

// FNV-1a of a disparity map's bytes, low byte first: the checksum the depth tests pin.
inline uint32_t DisparityHash(const std::vector<uint16_t>& disp) {
  uint32_t hash = 2166136261u;
  for (uint16_t v : disp) {
    hash = (hash ^ (v & 0xff)) * 16777619u;
    hash = (hash ^ (v >> 8)) * 16777619u;
  }
  return hash;
}

// A depth configuration over the whole burst: labels 0..labels-1, step_q8 apart from 0.
inline DepthConfig SmallConfig(const Burst& b, int32_t labels, int32_t step_q8) {
  DepthConfig c;
  c.width = b.width;
  c.height = b.height;
  c.views = static_cast<int32_t>(b.views.size());
  c.reference = b.reference;
  c.labels = labels;
  c.disp_min_q8 = 0;
  c.disp_max_q8 = (labels - 1) * step_q8;
  return c;
}

}  // namespace lb::synth
