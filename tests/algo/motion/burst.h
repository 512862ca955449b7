// Synthetic handheld bursts for the motion tests: the scene sensor's views rendered to RGB8 and
// the errors of an estimate against the scene's true poses. Host-side; allocates freely.
#pragma once

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
  CameraIntrinsics intrinsics;
};

// Renders `views` frames of a seeded handheld scene at width x height. False on failure.
inline bool MakeBurst(const SceneParams& params, int32_t width, int32_t height, int32_t views,
                      Burst* b) {
  if (!b->scene.Configure(params, width, height, views).ok()) return false;
  b->pixels.assign(views, std::vector<uint8_t>(static_cast<size_t>(width) * height * 3));
  b->views.clear();
  for (int32_t v = 0; v < views; ++v) {
    if (!b->scene.RenderRows(v, 0, height, b->pixels[v].data(), width * 3).ok()) return false;
    b->views.push_back(MakeView(b->pixels[v].data(), width, height, 3).AsConst());
  }
  const Intrinsics& k = b->scene.intrinsics();
  b->intrinsics = {k.fx, k.fy, k.cx, k.cy};
  return true;
}

inline SceneParams Handheld(uint64_t seed) {
  SceneParams p;
  p.seed = seed;
  p.motion = CameraMotion::kHandheld;
  return p;
}

// Angle in degrees of R_est * R_true^T.
inline double RotationErrorDeg(const ViewMotion& est, const Pose& truth) {
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

inline double TranslationErrorDeg(const ViewMotion& est, const Pose& truth) {
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
