// Small-motion bundle adjustment (Levenberg-Marquardt, Eigen, double): every non-reference view's
// rotation and translation and every point's inverse depth, from points observed in the
// reference (held exact, as in the accidental-motion literature: the reference pixel fixes the
// ray) and tracked into the other views.
//
// Model: a point on the reference ray r = (x, y, 1) at inverse depth w is seen in view v along
// R_v r + w t_v; residuals are in pixels (normalised error times fx, fy) under a Huber loss.
// Lens distortion, optionally estimated: one radial term k1 shared by all views (one lens), as an
// undistortion of the observed normalised points, p (1 + k1 |p|^2), in the reference and in the
// views. Without it, the barrel distortion of a real lens (a vertical motion growing as x y times
// the disparity) is fitted as a rotation about y, which small motion trades against an offset of
// every inverse depth: the dense depth then comes out shifted.
// Rotations are updated by a unit quaternion (1, d/2) normalised, so no sin/cos is needed and the
// same bits come out on every target. Start: identity rotations, zero translations, w = 1; small
// motion makes that close enough. Gauge: after every accepted step the inverse depths are scaled
// to mean |w| 1 with a mean >= 0 (translations scaled inversely). Inverse depths are signed: at a
// narrow field of view the fit may put points beyond its infinity (motion_stage.h).
//
// Linear algebra: the point block is diagonal (one unknown per point), so each step solves the
// reduced camera system (6 per view and k1, <= 91 unknowns) with an in-place Cholesky in arena
// memory.
#pragma once

#include <cstdint>

#include "algo/core/arena.h"
#include "algo/core/status.h"
#include "algo/motion/camera.h"

namespace lb {

struct BundleInput {
  int32_t views = 0;
  int32_t reference = 0;
  int32_t points = 0;
  double fx = 1, fy = 1;
  const double* ref_xy = nullptr;     // 2 per point: normalised reference coordinates
  const double* obs_xy = nullptr;     // 2 per (view, point), view-major: normalised
  const uint8_t* obs_ok = nullptr;    // per (view, point), view-major
  const uint8_t* point_ok = nullptr;  // per point
  // Weight of a prior pulling each view's rotation about `prior_axis` (a unit vector) towards
  // none: 0.5 w (fx theta . axis)^2 is added to the cost, as if w observations had seen that
  // rotation's shift of the image centre.
  double rotation_prior = 0;
  double prior_axis[3] = {0, 1, 0};
  // Weight of a prior pulling k1 towards 0: 0.5 w (k1 k1_reach_px)^2, as if w observations had
  // seen what k1 does at the frame's corner (k1_reach_px = fx |corner|^3, normalised). At a
  // narrow field of view k1 barely moves a pixel and would otherwise run off along the turn.
  double k1_prior = 0;
  double k1_reach_px = 0;
  // The same for k0, the focal length's error (the normalised points scaled by 1 + k0: the true
  // focal length is fx / (1 + k0)): 0.5 w (k0 k0_reach_px)^2, k0_reach_px = fx |corner|.
  double k0_prior = 0;
  double k0_reach_px = 0;
  // Solve stops once an accepted step lowers the cost by less than this fraction of it. Near
  // the minimum the steps shrink only linearly (Gauss-Newton with residuals left: each gain a
  // steady fraction of the one before), so a tighter bound buys iterations, not accuracy.
  double min_gain = 1e-8;
};

struct BundleReport {
  int32_t iterations = 0;
  double initial_rms_px = 0;
  double rms_px = 0;  // over the used observations
  int32_t observations = 0;
};

class Bundle {
 public:
  static constexpr int32_t kMaxViews = 16;
  // Unknowns of the reduced system: 6 per view but the reference's, k1 and k0.
  static constexpr int32_t kMaxReduced = 6 * (kMaxViews - 1) + 2;

  Status Carve(int32_t max_views, int32_t max_points, Arena& arena);

  // Refines `motion` (one per view; the reference's is left the identity), `inv_depth` (one
  // per point), the radial distortion `k1` and the focal length's error `k0` (each nullptr:
  // held at 0) from their current values.
  Status Solve(const BundleInput& in, int32_t max_iterations, double huber_px, ViewMotion* motion,
               double* inv_depth, double* k1, double* k0, BundleReport* report);

  // What ErrorPx says of a point behind the view's camera.
  static constexpr double kBehindPx = 1e6;
  // Reprojection error in px of one observation under the given parameters.
  static double ErrorPx(const BundleInput& in, const ViewMotion& m, double w, double k1,
                        int32_t view, int32_t point, double k0 = 0);

 private:
  double Cost(const BundleInput& in, const ViewMotion* motion, const double* w, double k1,
              double k0, double huber, int32_t* count) const;

  int32_t max_views_ = 0, max_points_ = 0;
  double* hcc_ = nullptr;    // camera blocks, 6(V-1) x 6
  double* hck_ = nullptr;    // the k1 and k0 rows of the reduced matrix, 2 x (6(V-1) + 2)
  double* g_ = nullptr;      // camera (and k1, k0) gradient, 6(V-1) + 2
  double* s_ = nullptr;      // damped reduced camera matrix, (6(V-1) + 2) squared
  double* g2_ = nullptr;     // its right-hand side, then the camera step
  double* hww_ = nullptr;    // per point
  double* gw_ = nullptr;     // per point
  double* hcw_ = nullptr;    // per point: 6(V-1) + 2
  double* w_try_ = nullptr;  // per point
};

}  // namespace lb
