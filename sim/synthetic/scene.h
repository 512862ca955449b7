// A synthetic burst with known depth: the default input on a PC and the ground truth of the depth,
// rendering and motion tests.
//
// The scene is a brick wall 12 m away with 6-8 bright point lights, an optional tiled ground
// plane and 5-6 planar objects in front (discs, a ring, boards, a thin pole) between about 0.45
// and 2.6 m, at distinct depths, some overlapping. It is designed at 640x480 ("design px",
// centred on the image centre; sizes up to 4:1 either way) and scaled to any size, so the same
// seed gives the same picture at every resolution (a finest texture octave joins where it spans
// 2 px or more). Distances are in metres; the reference camera sits at the origin looking down
// +Z, image y pointing down. At disparity_scale 1 a 640x480 frame's disparity runs from 0.5
// (wall) to 11-13 px per view step (the nearest disc).
//
// Every view is exactly a per-object plane-induced homography of the reference: objects are
// planes whose outline and texture are fixed in reference-image coordinates (the ground is
// textured in its own plane coordinates). Continuous pixel coordinates put pixel (i, j) on
// [i, i+1) x [j, j+1); the principal point is the image centre.
//
// Geometry (ViewGeometry, algo/motion/camera.h), kRectified or kHandheld:
//  - kRectified: view v's camera centre is at ((v - reference) * baseline, 0, 0), no rotation,
//    so a reference point of per-step disparity d is at x + (reference - v) * d in view v, same
//    row (the depth stage's convention).
//  - kHandheld: the reference has the identity pose; every other view a seeded random rotation
//    of 0.3..1 x max_rotation_deg about a random axis and a translation of 0.5..1 x
//    max_translation * scene_depth() in a random, mostly sideways direction; with converge_m,
//    then turned so the point converge_m down the reference's axis stays at the image centre.
//
// Ground truth: the reference view's per-step disparity (px per view step of the rectified rig;
// in handheld mode the same number, proportional to inverse depth) and inverse depth (1/m), at
// the full resolution or at full / scale, plus intrinsics and the poses.
//
// Determinism: per-frame setup (poses, homographies) is double arithmetic without FMA
// contraction or libm transcendentals, rounded to fixed point; every per-pixel value comes from
// integer arithmetic, so a burst has the same bytes on x86-64, aarch64 and armhf.
// Memory: Configure allocates; RenderRows and the ground-truth calls never do.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "algo/core/status.h"
#include "algo/motion/camera.h"

namespace lb {

struct SceneParams {
  uint64_t seed = 1;
  ViewGeometry geometry = ViewGeometry::kRectified;  // or kHandheld
  int32_t reference = -1;                            // reference view; -1 = views / 2
  double fov_deg = 65.0;                             // horizontal field of view of a 4:3 frame
  double disparity_scale = 1.0;   // scales the rectified baseline (and so every disparity)
  double max_rotation_deg = 1.0;  // handheld: rotation bound per frame
  double max_translation = 0.01;  // handheld: translation bound, a fraction of scene_depth()
  // handheld: > 0 turns every view toward the point this many metres down the reference's
  // axis, as a hand keeping its subject in frame does (the views converge on it).
  double converge_m = 0;
  bool ground_plane = true;
  bool point_lights = true;
};

class Scene {
 public:
  static constexpr int32_t kMinSize = 16;
  static constexpr int32_t kMaxSize = 8192;
  static constexpr int32_t kMaxAspect = 4;  // width:height or height:width
  static constexpr int32_t kMinViews = 2;
  static constexpr int32_t kMaxViews = 16;
  static constexpr int32_t kMaxObjects = 8;
  static constexpr int32_t kMaxLights = 8;

  enum class Shape : uint8_t { kWall, kGround, kDisc, kRing, kBox };

  // Builds the scene and every view's mapping. Allocates (row scratch of width + 1 samples).
  Status Configure(const SceneParams& params, int32_t width, int32_t height, int32_t views);

  // Renders rows [y0, y0 + rows) of `view` as RGB8 into `out_rgb8` (rows `stride` bytes apart).
  // Uses the scene's scratch rows: one call at a time per Scene.
  Status RenderRows(int32_t view, int32_t y0, int32_t rows, uint8_t* out_rgb8, ptrdiff_t stride);

  // Ground truth of the reference view at resolution (width / scale) x (height / scale), rows
  // [y0, y0 + rows) of that grid, each sample taken at the centre of its scale x scale block.
  // Disparity: px (of that grid) per view step, unsigned Q8.8, saturated to 65535.
  Status DisparityRows(int32_t scale, int32_t y0, int32_t rows, uint16_t* out_q8,
                       ptrdiff_t stride) const;
  // Inverse depth in 1/m, unsigned Q4.12.
  Status InverseDepthRows(int32_t scale, int32_t y0, int32_t rows, uint16_t* out_q12,
                          ptrdiff_t stride) const;
  // Index of the object seen at each sample of any view (0 = wall, see object_shape()): with
  // the poses, it tells which reference points a view can see.
  Status ObjectRows(int32_t view, int32_t scale, int32_t y0, int32_t rows, uint8_t* out,
                    ptrdiff_t stride) const;

  // Bounds of the per-step disparity over the scene's surfaces that can appear in the
  // reference view (wall to the nearest object or the ground's bottom row), at full / scale.
  // Use them to set the depth stage's label range.
  int32_t disparity_min_q8(int32_t scale = 1) const;
  int32_t disparity_max_q8(int32_t scale = 1) const;
  double disparity_min(int32_t scale = 1) const;
  double disparity_max(int32_t scale = 1) const;
  // The same bounds as inverse depth (1/m, Q4.12), for the handheld mode.
  int32_t inverse_depth_min_q12() const;
  int32_t inverse_depth_max_q12() const;

  int32_t width() const { return width_; }
  int32_t height() const { return height_; }
  int32_t views() const { return views_; }
  int32_t reference() const { return reference_; }
  const SceneParams& params() const { return params_; }
  // In px of the rendered resolution, and each view's pose in metres (camera.h's conventions).
  const CameraIntrinsics& intrinsics() const { return intrinsics_; }
  const ViewMotion& pose(int32_t view) const { return poses_[view]; }
  double baseline() const { return baseline_; }  // metres per view step (rectified rig)
  // Depth whose inverse is midway between the wall's and the nearest object's (metres).
  double scene_depth() const { return scene_depth_; }
  int32_t object_count() const { return object_count_; }
  Shape object_shape(int32_t i) const { return objects_[i].shape; }
  double object_depth(int32_t i) const;  // metres; the ground's at the bottom row

 private:
  struct Object {
    Shape shape = Shape::kWall;
    double depth = 1;       // metres (planes facing the camera); ground: camera height
    double cx = 0, cy = 0;  // design px, relative to the image centre
    double r0 = 0, r1 = 0;  // disc/ring radius and hole; box half length and half width
    double angle_deg = 0;   // box: long axis from vertical
    uint8_t color_a[3] = {}, color_b[3] = {};
    uint8_t pattern = 0;             // 0 plain, 1 checker, 2 stripes, 3 bricks, 4 tiles
    int32_t salt_x = 0, salt_y = 0;  // noise table offsets, so objects look different
    // Fixed-point outline in reference px (Q16): centre, squared radii (Q32) or box axes.
    int64_t cx_q16 = 0, cy_q16 = 0, r0_q16 = 0, r0sq_q32 = 0, r1sq_q32 = 0;
    int64_t cos_q15 = 0, sin_q15 = 0, half_len_q31 = 0, half_wid_q31 = 0;
  };
  // One object as seen from one view. Inputs are view coordinates in half pixels (X2 = 2x).
  struct ViewMap {
    int64_t nx[3] = {}, ny[3] = {};          // reference x, y numerators: Q40 px
    int64_t den[3] = {};                     // denominator, Q40 (den[2] = 2^40)
    bool affine = true;                      // den[0] == den[1] == 0: no division
    int64_t rho[3] = {};                     // inverse depth in this view, 1/m Q40
    int32_t x0 = 0, x1 = 0, y0 = 0, y1 = 0;  // conservative view bounds in half px
    bool bounded = false;
  };
  struct Light {
    int64_t x_q8 = 0, y_q8 = 0;  // design px Q8 (wall texture coordinates)
  };
  // Per-row evaluation state of one object.
  struct RowMap {
    int64_t nx, ny, den, rho;
  };
  // One row of one view: every object's state, and the objects whose bounds reach the row, in
  // test order.
  struct RowState {
    RowMap obj[kMaxObjects];
    int32_t active[kMaxObjects];
    int32_t active_count;
  };

  void BuildLayout(const SceneParams& params);
  int64_t RhoMinQ40() const;
  int64_t RhoMaxQ40() const;
  int32_t DispQ8(int64_t rho_q40, int32_t scale) const;
  void BuildFixedPoint();
  Status BuildView(int32_t view);
  void PrepareRow(const ViewMap* maps, int32_t y2, RowState* row) const;
  int32_t Winner(const ViewMap* maps, const RowState& row, int32_t x2, int64_t* rho_q40) const;
  void RefPoint(const ViewMap& m, const RowMap& r, int32_t x2, int64_t* xr_q16,
                int64_t* yr_q16) const;
  bool Inside(const Object& o, int64_t xr_q16, int64_t yr_q16) const;
  void Shade(int32_t object, int64_t xr_q16, int64_t yr_q16, int32_t* rgb) const;
  Status CheckTruthArgs(int32_t scale, int32_t y0, int32_t rows, const void* out,
                        ptrdiff_t stride) const;
  // Calls fn(x, y, object, rho_q40) for rows [y0, y0 + rows) of `view`'s grid at full / scale,
  // each sample at the centre of its block, with the renderer's z-test.
  template <typename Fn>
  void ForEachTruthSample(int32_t view, int32_t scale, int32_t y0, int32_t rows, Fn&& fn) const;

  SceneParams params_;
  int32_t width_ = 0, height_ = 0, views_ = 0, reference_ = 0;
  double px_per_design_ = 1;  // pixels per design px
  double focal_design_ = 0;   // focal length in design px
  double baseline_ = 0, scene_depth_ = 1;
  CameraIntrinsics intrinsics_;
  ViewMotion poses_[kMaxViews];
  Object objects_[kMaxObjects];
  int32_t object_count_ = 0;
  int32_t order_[kMaxObjects] = {};  // test order: nearest first
  Light lights_[kMaxLights];
  int32_t light_count_ = 0;
  ViewMap maps_[kMaxViews][kMaxObjects];
  // Fixed-point resolution constants.
  int64_t half_w_q16_ = 0, half_h_q16_ = 0;
  int64_t design_per_px_q24_ = 0;  // design px per pixel, Q24
  int64_t ground_fh_q8_ = 0;       // focal * camera height in px * cm, Q8
  int64_t ground_h_q8_ = 0;        // camera height in cm, Q8
  int64_t ground_vmin_q16_ = 0;    // smallest row offset below the centre the ground texture uses
  int64_t disp_per_rho_q16_ = 0;   // full-resolution px per view step per (1/m), Q16
  int32_t detail_octaves_ = 3;     // texture octaves the resolution can show
  // Value-noise lattice: small enough to stay in the L1 cache.
  static constexpr int32_t kNoiseSize = 128;
  uint8_t noise_[kNoiseSize * kNoiseSize] = {};
  uint8_t fade_[256] = {};            // smoothstep, Q8
  std::vector<uint8_t> corner_rows_;  // 2 x (width + 1) object indices
};

}  // namespace lb
