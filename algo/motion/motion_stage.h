// Motion stage: from the working-resolution views of a handheld burst to every view's rotation
// and translation relative to the reference, the sparse points' inverse depths and the
// inverse-depth range they span, or a diagnosis of why the burst cannot give depth.
//
// Steps: grey pyramids (pyramid.h), corners on the reference (corners.h), pyramidal
// Lucas-Kanade into every view (tracker.h), small-motion bundle adjustment under a Huber loss
// with the worst observations dropped and the adjustment rerun (bundle.h), the rail test (rail.h:
// frames on a line at equal steps are adjusted again with the turn across the rail held and the
// lens's radial distortion fitted), the parallax each view shows (parallax.h), then the checks.
//
// Scale convention: inverse depths are signed and scaled to mean |w| 1 over the points, and
// translations are in the inverse unit. Only the product inv_depth * translation reaches pixels
// (plane_homography.h), and it does not depend on the convention. At a narrow field of view a
// turn across the baseline looks like an offset of every inverse depth, so the fit's infinity
// may lie among the points (a converged burst): only differences of inverse depth are
// meaningful, which is all that depth labels and blur use (auto_geometry.h). A rectified rig of
// spacing b seen at mean inverse depth m has |translation| = b m per view step.
//
// Memory: every buffer is carved at Configure; Estimate allocates nothing (Eigen runs on arena
// memory and fixed-size temporaries; EIGEN_NO_MALLOC guards it).
// Determinism: integer pyramids, corners and tracking; double geometry without FMA contraction,
// SIMD or transcendentals, so the same burst gives the same bits on x86-64, aarch64 and armhf.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/arena.h"
#include "algo/core/image.h"
#include "algo/core/status.h"
#include "algo/motion/bundle.h"
#include "algo/motion/camera.h"
#include "algo/motion/corners.h"
#include "algo/motion/plane_homography.h"
#include "algo/motion/pyramid.h"
#include "algo/motion/tracker.h"

namespace lb {

struct MotionConfig {
  static constexpr int32_t kMaxViews = Bundle::kMaxViews;
  static constexpr int32_t kMinSize = 64;  // smallest working width and height

  int32_t width = 0;  // working resolution
  int32_t height = 0;
  int32_t views = 0;
  int32_t pyramid_levels = 4;  // follows motions up to ~(radius + 1) * 2^(levels - 1) px
  int32_t cell = 0;            // corner grid cell in px; 0 = max(8, width / 80)
  TrackerParams tracker;
  int32_t min_features = 40;        // corners, and followed points per view, below: degenerate
  int32_t bundle_iterations = 100;  // per round
  int32_t bundle_rounds = 3;        // adjust, drop observations off by > outlier_px, adjust again
  double huber_px = 0.5;
  // A rail (rail.h): every frame's translation within rail_off_axis (the sine of the angle) of
  // one line and its length per frame step within rail_spacing of their mean. The adjustment
  // then runs once more, with radial k1, and with this prior weight (bundle.h) on the turn that
  // shifts the image along the rail, which holds it at ~0. rail_off_axis 0: never a rail. Only a
  // rail's adjustment fits k1: on a handheld burst k1, the turn across the baseline and the depth
  // offset share one flat valley, and real frames can slide along it (motion_stage.cc).
  double rail_off_axis = 0.05;  // ~2.9 degrees
  double rail_spacing = 0.1;
  double rail_rotation_prior = 1000;
  // Weight of the prior that holds k1 near 0 (bundle.h): what k1 does at the frame's corner
  // counts as this many observations.
  double k1_prior = 0.01;
  // The focal length as an unknown too (k0 in bundle.h), for frames whose lens nobody told
  // (no EXIF, no configuration: DefaultIntrinsics' guess), held near the guess by this prior
  // weight (what k0 does at the frame's corner counts as this many observations). At a narrow
  // field of view the frames cannot tell and the guess stays.
  bool estimate_focal = false;
  double focal_prior = 0.001;
  double outlier_px = 0.8;
  double min_parallax_px = 1.0;  // depth-dependent motion the best view must show
  int32_t blur_percent = 55;     // a frame whose sharpness is below this % of the median: blurred
  int32_t workers = 1;           // the tracker's window buffers (task_runner.h), 1..kMaxWorkers
};

enum class MotionDiagnosis : uint8_t {
  kOk,
  kTooFewFeatures,  // the reference has too little texture
  kBlurredFrame,    // one frame is much less sharp than the others
  kLostTracking,    // a frame moved too far (or differs too much) to follow the points
  kNoMotion,        // the frames show the same view: the camera did not move
  kPureRotation,    // the camera turned but did not move sideways: no parallax
};

struct MotionResult {
  MotionDiagnosis diagnosis = MotionDiagnosis::kOk;
  int32_t bad_view = -1;  // the frame a per-frame diagnosis names
  int32_t views = 0, reference = 0;
  CameraIntrinsics intrinsics;
  ViewMotion motion[MotionConfig::kMaxViews];     // the reference's is the identity
  int32_t inliers[MotionConfig::kMaxViews] = {};  // points used per view
  int32_t sharpness_q4[MotionConfig::kMaxViews] = {};
  // Per view: 90th percentile over the points of how far their depth moves them (against the
  // median depth on the same ray), px.
  double parallax_px[MotionConfig::kMaxViews] = {};
  // Sparse points (arena memory, valid until the next Estimate): reference pixel-index position
  // and inverse depth, inliers only.
  int32_t points = 0;
  const double* point_xy = nullptr;  // 2 per point
  const double* inv_depth = nullptr;
  // Inverse-depth range for the depth labels: the 2nd and 98th percentiles of the points (a
  // caller adds its own margin).
  double inv_depth_min = 0, inv_depth_max = 0;
  double rms_px = 0;  // reprojection error of the final adjustment
  // Radial distortion of the frames' normalised coordinates (bundle.h), 0 when not estimated.
  // The depth stage's plane homographies leave it out: it moves points by a fraction of a pixel
  // over a burst's baseline.
  double k1 = 0;
  // The focal length's error the frames showed (estimate_focal): `intrinsics` already holds the
  // corrected fx / (1 + k0), the one every pose and inverse depth here is in.
  double k0 = 0;
  bool rail = false;  // the frames lie on a line at equal steps: the rotations were held
  int32_t corners = 0;

  // Plane homography of `view` for a plane at `inv_depth` (in this result's units).
  PlaneHomography Homography(int32_t view, double inv_depth) const {
    return MakePlaneHomography(intrinsics, motion[view], inv_depth);
  }
};

class MotionStage {
 public:
  static Status Validate(const MotionConfig& config);
  // Bytes of arena Configure carves; with `scratch_apart`, those it carves from `arena` when it
  // gets a scratch arena too.
  static size_t RequiredBytes(const MotionConfig& config, bool scratch_apart = false);
  // Bytes of the memory only Estimate reads, and only while it runs (the pyramids, the corner
  // detector's and the tracker's): a caller may lend memory it needs only before or after.
  static size_t ScratchBytes(const MotionConfig& config);
  // Carves from `arena`, and the memory of ScratchBytes from `scratch` when given.
  Status Configure(const MotionConfig& config, Arena& arena, Arena* scratch = nullptr);
  // Where the tracker runs its points (borrowed; nullptr: on the caller), with at most
  // config.workers workers. The result does not depend on it.
  void SetRunner(TaskRunner* runner) { runner_ = runner; }

  // `views` (config.views of them) are RGB8 or grey images of the working resolution. Fills
  // `result` and returns Ok, or a kDegenerate status whose message says what to do (the
  // diagnosis is in the result too), or kInvalidArgument for views that do not match.
  Status Estimate(const ConstImageU8* views, int32_t reference, const CameraIntrinsics& intrinsics,
                  MotionResult* result);

  // Turns `result` (of this stage's last Estimate) into its mirror w -> -w, t -> -t, which
  // moves every pixel the same way: for a caller that has learnt which end is near
  // (depth_order.h). Its points' inverse depths live in this stage's memory.
  void ReverseDepth(MotionResult* result);

  const MotionConfig& config() const { return config_; }
  size_t arena_bytes() const { return arena_bytes_; }

 private:
  Status Carve(Arena& arena, Arena& scratch);
  Status Track(const ConstImageU8* views, int32_t reference, MotionResult* result);
  int32_t* Displacements(int32_t v) { return disp_q16_ + 2 * static_cast<size_t>(v) * max_points_; }
  // The 90th percentile of view v's followed points' displacements, px.
  double ReachPx(int32_t v, int32_t n);
  // The scale s > 1 with which most of the points both views followed move in v by s times their
  // motion in u; `votes` receives how many (0 when too few for a chain).
  double FartherScale(int32_t u, int32_t v, int32_t n, int32_t* votes);
  // shift_[v]: the median of view v's followed points' displacements, px (0 for the reference).
  void MedianShift(int32_t v, int32_t reference, int32_t n);
  Status Adjust(const CameraIntrinsics& k, int32_t reference, MotionResult* result);
  Status Check(MotionResult* result);

  MotionConfig config_;
  size_t arena_bytes_ = 0;
  int32_t max_points_ = 0;
  GreyPyramid ref_, view_;
  CornerDetector corners_;
  Tracker tracker_;
  TaskRunner* runner_ = nullptr;
  Bundle bundle_;
  Corner* corner_ = nullptr;     // max_points_
  int32_t* pos_q16_ = nullptr;   // corner x (max_points_), then y (max_points_)
  int32_t* disp_q16_ = nullptr;  // dx, dy per (view, point)
  uint8_t* obs_ok_ = nullptr;    // per (view, point)
  uint8_t* near_ok_ = nullptr;   // obs_ok_ of the frames near the reference only
  uint8_t* point_ok_ = nullptr;  // per point
  double* ref_xy_ = nullptr;     // normalised, 2 per point
  double* obs_xy_ = nullptr;     // normalised, 2 per (view, point)
  double* inv_depth_ = nullptr;  // per point
  double* out_xy_ = nullptr;     // inliers: pixel positions
  double* out_w_ = nullptr;      // inliers: inverse depths (sorted copy for percentiles too)
  double* sorted_ = nullptr;
  double shift_[MotionConfig::kMaxViews][2] = {};  // MedianShift, per view
};

}  // namespace lb
