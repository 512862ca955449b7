#include "algo/motion/motion_stage.h"

#include <algorithm>
#include <cmath>

#include "algo/motion/parallax.h"
#include "algo/motion/rail.h"
#include "algo/motion/view_tree.h"

namespace lb {
namespace {

static_assert(MotionConfig::kMaxViews <= kMaxRailViews &&
              MotionConfig::kMaxViews <= kMaxTreePoints);

int32_t Cell(const MotionConfig& c) {
  if (c.cell > 0) return c.cell;
  return c.width / 80 > 8 ? c.width / 80 : 8;
}

// Chord |R - I|_F = 2 sqrt(2) sin(angle / 2): monotone in the angle, no acos needed.
double RotationChord(const ViewMotion& m) {
  double s = 0;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const double d = m.rotation[i][j] - (i == j ? 1.0 : 0.0);
      s += d * d;
    }
  }
  return __builtin_sqrt(s);
}

}  // namespace

Status MotionStage::Validate(const MotionConfig& c) {
  if (c.views < 2 || c.views > MotionConfig::kMaxViews) {
    return Status(Code::kInvalidArgument, "motion: %d views (2..%d)", c.views,
                  MotionConfig::kMaxViews);
  }
  if (c.width < MotionConfig::kMinSize || c.height < MotionConfig::kMinSize || c.width > 8192 ||
      c.height > 8192) {
    return Status(Code::kInvalidArgument, "motion: %dx%d working resolution (%d..8192)", c.width,
                  c.height, MotionConfig::kMinSize);
  }
  if (c.min_features < 8 || c.bundle_iterations < 1 || c.bundle_rounds < 1 ||
      c.bundle_rounds > 10 || !(c.huber_px > 0) || !(c.outlier_px > 0) ||
      !(c.min_parallax_px >= 0) || c.blur_percent < 0 || c.blur_percent > 100) {
    return Status(Code::kInvalidArgument,
                  "motion: min_features >= 8, iterations >= 1, 1..10 rounds, positive "
                  "thresholds and blur_percent 0..100 expected");
  }
  if (!(c.rail_off_axis >= 0 && c.rail_off_axis < 1) || !(c.rail_spacing >= 0) ||
      !(c.rail_rotation_prior >= 0) || !(c.k1_prior >= 0) || !(c.focal_prior >= 0)) {
    return Status(Code::kInvalidArgument,
                  "motion: rail_off_axis 0..1, rail_spacing and the priors >= 0 expected");
  }
  return Status::Ok();
}

size_t MotionStage::RequiredBytes(const MotionConfig& config, bool scratch_apart) {
  if (!Validate(config).ok()) return 0;
  MotionStage planner;
  Arena counting, apart;
  planner.config_ = config;
  if (!planner.Carve(counting, scratch_apart ? apart : counting).ok()) return 0;
  return counting.used();
}

size_t MotionStage::ScratchBytes(const MotionConfig& config) {
  if (!Validate(config).ok()) return 0;
  MotionStage planner;
  Arena counting, scratch;
  planner.config_ = config;
  if (!planner.Carve(counting, scratch).ok()) return 0;
  return scratch.used();
}

Status MotionStage::Configure(const MotionConfig& config, Arena& arena, Arena* scratch) {
  LB_RETURN_IF_ERROR(Validate(config));
  config_ = config;
  const size_t before = arena.used();
  const size_t scratch_before = scratch != nullptr ? scratch->used() : 0;
  LB_RETURN_IF_ERROR(Carve(arena, scratch != nullptr ? *scratch : arena));
  arena_bytes_ = arena.used() - before;
  if (arena.overflowed() || (scratch != nullptr && scratch->overflowed())) {
    return Status(Code::kOutOfMemory, "motion: arena too small (needs %zu bytes, %zu of scratch)",
                  arena_bytes_, scratch != nullptr ? scratch->used() - scratch_before : 0);
  }
  return Status::Ok();
}

Status MotionStage::Carve(Arena& arena, Arena& scratch) {
  const MotionConfig& c = config_;
  LB_RETURN_IF_ERROR(ref_.Carve(c.width, c.height, c.pyramid_levels, scratch));
  LB_RETURN_IF_ERROR(view_.Carve(c.width, c.height, c.pyramid_levels, scratch));
  LB_RETURN_IF_ERROR(corners_.Carve(c.width, c.height, Cell(c), scratch));
  LB_RETURN_IF_ERROR(tracker_.Carve(c.tracker, scratch, c.workers));
  max_points_ = corners_.max_corners();
  LB_RETURN_IF_ERROR(bundle_.Carve(c.views, max_points_, arena));
  const size_t n = static_cast<size_t>(max_points_);
  const size_t vn = n * static_cast<size_t>(c.views);
  corner_ = arena.Allocate<Corner>(n);
  pos_q16_ = arena.Allocate<int32_t>(2 * n);
  disp_q16_ = arena.Allocate<int32_t>(2 * vn);
  obs_ok_ = arena.Allocate<uint8_t>(vn);
  near_ok_ = arena.Allocate<uint8_t>(vn);
  point_ok_ = arena.Allocate<uint8_t>(n);
  ref_xy_ = arena.Allocate<double>(2 * n);
  obs_xy_ = arena.Allocate<double>(2 * vn);
  inv_depth_ = arena.Allocate<double>(n);
  out_xy_ = arena.Allocate<double>(2 * n);
  out_w_ = arena.Allocate<double>(n);
  sorted_ = arena.Allocate<double>(n);
  return Status::Ok();
}

Status MotionStage::Estimate(const ConstImageU8* views, int32_t reference,
                             const CameraIntrinsics& k, MotionResult* result) {
  const MotionConfig& c = config_;
  if (corner_ == nullptr) return Status(Code::kInvalidArgument, "motion: not configured");
  if (reference < 0 || reference >= c.views) {
    return Status(Code::kInvalidArgument, "motion: reference %d of %d views", reference, c.views);
  }
  if (!(k.fx > 0) || !(k.fy > 0)) {
    return Status(Code::kInvalidArgument, "motion: focal length %g x %g px", k.fx, k.fy);
  }
  for (int32_t v = 0; v < c.views; ++v) {
    if (views[v].width != c.width || views[v].height != c.height ||
        (views[v].channels != 1 && views[v].channels != 3) || views[v].data == nullptr) {
      return Status(Code::kInvalidArgument, "motion: view %d is %dx%dx%d, expected %dx%d", v,
                    views[v].width, views[v].height, views[v].channels, c.width, c.height);
    }
  }
  *result = MotionResult{};
  result->views = c.views;
  result->reference = reference;
  result->intrinsics = k;
  LB_RETURN_IF_ERROR(Track(views, reference, result));
  const Status adjusted = Adjust(k, reference, result);
  if (adjusted.code() == Code::kDegenerate) {
    // Nothing to adjust (no point followed into any frame): say why in the user's terms, a
    // blurred frame or points lost, rather than the adjustment's.
    const Status why = Check(result);
    return why.ok() ? adjusted : why;
  }
  LB_RETURN_IF_ERROR(adjusted);
  return Check(result);
}

Status MotionStage::Track(const ConstImageU8* views, int32_t reference, MotionResult* result) {
  const MotionConfig& c = config_;
  LB_RETURN_IF_ERROR(ref_.Build(views[reference]));
  result->sharpness_q4[reference] = SharpnessQ4(ref_.level(0));
  // A corner must stand out from the frame's noise: its response at least that of a 1-level
  // step over the 5x5 box. No floor relative to the strongest corner: a bright, textured
  // subject must not silence a faint wall behind it, or the label range never reaches the
  // wall (the HCI scene: 233 points on the bust alone, 544 with the wall). The tracker's
  // error check and the adjustment's outlier drop take what noise lets through.
  const int32_t n = corners_.Detect(ref_.level(0), 250000, 100000, corner_);
  result->corners = n;
  if (n < c.min_features) {
    result->diagnosis = MotionDiagnosis::kTooFewFeatures;
    return Status(Code::kDegenerate,
                  "too few features: %d corners in the reference frame, %d needed; aim at a "
                  "scene with more texture or light",
                  n, c.min_features);
  }
  for (int32_t i = 0; i < n; ++i) {
    pos_q16_[i] = corner_[i].x << 16;
    pos_q16_[max_points_ + i] = corner_[i].y << 16;
  }
  // Every frame from no motion first, over the whole pyramid. How far it went is the 90th
  // percentile of its points' displacements: the median can be a repetitive texture's wrong
  // period, locked onto by most points, where the nearest surfaces' large motion shows.
  double reach[MotionConfig::kMaxViews] = {};
  for (int32_t v = 0; v < c.views; ++v) {
    if (v == reference) continue;
    LB_RETURN_IF_ERROR(view_.Build(views[v]));
    result->sharpness_q4[v] = SharpnessQ4(view_.level(0));
    int32_t* dx = Displacements(v);
    for (int32_t i = 0; i < 2 * max_points_; ++i) dx[i] = 0;
    tracker_.Track(ref_, view_, pos_q16_, pos_q16_ + max_points_, n, dx, dx + max_points_,
                   obs_ok_ + static_cast<size_t>(v) * n, runner_);
    reach[v] = ReachPx(v, n);
  }
  // Then outward, in that order, whatever the frames' places in the list: a frame whose points
  // lie, most of them, where a nearer frame's went times one scale above 1 (the farther frame of
  // a line) starts again from that frame's motion times the scale. A frame several steps out
  // then starts within a step of its points, where a repetitive texture cannot lock onto the
  // wrong period (the tracker also tries no motion, for a hand that went back).
  int32_t order[MotionConfig::kMaxViews];
  int32_t count = 0;
  for (int32_t v = 0; v < c.views; ++v) {
    if (v != reference) order[count++] = v;
  }
  std::sort(order, order + count, [&](int32_t a, int32_t b) {
    return reach[a] < reach[b] || (reach[a] == reach[b] && a < b);
  });
  for (int32_t k = 1; k < count; ++k) {
    const int32_t v = order[k];
    // The farthest of the nearer frames that agrees: the smallest scale, the shortest reach.
    int32_t u = -1;
    double scale = 0;
    for (int32_t j = k - 1; j >= 0 && u < 0; --j) {
      int32_t votes = 0;
      scale = FartherScale(order[j], v, n, &votes);
      if (votes > 0) u = order[j];
    }
    if (u < 0) continue;
    LB_RETURN_IF_ERROR(view_.Build(views[v]));
    int32_t* dx = Displacements(v);
    int32_t* dy = dx + max_points_;
    const int32_t* ux = Displacements(u);
    const int32_t* uy = ux + max_points_;
    const uint8_t* u_ok = obs_ok_ + static_cast<size_t>(u) * n;
    // Q16 starts, held within +-2^30 (16384 px, beyond any frame: such a start just fails).
    auto start = [scale](int32_t d) {
      const double q = d * scale, limit = 1073741824.0;
      return static_cast<int32_t>(std::lround(q > limit ? limit : (q < -limit ? -limit : q)));
    };
    for (int32_t i = 0; i < n; ++i) {
      dx[i] = u_ok[i] ? start(ux[i]) : 0;
      dy[i] = u_ok[i] ? start(uy[i]) : 0;
    }
    tracker_.Track(ref_, view_, pos_q16_, pos_q16_ + max_points_, n, dx, dy,
                   obs_ok_ + static_cast<size_t>(v) * n, runner_);
  }
  for (int32_t v = 0; v < c.views; ++v) MedianShift(v, reference, n);
  return Status::Ok();
}

double MotionStage::ReachPx(int32_t v, int32_t n) {
  const int32_t* d = Displacements(v);
  const uint8_t* ok = obs_ok_ + static_cast<size_t>(v) * n;
  int32_t m = 0;
  for (int32_t i = 0; i < n; ++i) {
    if (!ok[i]) continue;
    const double x = d[i] / 65536.0, y = d[max_points_ + i] / 65536.0;
    sorted_[m++] = x * x + y * y;
  }
  if (m == 0) return 0;
  std::nth_element(sorted_, sorted_ + m * 9 / 10, sorted_ + m);
  return __builtin_sqrt(sorted_[m * 9 / 10]);
}

double MotionStage::FartherScale(int32_t u, int32_t v, int32_t n, int32_t* votes) {
  // Point i agrees with the scales s whose s d_u lies within kTolerancePx of d_v: an interval
  // of s around its projection, if it lies that near the line of d_u at all. The scale most
  // points agree with, above 1 (v is the farther), in bins of 1/kBins.
  constexpr double kTolerancePx = 1.0, kMinPx = 1.0;
  constexpr int32_t kBins = 32, kMaxScale = MotionConfig::kMaxViews;
  constexpr int32_t kLast = kBins * (kMaxScale - 1);
  int32_t histogram[kLast + 1] = {};
  const int32_t* du = Displacements(u);
  const int32_t* dv = Displacements(v);
  const uint8_t* u_ok = obs_ok_ + static_cast<size_t>(u) * n;
  const uint8_t* v_ok = obs_ok_ + static_cast<size_t>(v) * n;
  for (int32_t i = 0; i < n; ++i) {
    if (!u_ok[i] || !v_ok[i]) continue;
    const double ax = du[i] / 65536.0, ay = du[max_points_ + i] / 65536.0;
    const double bx = dv[i] / 65536.0, by = dv[max_points_ + i] / 65536.0;
    const double aa = ax * ax + ay * ay;
    if (aa < kMinPx * kMinPx) continue;
    const double along = (ax * bx + ay * by) / aa, across = ax * by - ay * bx;
    if (across * across > kTolerancePx * kTolerancePx * aa) continue;
    const double half = kTolerancePx / __builtin_sqrt(aa);
    const double lo = (along - half - 1) * kBins, hi = (along + half - 1) * kBins;
    if (hi < 0 || lo > kLast) continue;
    const int32_t b0 = lo < 0 ? 0 : static_cast<int32_t>(__builtin_ceil(lo));
    const int32_t b1 = hi > kLast ? kLast : static_cast<int32_t>(__builtin_floor(hi));
    for (int32_t b = b0; b <= b1; ++b) ++histogram[b];
  }
  // The middle of the first run of bins at the most votes.
  int32_t best = 0;
  for (int32_t b = 1; b <= kLast; ++b) best = histogram[b] > histogram[best] ? b : best;
  int32_t end = best;
  while (end < kLast && histogram[end + 1] == histogram[best]) ++end;
  // Most of the points the two frames share, and enough to stand on.
  int32_t shared = 0;
  for (int32_t i = 0; i < n; ++i) shared += u_ok[i] && v_ok[i];
  const int32_t need = shared / 4 > config_.min_features ? shared / 4 : config_.min_features;
  *votes = histogram[best] >= need ? histogram[best] : 0;
  return 1 + 0.5 * (best + end) / kBins;
}

void MotionStage::MedianShift(int32_t v, int32_t reference, int32_t n) {
  shift_[v][0] = shift_[v][1] = 0;
  if (v == reference) return;
  const int32_t* d = Displacements(v);
  const uint8_t* ok = obs_ok_ + static_cast<size_t>(v) * n;
  for (int32_t axis = 0; axis < 2; ++axis) {
    int32_t m = 0;
    for (int32_t i = 0; i < n; ++i) {
      if (ok[i]) sorted_[m++] = d[axis * max_points_ + i] / 65536.0;
    }
    if (m == 0) {
      shift_[v][axis] = 0;
      continue;
    }
    std::nth_element(sorted_, sorted_ + m / 2, sorted_ + m);
    shift_[v][axis] = sorted_[m / 2];
  }
}

Status MotionStage::Adjust(const CameraIntrinsics& k, int32_t reference, MotionResult* result) {
  const MotionConfig& c = config_;
  const int32_t n = result->corners;
  for (int32_t i = 0; i < n; ++i) {
    // Index coordinates to continuous (+0.5), then normalised.
    ref_xy_[2 * i] = (pos_q16_[i] / 65536.0 + 0.5 - k.cx) / k.fx;
    ref_xy_[2 * i + 1] = (pos_q16_[max_points_ + i] / 65536.0 + 0.5 - k.cy) / k.fy;
    point_ok_[i] = 0;
    inv_depth_[i] = 1.0;
  }
  for (int32_t v = 0; v < c.views; ++v) {
    uint8_t* ok = obs_ok_ + static_cast<size_t>(v) * n;
    if (v == reference) {
      for (int32_t i = 0; i < n; ++i) ok[i] = 0;
      continue;
    }
    const int32_t* dx = disp_q16_ + 2 * static_cast<size_t>(v) * max_points_;
    const int32_t* dy = dx + max_points_;
    for (int32_t i = 0; i < n; ++i) {
      double* o = obs_xy_ + 2 * (static_cast<size_t>(v) * n + i);
      o[0] = ((pos_q16_[i] + dx[i]) / 65536.0 + 0.5 - k.cx) / k.fx;
      o[1] = ((pos_q16_[max_points_ + i] + dy[i]) / 65536.0 + 0.5 - k.cy) / k.fy;
      if (ok[i]) point_ok_[i] = 1;
    }
  }
  BundleInput in;
  in.views = c.views;
  in.reference = reference;
  in.points = n;
  in.fx = k.fx;
  in.fy = k.fy;
  in.ref_xy = ref_xy_;
  in.obs_xy = obs_xy_;
  in.obs_ok = obs_ok_;
  in.point_ok = point_ok_;
  const double cx = 0.5 * c.width / k.fx, cy = 0.5 * c.height / k.fy;
  const double corner = __builtin_sqrt(cx * cx + cy * cy);
  in.k1_prior = c.k1_prior;
  in.k1_reach_px = k.fx * corner * corner * corner;
  in.k0_prior = c.focal_prior;
  in.k0_reach_px = k.fx * corner;
  BundleReport report;
  // The solves before the last only seed the next (its start, which observations it drops at
  // outlier_px): a coarser stop serves them as well (a fifth off the motion stage on a handheld
  // burst; every accuracy figure within 0.04 point).
  constexpr double kSeedGain = 1e-6;
  const double final_gain = in.min_gain;
  // Far frames start from the near ones: from the identity, a frame many steps out (18 px on
  // barn1's ninth view) can send the first adjustment into a wrong minimum. Steps are hops along
  // the tree of the frames' shifts (Track; view_tree.h), not places in the list, so the same
  // frames in any order start alike. The frames within kNearSteps of the reference are adjusted
  // first; each farther frame then starts from the one kNearSteps out on its branch, its
  // translation scaled by the steps.
  constexpr int32_t kNearSteps = 2;
  double points[2 * MotionConfig::kMaxViews] = {};
  for (int32_t v = 0; v < c.views; ++v) {
    points[2 * v] = shift_[v][0];
    points[2 * v + 1] = shift_[v][1];
  }
  int32_t parent[MotionConfig::kMaxViews], hops[MotionConfig::kMaxViews];
  int32_t far = 0;
  if (ViewTree(points, c.views, 2, reference, parent, hops)) {
    for (int32_t v = 0; v < c.views; ++v) far = hops[v] > far ? hops[v] : far;
  }
  if (far > kNearSteps) {
    for (int32_t v = 0; v < c.views; ++v) {
      const size_t at = static_cast<size_t>(v) * n;
      for (int32_t i = 0; i < n; ++i)
        near_ok_[at + i] = hops[v] <= kNearSteps ? obs_ok_[at + i] : 0;
    }
    in.obs_ok = near_ok_;
    in.min_gain = kSeedGain;
    LB_RETURN_IF_ERROR(bundle_.Solve(in, c.bundle_iterations, c.huber_px, result->motion,
                                     inv_depth_, nullptr, nullptr, &report));
    in.obs_ok = obs_ok_;
    for (int32_t v = 0; v < c.views; ++v) {
      if (hops[v] <= kNearSteps) continue;
      int32_t u = v;
      while (hops[u] > kNearSteps) u = parent[u];
      result->motion[v] = result->motion[u];
      for (int32_t k = 0; k < 3; ++k) {
        result->motion[v].translation[k] *= static_cast<double>(hops[v]) / kNearSteps;
      }
    }
  }
  for (int32_t round = 0; round < c.bundle_rounds; ++round) {
    // The focal length joins once the poses have settled without it: from the identity start a
    // free k0 can run off before the rotations have taken their share.
    const bool settled = round > 0 || c.bundle_rounds == 1;
    double* k0 = c.estimate_focal && settled ? &result->k0 : nullptr;
    in.min_gain = round + 1 < c.bundle_rounds ? kSeedGain : final_gain;
    LB_RETURN_IF_ERROR(bundle_.Solve(in, c.bundle_iterations, c.huber_px, result->motion,
                                     inv_depth_, nullptr, k0, &report));
    if (round + 1 == c.bundle_rounds) break;
    // Drop the observations the fit cannot explain (mismatched corners, moving things), and
    // points left with none.
    for (int32_t i = 0; i < n; ++i) {
      if (!point_ok_[i]) continue;
      bool any = false;
      for (int32_t v = 0; v < c.views; ++v) {
        uint8_t& ok = obs_ok_[static_cast<size_t>(v) * n + i];
        if (!ok) continue;
        if (Bundle::ErrorPx(in, result->motion[v], inv_depth_[i], result->k1, v, i, result->k0) >
            c.outlier_px) {
          ok = 0;
        }
        any = any || ok;
      }
      if (!any) point_ok_[i] = 0;
    }
  }
  // Small motion cannot tell a turn about the axis across the baseline from an offset of every
  // inverse depth, nor either from a lens or a rectification the pinhole misses by a tenth of a
  // pixel: real frames can slide along that valley to a turned, depth-shifted fit. A burst whose
  // frames lie on one line at equal steps came from a rail (a slider, a rig) that holds the
  // camera's orientation: it is solved again with that turn held, and with the lens's radial
  // distortion, which the turn no longer absorbs.
  result->rail = IsRail(result->motion, result->views, result->reference,
                        {c.rail_off_axis, c.rail_spacing}, in.prior_axis);
  if (result->rail && c.rail_rotation_prior > 0) {
    in.rotation_prior = c.rail_rotation_prior;
    LB_RETURN_IF_ERROR(bundle_.Solve(in, c.bundle_iterations, c.huber_px, result->motion,
                                     inv_depth_, &result->k1,
                                     c.estimate_focal ? &result->k0 : nullptr, &report));
  }
  result->rms_px = report.rms_px;
  // The poses and inverse depths now live in the normalised coordinates of the focal length the
  // frames told: fx / (1 + k0).
  result->intrinsics.fx = k.fx / (1 + result->k0);
  result->intrinsics.fy = k.fy / (1 + result->k0);
  int32_t m = 0;
  for (int32_t i = 0; i < n; ++i) {
    if (!point_ok_[i]) continue;
    for (int32_t v = 0; v < c.views; ++v)
      result->inliers[v] += obs_ok_[static_cast<size_t>(v) * n + i];
    out_xy_[2 * m] = pos_q16_[i] / 65536.0;
    out_xy_[2 * m + 1] = pos_q16_[max_points_ + i] / 65536.0;
    out_w_[m] = inv_depth_[i];
    sorted_[m] = inv_depth_[i];
    ++m;
  }
  result->inliers[reference] = m;
  result->points = m;
  result->point_xy = out_xy_;
  result->inv_depth = out_w_;
  if (m == 0) return Status::Ok();
  std::sort(sorted_, sorted_ + m);
  result->inv_depth_min = sorted_[(m - 1) * 2 / 100];
  result->inv_depth_max = sorted_[(m - 1) * 98 / 100];
  // Parallax (parallax.h), against the same ray at the median depth.
  ParallaxPoints pts;
  pts.xy = out_xy_;
  pts.inv_depth = out_w_;
  pts.count = m;
  pts.inv_depth_ref = sorted_[m / 2];
  pts.measured = k;
  pts.projected = result->intrinsics;
  pts.k1 = result->k1;
  pts.k0 = result->k0;
  for (int32_t v = 0; v < c.views; ++v) {
    if (v != reference) result->parallax_px[v] = ParallaxPx(pts, result->motion[v], sorted_);
  }
  return Status::Ok();
}

void MotionStage::ReverseDepth(MotionResult* r) {
  if (r->inv_depth == out_w_) {  // this stage's points
    for (int32_t i = 0; i < r->points; ++i) out_w_[i] = -out_w_[i];
  }
  for (int32_t v = 0; v < r->views; ++v) {
    for (double& t : r->motion[v].translation) t = -t;
  }
  const double lo = r->inv_depth_min;
  r->inv_depth_min = -r->inv_depth_max;
  r->inv_depth_max = -lo;
}

Status MotionStage::Check(MotionResult* r) {
  const MotionConfig& c = config_;
  // Blur first: a blurred frame also loses points, and blur is what the user should hear about.
  int32_t sharp[MotionConfig::kMaxViews] = {};
  for (int32_t v = 0; v < c.views; ++v) sharp[v] = r->sharpness_q4[v];
  std::sort(sharp, sharp + c.views);
  const int64_t median = sharp[c.views / 2];
  for (int32_t v = 0; v < c.views; ++v) {
    if (int64_t{r->sharpness_q4[v]} * 100 < median * c.blur_percent) {
      r->diagnosis = MotionDiagnosis::kBlurredFrame;
      r->bad_view = v;
      return Status(Code::kDegenerate,
                    "frame %d is blurred (sharpness %lld%% of the burst's median): hold the "
                    "camera steadier or add light, and shoot again",
                    v, static_cast<long long>(int64_t{r->sharpness_q4[v]} * 100 / median));
    }
  }
  for (int32_t v = 0; v < c.views; ++v) {
    if (v != r->reference && r->inliers[v] < c.min_features) {
      r->diagnosis = MotionDiagnosis::kLostTracking;
      r->bad_view = v;
      return Status(Code::kDegenerate,
                    "frame %d: only %d points could be followed from the reference (%d needed); "
                    "move the camera less between frames and keep the scene still",
                    v, r->inliers[v], c.min_features);
    }
  }
  const double f = r->intrinsics.fx > r->intrinsics.fy ? r->intrinsics.fx : r->intrinsics.fy;
  double best = 0, chord = 0;
  for (int32_t v = 0; v < c.views; ++v) {
    best = r->parallax_px[v] > best ? r->parallax_px[v] : best;
    const double ch = RotationChord(r->motion[v]);
    chord = ch > chord ? ch : chord;
  }
  if (best < c.min_parallax_px) {
    // The rotation (chord ~ sqrt(2) x angle) shows whether the hand turned: 0.05 degree moves
    // the image by less than half a pixel at the working resolution.
    const bool turned = chord * f > 0.5 * 1.41421356;
    r->diagnosis = turned ? MotionDiagnosis::kPureRotation : MotionDiagnosis::kNoMotion;
    if (turned) {
      return Status(Code::kDegenerate,
                    "the camera turned but did not shift (parallax %.2f px): move the camera a "
                    "little sideways between frames instead of turning it",
                    best);
    }
    return Status(Code::kDegenerate,
                  "the camera did not move between frames (parallax %.2f px): move the camera a "
                  "little sideways between frames",
                  best);
  }
  return Status::Ok();
}

}  // namespace lb
