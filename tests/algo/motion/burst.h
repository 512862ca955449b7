// Synthetic handheld bursts for the motion tests: the scene sensor's views rendered to RGB8 and
// the errors of an estimate against the scene's true poses. Host-side; allocates freely.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "algo/core/image.h"
#include "algo/motion/camera.h"
#include "sim/synthetic/scene.h"

namespace lb::motiontest {

struct Burst {
  Scene scene;
  std::vector<std::vector<uint8_t>> pixels;
  std::vector<ConstImageU8> views;
  CameraIntrinsics intrinsics;  // of the views
  int32_t width = 0, height = 0;
  // The scene renders at truth_scale times the views' size (scene.width() is that size): pass
  // truth_scale times the wanted scale to its ground-truth calls.
  int32_t truth_scale = 1;
};

// Renders `views` frames of a seeded handheld scene at width x height. With pixel_samples s > 1
// the scene is rendered at s times the size and each pixel is the mean of its s x s samples:
// the pixel integrates the light over its area, as a sensor's does (behind its lens and
// anti-aliasing filter), instead of point-sampling the hard-edged patterns at its centre, which
// moves the tracked corners by up to ~0.3 px (tests/algo/motion/accuracy_test.cc). False on
// failure.
inline bool MakeBurst(const SceneParams& params, int32_t width, int32_t height, int32_t views,
                      Burst* b, int32_t pixel_samples = 1) {
  const int32_t s = pixel_samples, sw = width * s, sh = height * s;
  if (s < 1 || !b->scene.Configure(params, sw, sh, views).ok()) return false;
  b->width = width;
  b->height = height;
  b->truth_scale = s;
  b->pixels.assign(views, std::vector<uint8_t>(static_cast<size_t>(width) * height * 3));
  b->views.clear();
  std::vector<uint8_t> rows(static_cast<size_t>(sw) * s * 3);
  std::vector<int32_t> sum(static_cast<size_t>(width) * 3);
  for (int32_t v = 0; v < views; ++v) {
    for (int32_t y = 0; y < height; ++y) {
      if (!b->scene.RenderRows(v, y * s, s, rows.data(), sw * 3).ok()) return false;
      std::fill(sum.begin(), sum.end(), 0);
      for (int32_t j = 0; j < s; ++j) {
        const uint8_t* r = rows.data() + static_cast<size_t>(j) * sw * 3;
        for (int32_t x = 0; x < sw; ++x) {
          for (int32_t c = 0; c < 3; ++c) sum[(x / s) * 3 + c] += r[x * 3 + c];
        }
      }
      uint8_t* out = b->pixels[v].data() + static_cast<size_t>(y) * width * 3;
      for (int32_t i = 0; i < width * 3; ++i) {
        out[i] = static_cast<uint8_t>((sum[i] + s * s / 2) / (s * s));
      }
    }
    b->views.push_back(MakeView(b->pixels[v].data(), width, height, 3).AsConst());
  }
  // Pixel (i, j) covers [s i, s i + s) of the render: the same continuous coordinates / s.
  const CameraIntrinsics& k = b->scene.intrinsics();
  b->intrinsics = {k.fx / s, k.fy / s, k.cx / s, k.cy / s};
  return true;
}

inline SceneParams Handheld(uint64_t seed) {
  SceneParams p;
  p.seed = seed;
  p.geometry = ViewGeometry::kHandheld;
  return p;
}

// Angle in degrees of R_est * R_true^T.
inline double RotationErrorDeg(const ViewMotion& est, const ViewMotion& truth) {
  double tr = 0;
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k) tr += est.rotation[i][k] * truth.rotation[i][k];
  }
  const double c = std::fmax(-1.0, std::fmin(1.0, 0.5 * (tr - 1)));
  return std::acos(c) * 180.0 / M_PI;
}

inline double AngleDeg(const double* a, const double* b) {
  const double dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const double na = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  const double nb = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
  return std::acos(std::fmax(-1.0, std::fmin(1.0, dot / (na * nb)))) * 180.0 / M_PI;
}

inline double TranslationErrorDeg(const ViewMotion& est, const ViewMotion& truth) {
  return AngleDeg(est.translation, truth.translation);
}

// 7x7 box blur of an RGB8 frame, twice: a frame shot while the hand shook.
inline void Blur(std::vector<uint8_t>* rgb, int32_t w, int32_t h) {
  std::vector<uint8_t> src;
  for (int pass = 0; pass < 2; ++pass) {
    src = *rgb;
    for (int32_t y = 0; y < h; ++y) {
      for (int32_t x = 0; x < w; ++x) {
        for (int c = 0; c < 3; ++c) {
          int32_t sum = 0, n = 0;
          for (int32_t dy = -3; dy <= 3; ++dy) {
            for (int32_t dx = -3; dx <= 3; ++dx) {
              const int32_t xx = x + dx, yy = y + dy;
              if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
              sum += src[(static_cast<size_t>(yy) * w + xx) * 3 + c];
              ++n;
            }
          }
          (*rgb)[(static_cast<size_t>(y) * w + x) * 3 + c] = static_cast<uint8_t>(sum / n);
        }
      }
    }
  }
}

}  // namespace lb::motiontest
