#include "sim/synthetic/scene.h"

#include <cmath>

#include "algo/core/fixed_point.h"
#include "algo/core/sin_cos.h"

// This file is compiled with -ffp-contract=off (see CMakeLists.txt): the double setup below must
// round the same way on every architecture, and it uses no libm function except sqrt.

namespace lb {
namespace {

constexpr double kDesignW = 640, kDesignH = 480;
constexpr double kWallDepth = 12.0;  // metres
constexpr double kWallDisp = 0.5;    // design px per view step at disparity_scale 1
constexpr double kGroundDisp = 6.0;  // the ground's disparity at the bottom row (design px)
constexpr int64_t kOne40 = int64_t{1} << 40;

// splitmix64: a tiny, portable, well-mixed generator (std distributions differ across libraries).
struct Rng {
  uint64_t state;
  uint64_t Next() {
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double Uniform() { return static_cast<double>(Next() >> 11) * (1.0 / 9007199254740992.0); }
  double Range(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  int32_t Int(int32_t n) { return static_cast<int32_t>(Next() % static_cast<uint64_t>(n)); }
};

int64_t ToFixed(double v, int frac) {
  return static_cast<int64_t>(std::floor(v * static_cast<double>(int64_t{1} << frac) + 0.5));
}

using Mat3 = double[3][3];

void Mul(const Mat3 a, const Mat3 b, Mat3 out) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      out[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
}

bool Invert(const Mat3 m, Mat3 out) {
  const double c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1];
  const double c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2];
  const double c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
  const double det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
  if (!(std::fabs(det) > 1e-300)) return false;
  const double inv = 1.0 / det;
  out[0][0] = c00 * inv;
  out[1][0] = c01 * inv;
  out[2][0] = c02 * inv;
  out[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * inv;
  out[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * inv;
  out[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * inv;
  out[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * inv;
  out[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * inv;
  out[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * inv;
  return true;
}

void RandomUnit(Rng& rng, double v[3]) {
  for (;;) {
    for (int i = 0; i < 3; ++i) v[i] = rng.Range(-1, 1);
    const double n2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    if (n2 > 0.01 && n2 <= 1) {
      const double n = std::sqrt(n2);
      for (int i = 0; i < 3; ++i) v[i] /= n;
      return;
    }
  }
}

const uint8_t kPalette[][3] = {{200, 62, 50},  {52, 118, 200}, {232, 188, 62}, {70, 160, 92},
                               {176, 88, 168}, {230, 132, 52}, {88, 188, 200}, {222, 218, 206},
                               {120, 80, 60},  {40, 60, 90}};
constexpr int kPaletteSize = sizeof(kPalette) / sizeof(kPalette[0]);
static_assert(kPaletteSize >= Scene::kMaxObjects, "every object needs a colour of its own");

}  // namespace

Status Scene::Configure(const SceneParams& params, int32_t width, int32_t height, int32_t views) {
  if (width < kMinSize || width > kMaxSize || height < kMinSize || height > kMaxSize)
    return Status(Code::kInvalidArgument, "synthetic scene: size %dx%d outside %d..%d", width,
                  height, kMinSize, kMaxSize);
  if (width > kMaxAspect * height || height > kMaxAspect * width)
    return Status(Code::kInvalidArgument, "synthetic scene: size %dx%d wider than %d:1", width,
                  height, kMaxAspect);
  if (views < kMinViews || views > kMaxViews)
    return Status(Code::kInvalidArgument, "synthetic scene: %d views outside %d..%d", views,
                  kMinViews, kMaxViews);
  const int32_t reference = params.reference < 0 ? views / 2 : params.reference;
  if (reference >= views)
    return Status(Code::kInvalidArgument, "synthetic scene: reference %d not among %d views",
                  params.reference, views);
  if (params.geometry != ViewGeometry::kRectified && params.geometry != ViewGeometry::kHandheld)
    return Status(Code::kInvalidArgument,
                  "synthetic scene: geometry %d is neither rectified nor handheld",
                  static_cast<int>(params.geometry));
  if (!(params.fov_deg >= 10 && params.fov_deg <= 120))
    return Status(Code::kInvalidArgument, "synthetic scene: field of view %.1f outside 10..120",
                  params.fov_deg);
  if (!(params.disparity_scale > 0 && params.disparity_scale <= 8))
    return Status(Code::kInvalidArgument, "synthetic scene: disparity scale %g outside (0, 8]",
                  params.disparity_scale);
  if (!(params.max_rotation_deg >= 0 && params.max_rotation_deg <= 10) ||
      !(params.max_translation >= 0 && params.max_translation <= 0.1))
    return Status(Code::kInvalidArgument,
                  "synthetic scene: handheld bounds %g deg / %g outside 0..10 deg / 0..0.1",
                  params.max_rotation_deg, params.max_translation);
  if (!(params.converge_m >= 0 && params.converge_m <= 1000))
    return Status(Code::kInvalidArgument, "synthetic scene: convergence at %g m outside 0..1000",
                  params.converge_m);

  params_ = params;
  width_ = width;
  height_ = height;
  views_ = views;
  reference_ = reference;
  BuildLayout(params);
  BuildFixedPoint();
  for (int32_t v = 0; v < views; ++v) LB_RETURN_IF_ERROR(BuildView(v));
  corner_rows_.assign(2 * (static_cast<size_t>(width) + 1), 0);
  return Status::Ok();
}

void Scene::BuildLayout(const SceneParams& params) {
  Rng rng{params.seed ^ 0x5CE7E5EEDull};
  double s, c;
  SinCosDeg(params.fov_deg / 2, &s, &c);
  focal_design_ = 0.5 * kDesignW * c / s;
  const double base_baseline = kWallDisp * kWallDepth / focal_design_;
  baseline_ = base_baseline * params.disparity_scale;
  const auto depth_of = [&](double disp) { return focal_design_ * base_baseline / disp; };

  for (int i = 0; i < kNoiseSize * kNoiseSize; ++i)
    noise_[i] = static_cast<uint8_t>(rng.Next() >> 56);
  for (int t = 0; t < 256; ++t)
    fade_[t] = static_cast<uint8_t>((3 * t * t * 256 - 2 * t * t * t) >> 16);

  object_count_ = 0;
  uint32_t used_colors = 0;
  auto add = [&](Shape shape, double depth, double x, double y, double r0, double r1, double angle,
                 uint8_t pattern) -> Object& {
    Object& o = objects_[object_count_++];
    o = Object();
    o.shape = shape;
    o.depth = depth;
    o.cx = x;
    o.cy = y;
    o.r0 = r0;
    o.r1 = r1;
    o.angle_deg = angle;
    o.pattern = pattern;
    o.salt_x = rng.Int(256);
    o.salt_y = rng.Int(256);
    // A main colour no other object has, so neighbours differ at their shared edges.
    int32_t pick = rng.Int(kPaletteSize - (object_count_ - 1));
    int32_t index = 0;
    for (int32_t c = 0; c < kPaletteSize; ++c) {
      if (used_colors & (1u << c)) continue;
      if (pick-- == 0) {
        index = c;
        break;
      }
    }
    used_colors |= 1u << index;
    const uint8_t* a = kPalette[index];
    const uint8_t* b = kPalette[rng.Int(kPaletteSize)];
    for (int k = 0; k < 3; ++k) {
      o.color_a[k] = a[k];
      o.color_b[k] = static_cast<uint8_t>((a[k] + b[k] + 1) / 2);
    }
    return o;
  };
  auto set_colors = [](Object& o, uint8_t r, uint8_t g, uint8_t b, uint8_t r2, uint8_t g2,
                       uint8_t b2) {
    o.color_a[0] = r, o.color_a[1] = g, o.color_a[2] = b;
    o.color_b[0] = r2, o.color_b[1] = g2, o.color_b[2] = b2;
  };

  set_colors(add(Shape::kWall, kWallDepth, 0, 0, 0, 0, 0, 3), 112, 92, 80, 150, 118, 92);
  if (params.ground_plane) {
    // Camera height that puts the ground's bottom row at kGroundDisp.
    const double h = base_baseline * (0.5 * kDesignH) / kGroundDisp;
    set_colors(add(Shape::kGround, h, 0, 0, 0, 0, 0, 4), 92, 104, 78, 138, 128, 108);
  }
  // Front objects: nominal disparity (design px per step at disparity_scale 1), position
  // (design px from the centre), size and angle, jittered by the seed within bounds that keep
  // the depth order and the overlaps. Every draw is its own statement: the order of evaluation
  // of function arguments differs between compilers and targets.
  struct Spec {
    Shape shape;
    double disp, x, y, jx, jy, r0, r1, angle, jangle;
    bool scale_r0;  // false for the pole, whose length crosses the frame
    uint8_t pattern;
    bool optional;
  };
  const bool with_sign = rng.Int(2) == 0;  // the optional small board at the top right
  const uint8_t disc_pattern = rng.Int(3) == 0 ? 2 : 0;
  const Spec specs[] = {
      {Shape::kDisc, 2.5, -120, -40, 20, 20, 95, 0, 0, 0, true, disc_pattern, false},
      {Shape::kBox, 3.5, 225, -165, 15, 15, 52, 40, 0, 10, true, 0, true},
      {Shape::kBox, 4.5, 40, 30, 20, 15, 72, 112, 0, 8, true, 1, false},
      {Shape::kRing, 7.0, 190, -70, 15, 15, 70, 30, 0, 0, true, 2, false},
      {Shape::kBox, 9.5, -20, 0, 25, 0, 330, 5.5, 6, 4, false, 0, false},
      {Shape::kDisc, 12.0, -170, 92, 15, 10, 45, 0, 0, 0, true, 1, false},
  };
  for (const Spec& sp : specs) {
    if (sp.optional && !with_sign) continue;
    const double disp = sp.disp * rng.Range(0.93, 1.07);
    const double x = sp.x + rng.Range(-sp.jx, sp.jx);
    const double y = sp.y + rng.Range(-sp.jy, sp.jy);
    const double r0 = sp.scale_r0 ? sp.r0 * rng.Range(0.9, 1.1) : sp.r0;
    const double r1 = sp.r1 * rng.Range(0.9, 1.1);
    const double angle = sp.angle + rng.Range(-sp.jangle, sp.jangle);
    Object& o = add(sp.shape, depth_of(disp), x, y, r0, r1, angle, sp.pattern);
    if (!sp.scale_r0) set_colors(o, 78, 52, 36, 132, 96, 64);
  }

  // Nearest first: the z-test then rarely needs to look at an outline twice.
  int32_t n = 0;
  for (int32_t i = object_count_ - 1; i >= 0; --i)
    if (objects_[i].shape != Shape::kWall && objects_[i].shape != Shape::kGround) order_[n++] = i;
  for (int32_t i = 0; i < object_count_; ++i)
    if (objects_[i].shape == Shape::kGround) order_[n++] = i;
  order_[n++] = 0;

  light_count_ = 0;
  if (params.point_lights) {
    const int32_t count = 6 + rng.Int(3);
    for (int32_t i = 0; i < count; ++i) {
      const int64_t x = ToFixed(rng.Range(-300, 300), 8);
      const int64_t y = ToFixed(rng.Range(-230, -60), 8);
      lights_[light_count_++] = {x, y};
    }
  }
  // The depth midway (in inverse depth) between the wall and the nearest object.
  double rho_max = 1 / kWallDepth;
  for (int32_t i = 0; i < object_count_; ++i)
    if (objects_[i].shape != Shape::kGround && 1 / objects_[i].depth > rho_max)
      rho_max = 1 / objects_[i].depth;
  scene_depth_ = 2 / (rho_max + 1 / kWallDepth);
}

void Scene::BuildFixedPoint() {
  const double sx = width_ / kDesignW, sy = height_ / kDesignH;
  const double s = sx < sy ? sx : sy;
  px_per_design_ = s;
  intrinsics_.fx = intrinsics_.fy = focal_design_ * s;
  intrinsics_.cx = 0.5 * width_;
  intrinsics_.cy = 0.5 * height_;
  half_w_q16_ = int64_t{width_} << 15;
  half_h_q16_ = int64_t{height_} << 15;
  design_per_px_q24_ = ToFixed(1 / s, 24);
  disp_per_rho_q16_ = ToFixed(intrinsics_.fx * baseline_, 16);
  // The finest octave only where its cells span 2 px or more: below that a camera's optics
  // would blur it, and point-sampling it would alias.
  detail_octaves_ = 1.25 * s >= 2 ? 4 : 3;
  for (int32_t i = 0; i < object_count_; ++i) {
    Object& o = objects_[i];
    o.cx_q16 = ToFixed(0.5 * width_ + o.cx * s, 16);
    o.cy_q16 = ToFixed(0.5 * height_ + o.cy * s, 16);
    o.r0_q16 = ToFixed(o.r0 * s, 16);
    o.r0sq_q32 = ToFixed(o.r0 * s * o.r0 * s, 32);
    o.r1sq_q32 = ToFixed(o.r1 * s * o.r1 * s, 32);
    double sn, cs;
    SinCosDeg(o.angle_deg, &sn, &cs);
    o.cos_q15 = ToFixed(cs, 15);
    o.sin_q15 = ToFixed(sn, 15);
    o.half_len_q31 = ToFixed(o.r0 * s, 31);
    o.half_wid_q31 = ToFixed(o.r1 * s, 31);
    if (o.shape == Shape::kGround) {
      const double h_cm = o.depth * 100;
      ground_fh_q8_ = ToFixed(intrinsics_.fy * h_cm, 8);
      ground_h_q8_ = ToFixed(h_cm, 8);
      // The ground is hidden behind the wall above this row offset; half of it keeps the
      // texture's division away from the horizon.
      ground_vmin_q16_ = ToFixed(0.5 * intrinsics_.fy * o.depth / kWallDepth, 16);
    }
  }
}

// Turns `pose` so the reference point (0, 0, depth) lies on the view's optical axis: the
// rotation taking its direction a to b = (0, 0, 1), I + [v]x + [v]x^2 / (1 + a.b) with
// v = a x b (no trigonometry: the same bits everywhere).
static void TurnToward(double depth, ViewMotion* pose) {
  double q[3];
  for (int i = 0; i < 3; ++i) q[i] = pose->rotation[i][2] * depth + pose->translation[i];
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
  const double a[3] = {q[0] / n, q[1] / n, q[2] / n};
  const double v[3] = {a[1], -a[0], 0};  // a x (0, 0, 1)
  const double c = a[2];
  const double vx[3][3] = {{0, -v[2], v[1]}, {v[2], 0, -v[0]}, {-v[1], v[0], 0}};
  double r[3][3];
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      double sq = 0;
      for (int k = 0; k < 3; ++k) sq += vx[i][k] * vx[k][j];
      r[i][j] = (i == j ? 1.0 : 0.0) + vx[i][j] + sq / (1 + c);
    }
  }
  ViewMotion out;
  for (int i = 0; i < 3; ++i) {
    out.translation[i] = 0;
    for (int j = 0; j < 3; ++j) {
      out.rotation[i][j] = 0;
      for (int k = 0; k < 3; ++k) out.rotation[i][j] += r[i][k] * pose->rotation[k][j];
      out.translation[i] += r[i][j] * pose->translation[j];
    }
  }
  *pose = out;
}

Status Scene::BuildView(int32_t view) {
  ViewMotion& pose = poses_[view];
  pose = ViewMotion();
  if (params_.geometry == ViewGeometry::kRectified) {
    pose.translation[0] = -(view - reference_) * baseline_;
  } else if (view != reference_) {
    Rng rng{params_.seed * 0x2545F4914F6CDD1Dull + static_cast<uint64_t>(view) * 0x9E37ull + 7};
    double axis[3], dir[3];
    RandomUnit(rng, axis);
    // Magnitudes from the upper part of their range, and mostly sideways motion, as a burst
    // from a hand gives: enough parallax for depth in every view.
    const double angle_deg = rng.Range(0.3, 1) * params_.max_rotation_deg;
    double s, c;
    SinCosDeg(angle_deg, &s, &c);
    const double k[3][3] = {{0, -axis[2], axis[1]}, {axis[2], 0, -axis[0]}, {-axis[1], axis[0], 0}};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        pose.rotation[i][j] = (i == j ? c : 0) + s * k[i][j] + (1 - c) * axis[i] * axis[j];
    RandomUnit(rng, dir);
    dir[2] *= 0.3;
    const double norm = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    const double mag = rng.Range(0.5, 1) * params_.max_translation * scene_depth_ / norm;
    for (int i = 0; i < 3; ++i) pose.translation[i] = dir[i] * mag;
    if (params_.converge_m > 0) TurnToward(params_.converge_m, &pose);
  }

  const CameraIntrinsics& in = intrinsics_;
  const Mat3 k = {{in.fx, 0, in.cx}, {0, in.fy, in.cy}, {0, 0, 1}};
  const Mat3 k_inv = {{1 / in.fx, 0, -in.cx / in.fx}, {0, 1 / in.fy, -in.cy / in.fy}, {0, 0, 1}};
  for (int32_t i = 0; i < object_count_; ++i) {
    const Object& o = objects_[i];
    ViewMap& m = maps_[view][i];
    m = ViewMap();
    const double n[3] = {0, o.shape == Shape::kGround ? 1.0 : 0.0,
                         o.shape == Shape::kGround ? 0.0 : 1.0};
    const double d = o.depth;
    // Reference -> view for points on the plane n.X = d: K (R + t n^T / d) K^-1.
    Mat3 a, tmp, h_rv, h_vr;
    for (int r = 0; r < 3; ++r)
      for (int cidx = 0; cidx < 3; ++cidx)
        a[r][cidx] = pose.rotation[r][cidx] + pose.translation[r] * n[cidx] / d;
    Mul(k, a, tmp);
    Mul(tmp, k_inv, h_rv);
    if (!Invert(h_rv, h_vr))
      return Status(Code::kInternal, "synthetic scene: view %d object %d has a singular mapping",
                    view, i);
    // Inputs in half pixels; normalised so the denominator's constant is 1.
    const double w = h_vr[2][2];
    const double* rows[3] = {h_vr[0], h_vr[1], h_vr[2]};
    int64_t* outs[3] = {m.nx, m.ny, m.den};
    for (int r = 0; r < 3; ++r) {
      outs[r][0] = ToFixed(rows[r][0] * 0.5 / w, 40);
      outs[r][1] = ToFixed(rows[r][1] * 0.5 / w, 40);
      outs[r][2] = ToFixed(rows[r][2] / w, 40);
    }
    m.den[2] = kOne40;
    m.affine = m.den[0] == 0 && m.den[1] == 0;
    // Inverse depth along view rays: (n_v . K^-1 x) / d_v with n_v = R n, d_v = d + n_v . t.
    double nv[3];
    for (int r = 0; r < 3; ++r)
      nv[r] = pose.rotation[r][0] * n[0] + pose.rotation[r][1] * n[1] + pose.rotation[r][2] * n[2];
    const double dv =
        d + nv[0] * pose.translation[0] + nv[1] * pose.translation[1] + nv[2] * pose.translation[2];
    m.rho[0] = ToFixed(nv[0] / (2 * in.fx * dv), 40);
    m.rho[1] = ToFixed(nv[1] / (2 * in.fy * dv), 40);
    m.rho[2] = ToFixed((nv[2] - nv[0] * in.cx / in.fx - nv[1] * in.cy / in.fy) / dv, 40);

    if (o.shape == Shape::kWall || o.shape == Shape::kGround) continue;
    // Bounds: the outline's reference bounding box mapped into the view, plus a margin.
    const double sc = px_per_design_;
    double ex = o.r0 * sc, ey = o.r0 * sc;
    if (o.shape == Shape::kBox) {
      double sn, cs;
      SinCosDeg(o.angle_deg, &sn, &cs);
      ex = std::fabs(o.r0 * sn) * sc + std::fabs(o.r1 * cs) * sc;
      ey = std::fabs(o.r0 * cs) * sc + std::fabs(o.r1 * sn) * sc;
    }
    const double cx = 0.5 * width_ + o.cx * sc, cy = 0.5 * height_ + o.cy * sc;
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
    bool ok = true;
    for (int corner = 0; corner < 4; ++corner) {
      const double x = cx + ((corner & 1) ? ex : -ex), y = cy + ((corner & 2) ? ey : -ey);
      const double pw = h_rv[2][0] * x + h_rv[2][1] * y + h_rv[2][2];
      if (!(pw > 1e-9)) ok = false;
      const double p[2] = {(h_rv[0][0] * x + h_rv[0][1] * y + h_rv[0][2]) / pw,
                           (h_rv[1][0] * x + h_rv[1][1] * y + h_rv[1][2]) / pw};
      for (int q = 0; q < 2; ++q) {
        lo[q] = p[q] < lo[q] ? p[q] : lo[q];
        hi[q] = p[q] > hi[q] ? p[q] : hi[q];
      }
    }
    const double lim = 4.0 * kMaxSize;
    if (ok && lo[0] > -lim && hi[0] < lim && lo[1] > -lim && hi[1] < lim) {
      m.bounded = true;
      m.x0 = static_cast<int32_t>(std::floor(2 * lo[0])) - 4;
      m.x1 = static_cast<int32_t>(std::ceil(2 * hi[0])) + 4;
      m.y0 = static_cast<int32_t>(std::floor(2 * lo[1])) - 4;
      m.y1 = static_cast<int32_t>(std::ceil(2 * hi[1])) + 4;
    }
  }
  return Status::Ok();
}

double Scene::object_depth(int32_t i) const {
  const Object& o = objects_[i];
  if (o.shape == Shape::kGround) return intrinsics_.fy * o.depth / (0.5 * height_);
  return o.depth;
}

}  // namespace lb
