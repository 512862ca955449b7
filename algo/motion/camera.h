// Camera model shared by the motion stage and its users: a pinhole with square-ish pixels, each
// view's pose relative to the reference, and how the views of a burst relate.
//
// Coordinates: continuous pixel coordinates put pixel (i, j) on [i, i+1) x [j, j+1), so its
// centre is (i + 0.5, j + 0.5); cx, cy are in those coordinates (the image centre is (w/2, h/2)).
// A reference-camera point X (x right, y down, z forward) is X_v = rotation * X + translation in
// view v's camera (row-major rotation).
#pragma once

#include <cstdint>

namespace lb {

struct CameraIntrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0;
};

// Without EXIF or a sensor description: fx = fy = 0.8 * width (a ~64 degree horizontal field of
// view, a typical compact camera at its wide end), principal point at the centre.
inline CameraIntrinsics DefaultIntrinsics(int32_t width, int32_t height) {
  const double f = 0.8 * width;
  return {f, f, 0.5 * width, 0.5 * height};
}

// A 35 mm equivalent focal length (mm) as px of a width x height image, and back: the equivalent
// is defined on the 43.27 mm diagonal of a 36 x 24 mm frame, so any aspect ratio works.
inline double FocalPxFrom35mm(double focal_35mm, int32_t width, int32_t height) {
  return focal_35mm * __builtin_sqrt(double{1} * width * width + double{1} * height * height) /
         43.27;
}
inline double Focal35mmFromPx(double focal_px, int32_t width, int32_t height) {
  return focal_px / FocalPxFrom35mm(1.0, width, height);
}

// The lens's radial distortion, one term, and the focal length's error k0 (bundle.h): an
// observed (distorted) normalised point (x, y) times this is the pinhole's point, as bundle.h
// undistorts the observations.
inline double UndistortScale(double k1, double x, double y, double k0 = 0) {
  return 1 + k0 + k1 * (x * x + y * y);
}

struct ViewMotion {
  double rotation[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  double translation[3] = {0, 0, 0};
};

// How the views of a burst relate: one vocabulary for the synthetic scene (which moves its camera
// so), the depth stage (which is told so) and the pipeline (which is told so, or finds out). Each
// takes the values it can act on and refuses the others.
enum class ViewGeometry : uint8_t {
  // A rectified rig: equally spaced views, left to right, none turned; a point moves along its
  // row by its disparity per view step. Scene, depth stage and pipeline.
  kRectified,
  // A hand holding the camera: each view turned and moved a little at random. Scene only: it
  // knows the poses it drew; a pipeline given such a burst uses kAuto.
  kHandheld,
  // Every view's pose is given (ViewMotion): the depth stage sweeps planes through the views'
  // homographies. Depth stage only.
  kKnownPoses,
  // The poses are unknown: the motion stage recovers them from the frames, then the depth stage
  // runs as kKnownPoses. Pipeline only.
  kAuto,
};

}  // namespace lb
