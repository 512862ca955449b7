#include "algo/motion/bundle.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "algo/core/clones.h"

namespace lb {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;

Mat3 Rot(const ViewMotion& m) { return Eigen::Map<const Mat3>(&m.rotation[0][0]); }

// a . b over three terms as Eigen's unrolled sum adds them (a0 b0 + (a1 b1 + a2 b2)), so that
// the products written out here give the bits the Eigen expressions gave.
inline double Dot3(double a0, double a1, double a2, double b0, double b1, double b2) {
  return a0 * b0 + (a1 * b1 + a2 * b2);
}

// Undistorted normalised coordinates of a distorted observation p: p (1 + k0 + k1 |p|^2).
Eigen::Vector2d Undistort(const double* p, double k1, double k0) {
  return Eigen::Vector2d(p[0], p[1]) * UndistortScale(k1, p[0], p[1], k0);
}

// Point on the reference ray through u (the point's undistorted reference observation) at
// inverse depth w, in view coordinates (up to scale); rr receives R r.
inline Vec3 Ray(const ViewMotion& m, double w, const Eigen::Vector2d& u, Vec3* rr) {
  const double(*r)[3] = m.rotation;
  for (int32_t i = 0; i < 3; ++i) (*rr)[i] = Dot3(r[i][0], r[i][1], r[i][2], u[0], u[1], 1.0);
  return *rr + w * Eigen::Map<const Vec3>(m.translation);
}

const double* Obs(const BundleInput& in, int32_t view, int32_t point) {
  return in.obs_xy + 2 * (static_cast<size_t>(view) * in.points + point);
}
bool ObsOk(const BundleInput& in, int32_t view, int32_t point) {
  return in.obs_ok[static_cast<size_t>(view) * in.points + point] != 0;
}

double Huber(double e2, double huber) {
  if (e2 <= huber * huber) return 0.5 * e2;
  return huber * (__builtin_sqrt(e2) - 0.5 * huber);
}

// Left update R <- Q(d) R with Q the rotation of the unit quaternion (1, d/2) / norm.
void RotateBy(const double d[3], ViewMotion* m) {
  double qw = 1, qx = 0.5 * d[0], qy = 0.5 * d[1], qz = 0.5 * d[2];
  const double n = __builtin_sqrt(qw * qw + qx * qx + qy * qy + qz * qz);
  qw /= n, qx /= n, qy /= n, qz /= n;
  Mat3 q;
  q << 1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw),
      2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw),
      2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy);
  Eigen::Map<Mat3>(&m->rotation[0][0]) = (q * Rot(*m)).eval();
}

// Small-angle rotation vector of R: vee((R - R^T) / 2), sin(angle) times the axis.
Vec3 AngleVector(const ViewMotion& m) {
  const double(*r)[3] = m.rotation;
  return Vec3(0.5 * (r[2][1] - r[1][2]), 0.5 * (r[0][2] - r[2][0]), 0.5 * (r[1][0] - r[0][1]));
}

double PriorCost(const BundleInput& in, const ViewMotion* motion, double k1, double k0) {
  const double reach = k1 * in.k1_reach_px, scale = k0 * in.k0_reach_px;
  double cost = 0.5 * in.k1_prior * reach * reach + 0.5 * in.k0_prior * scale * scale;
  if (in.rotation_prior > 0) {
    for (int32_t v = 0; v < in.views; ++v) {
      if (v == in.reference) continue;
      const double a = AngleVector(motion[v]).dot(Eigen::Map<const Vec3>(in.prior_axis));
      cost += 0.5 * in.rotation_prior * in.fx * in.fx * a * a;
    }
  }
  return cost;
}

// s -= scaled h^T on and below the diagonal of the nr x nr column-major s. Each entry is one
// product and one difference whatever the lanes (no contraction: -ffp-contract=off), so the
// AVX2 copy and the optimisation this file's -O2 leaves out give the same bits.
#if defined(__GNUC__) && !defined(__clang__)
#define LB_VECTORIZE __attribute__((optimize("tree-vectorize")))  // this file is built -O2
#else
#define LB_VECTORIZE
#endif
LB_CLONES_AVX2 LB_VECTORIZE void LowerUpdate(const double* __restrict h,
                                             const double* __restrict scaled, int32_t nr,
                                             double* __restrict s) {
  for (int32_t b = 0; b < nr; ++b) {
    double* col = s + static_cast<size_t>(nr) * b;
    const double hb = h[b];
    for (int32_t a = b; a < nr; ++a) col[a] -= hb * scaled[a];
  }
}
// LowerUpdate of two points at once, the first's difference before the second's: each entry is
// loaded and stored once for both.
LB_CLONES_AVX2 LB_VECTORIZE void LowerUpdate2(const double* __restrict h,
                                              const double* __restrict scaled,
                                              const double* __restrict h2,
                                              const double* __restrict scaled2, int32_t nr,
                                              double* __restrict s) {
  for (int32_t b = 0; b < nr; ++b) {
    double* col = s + static_cast<size_t>(nr) * b;
    const double hb = h[b], hb2 = h2[b];
    for (int32_t a = b; a < nr; ++a) col[a] = (col[a] - hb * scaled[a]) - hb2 * scaled2[a];
  }
}

// One observation's share of the normal equations: H += rw Jc^T Jc (camera block b, the
// column-major nc x 6 hcc at h), g -= rw Jc^T e, hcw += rw Jc^T jw. Written out so it inlines,
// in the order Eigen's products gave (each entry of rw Jc^T times a column summed over the two
// rows, then added): the same bits.
inline void AddObservation(const Eigen::Matrix<double, 2, 6>& jc, double rw,
                           const Eigen::Vector2d& e, const Eigen::Vector2d& jw, double* h,
                           int32_t nc, double* g, double* hcw) {
  double l0[6], l1[6];
  for (int32_t i = 0; i < 6; ++i) {
    l0[i] = rw * jc(0, i);
    l1[i] = rw * jc(1, i);
  }
  for (int32_t j = 0; j < 6; ++j) {
    double* col = h + static_cast<ptrdiff_t>(nc) * j;
    const double c0 = jc(0, j), c1 = jc(1, j);
    for (int32_t i = 0; i < 6; ++i) col[i] += l0[i] * c0 + l1[i] * c1;
  }
  for (int32_t i = 0; i < 6; ++i) g[i] -= l0[i] * e[0] + l1[i] * e[1];
  for (int32_t i = 0; i < 6; ++i) hcw[i] += l0[i] * jw[0] + l1[i] * jw[1];
}

// ErrorPx with the point's undistorted reference observation u given (the same in every view).
double Error(const BundleInput& in, const ViewMotion& m, double w, const Eigen::Vector2d& u,
             double k1, int32_t view, int32_t point, double k0) {
  Vec3 rr;
  const Vec3 a = Ray(m, w, u, &rr);
  // A point behind the view's camera (or at its centre) is no fit of the observation, however
  // its projection happens to fall: with signed inverse depths a step could otherwise flip
  // points through the camera into a fit that wanders off.
  if (!(a[2] > 1e-6 * rr.norm())) return Bundle::kBehindPx;
  const Eigen::Vector2d o = Undistort(Obs(in, view, point), k1, k0);
  const double ex = in.fx * (a[0] / a[2] - o[0]), ey = in.fy * (a[1] / a[2] - o[1]);
  // In px of the focal length the fit holds, fx / (1 + k0): the frames' own pixels.
  return __builtin_sqrt(ex * ex + ey * ey) / (1 + k0);
}

}  // namespace

Status Bundle::Carve(int32_t max_views, int32_t max_points, Arena& arena) {
  if (max_views < 2 || max_views > kMaxViews || max_points < 1) {
    return Status(Code::kInvalidArgument, "bundle: %d views (2..%d), %d points", max_views,
                  kMaxViews, max_points);
  }
  max_views_ = max_views;
  max_points_ = max_points;
  const size_t nc = 6 * static_cast<size_t>(max_views - 1), nr = nc + 2;
  hcc_ = arena.Allocate<double>(nc * 6);
  hck_ = arena.Allocate<double>(2 * nr);
  g_ = arena.Allocate<double>(nr);
  s_ = arena.Allocate<double>(nr * nr);
  g2_ = arena.Allocate<double>(nr);
  hww_ = arena.Allocate<double>(max_points);
  gw_ = arena.Allocate<double>(max_points);
  hcw_ = arena.Allocate<double>(nr * max_points);
  w_try_ = arena.Allocate<double>(max_points);
  return Status::Ok();
}

double Bundle::ErrorPx(const BundleInput& in, const ViewMotion& m, double w, double k1,
                       int32_t view, int32_t point, double k0) {
  return Error(in, m, w, Undistort(in.ref_xy + 2 * point, k1, k0), k1, view, point, k0);
}

double Bundle::Cost(const BundleInput& in, const ViewMotion* motion, const double* w, double k1,
                    double k0, double huber, int32_t* count) const {
  double cost = 0;
  int32_t n = 0;
  for (int32_t j = 0; j < in.points; ++j) {
    if (!in.point_ok[j]) continue;
    const Eigen::Vector2d u = Undistort(in.ref_xy + 2 * j, k1, k0);  // the same in every view
    for (int32_t v = 0; v < in.views; ++v) {
      if (v == in.reference || !ObsOk(in, v, j)) continue;
      const double e = Error(in, motion[v], w[j], u, k1, v, j, k0);
      cost += Huber(e * e, huber);
      ++n;
    }
  }
  if (count) *count = n;
  return cost;
}

Status Bundle::Solve(const BundleInput& in, int32_t max_iterations, double huber,
                     ViewMotion* motion, double* w, double* k1, double* k0, BundleReport* report) {
  if (in.views < 2 || in.views > max_views_ || in.points > max_points_ || in.reference < 0 ||
      in.reference >= in.views) {
    return Status(Code::kInvalidArgument, "bundle: %d views, %d points beyond the configuration",
                  in.views, in.points);
  }
  const int32_t nc = 6 * (in.views - 1);
  // The reduced system: the camera blocks, then k1 and k0 when they are estimated (at i1, i0).
  double kd = k1 ? *k1 : 0, kz = k0 ? *k0 : 0;
  const int32_t i1 = nc, i0 = nc + (k1 ? 1 : 0);
  const int32_t nr = i0 + (k0 ? 1 : 0);
  // Hcc is block diagonal (an observation involves one camera): kept as nc x 6 undamped blocks;
  // the lens rows are hck: row 0 for k1, row 1 for k0, each over all nr unknowns.
  Eigen::Map<Eigen::MatrixXd> hcc(hcc_, nc, 6);
  Eigen::Map<Eigen::Matrix<double, 2, Eigen::Dynamic>> hck(hck_, 2, nr);
  Eigen::Map<Eigen::VectorXd> g(g_, nr);
  Eigen::Map<Eigen::MatrixXd> s(s_, nr, nr);
  Eigen::Map<Eigen::VectorXd> g2(g2_, nr);
  // Camera block index of a view (the reference has none).
  auto block = [&](int32_t v) { return 6 * (v < in.reference ? v : v - 1); };
  int32_t count = 0;
  double cost = Cost(in, motion, w, kd, kz, huber, &count);
  *report = BundleReport{};
  report->observations = count;
  report->initial_rms_px = count ? __builtin_sqrt(2 * cost / count) : 0;
  if (count == 0) return Status(Code::kDegenerate, "bundle: no observations");
  cost += PriorCost(in, motion, kd, kz);
  double lambda = 1e-3;
  const double eps = 1e-12 * in.fx * in.fx;
  ViewMotion trial[kMaxViews];
  int32_t it = 0;
  for (; it < max_iterations; ++it) {
    // Normal equations of the IRLS-weighted problem; the point unknowns are eliminated below.
    hcc.setZero();
    hck.setZero();
    g.setZero();
    for (int32_t j = 0; j < in.points; ++j) {
      hww_[j] = 0;
      gw_[j] = 0;
      Eigen::Map<Eigen::VectorXd> hcw(hcw_ + static_cast<size_t>(nr) * j, nr);
      hcw.setZero();
      if (!in.point_ok[j]) continue;
      const double* rd = in.ref_xy + 2 * j;
      const double rd2 = rd[0] * rd[0] + rd[1] * rd[1];
      const Eigen::Vector2d u = Undistort(rd, kd, kz);
      for (int32_t v = 0; v < in.views; ++v) {
        if (v == in.reference || !ObsOk(in, v, j)) continue;
        Vec3 rr;
        const Vec3 a = Ray(motion[v], w[j], u, &rr);
        const double* od = Obs(in, v, j);
        const Eigen::Vector2d o = Undistort(od, kd, kz);
        const double iz = 1.0 / a[2];
        // Residuals in px of the focal length the fit holds (ErrorPx): scaled by c, so a focal
        // length that shrinks every normalised error is no gain in itself.
        const double c = 1 / (1 + kz);
        const Eigen::Vector2d e(c * in.fx * (a[0] * iz - o[0]), c * in.fy * (a[1] * iz - o[1]));
        const double en = e.norm();
        const double rw = en <= huber ? 1.0 : huber / en;
        Eigen::Matrix<double, 2, 3> ja;
        ja << in.fx * iz, 0, -in.fx * a[0] * iz * iz, 0, in.fy * iz, -in.fy * a[1] * iz * iz;
        ja *= c;
        Mat3 skew;  // d(R r)/dd = -[R r]x
        skew << 0, rr[2], -rr[1], -rr[2], 0, rr[0], rr[1], -rr[0], 0;
        Eigen::Matrix<double, 2, 6> jc;
        const double* t = motion[v].translation;
        Eigen::Vector2d jw;
        for (int32_t r = 0; r < 2; ++r) {
          for (int32_t k = 0; k < 3; ++k) {
            jc(r, k) = Dot3(ja(r, 0), ja(r, 1), ja(r, 2), skew(0, k), skew(1, k), skew(2, k));
            jc(r, 3 + k) = ja(r, k) * w[j];
          }
          jw[r] = Dot3(ja(r, 0), ja(r, 1), ja(r, 2), t[0], t[1], t[2]);
        }
        const int32_t b = block(v);
        AddObservation(jc, rw, e, jw, hcc_ + b, nc, g_ + b, hcw.data() + b);
        hww_[j] += rw * jw.squaredNorm();
        gw_[j] -= rw * jw.dot(e);
        if (k1 || k0) {
          // k1 moves the reference ray (R (rd |rd|^2, 0)) and the observation (od |od|^2), k0
          // the same without the |.|^2: a focal length a fraction off.
          const double od2 = od[0] * od[0] + od[1] * od[1];
          const Mat3 r = Rot(motion[v]);
          Eigen::Vector2d jk[2];
          jk[0] = ja * (r * Vec3(rd[0] * rd2, rd[1] * rd2, 0)) -
                  c * Eigen::Vector2d(in.fx * od[0] * od2, in.fy * od[1] * od2);
          // k0 also moves the residual's scale c: d(c E)/dk0 = c dE/dk0 - c e.
          jk[1] = ja * (r * Vec3(rd[0], rd[1], 0)) -
                  c * Eigen::Vector2d(in.fx * od[0], in.fy * od[1]) - c * e;
          const bool on[2] = {k1 != nullptr, k0 != nullptr};
          const int32_t at[2] = {i1, i0};
          for (int32_t e1 = 0; e1 < 2; ++e1) {
            if (!on[e1]) continue;
            hck.row(e1).segment<6>(b) += rw * (jc.transpose() * jk[e1]).transpose();
            for (int32_t e2 = 0; e2 < 2; ++e2) {
              if (on[e2]) hck(e1, at[e2]) += rw * jk[e1].dot(jk[e2]);
            }
            g[at[e1]] -= rw * jk[e1].dot(e);
            hcw[at[e1]] += rw * jk[e1].dot(jw);
          }
        }
      }
    }
    if (in.rotation_prior > 0) {
      // The left update d turns the angle vector by d (small angles).
      const double pw = in.rotation_prior * in.fx * in.fx;
      const Eigen::Map<const Vec3> axis(in.prior_axis);
      for (int32_t v = 0; v < in.views; ++v) {
        if (v == in.reference) continue;
        const int32_t b = block(v);
        hcc.block<3, 3>(b, 0) += pw * axis * axis.transpose();
        g.segment<3>(b) -= pw * AngleVector(motion[v]).dot(axis) * axis;
      }
    }
    if (k1 && in.k1_prior > 0) {
      const double pk = in.k1_prior * in.k1_reach_px * in.k1_reach_px;
      hck(0, i1) += pk;
      g[i1] -= pk * kd;
    }
    if (k0 && in.k0_prior > 0) {
      const double pk = in.k0_prior * in.k0_reach_px * in.k0_reach_px;
      hck(1, i0) += pk;
      g[i0] -= pk * kz;
    }
    bool accepted = false;
    for (int32_t tries = 0; tries < 10 && !accepted; ++tries) {
      // Damped reduced system S = Hcc - sum_j Hcw_j Hww_j^-1 Hwc_j (Marquardt: diagonal scaled).
      s.setZero();
      for (int32_t b = 0; b < nc; b += 6) s.block<6, 6>(b, b) = hcc.block<6, 6>(b, 0);
      if (k1) {
        s.col(i1) = hck.row(0).transpose();
        s.row(i1) = hck.row(0);
      }
      if (k0) {
        s.col(i0) = hck.row(1).transpose();
        s.row(i0) = hck.row(1);
      }
      for (int32_t k = 0; k < nr; ++k) s(k, k) = s(k, k) * (1 + lambda) + eps;
      g2 = g;
      // Only S's lower triangle: the Cholesky reads nothing else. Each entry as the full
      // outer product s -= (hcw / hd) hcw^T computes it, in the same order over the points.
      // Points in pairs (LowerUpdate2), the one left over alone.
      double scaled[2][kMaxReduced];
      const double* pending = nullptr;
      for (int32_t j = 0; j < in.points; ++j) {
        if (!in.point_ok[j]) continue;
        const double hd = hww_[j] * (1 + lambda) + eps;
        const double* h = hcw_ + static_cast<size_t>(nr) * j;
        double* sc = scaled[pending != nullptr ? 1 : 0];
        for (int32_t a = 0; a < nr; ++a) sc[a] = h[a] / hd;
        if (pending != nullptr) {
          LowerUpdate2(pending, scaled[0], h, sc, nr, s_);
          pending = nullptr;
        } else {
          pending = h;
        }
        Eigen::Map<const Eigen::VectorXd> hcw(h, nr);
        g2 -= hcw * (gw_[j] / hd);
      }
      if (pending != nullptr) LowerUpdate(pending, scaled[0], nr, s_);
      Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> llt(s);
      if (llt.info() != Eigen::Success) {
        lambda *= 10;
        continue;
      }
      llt.solveInPlace(g2);
      for (int32_t v = 0; v < in.views; ++v) {
        trial[v] = motion[v];
        if (v == in.reference) continue;
        const int32_t b = block(v);
        const double d[3] = {g2[b], g2[b + 1], g2[b + 2]};
        RotateBy(d, &trial[v]);
        for (int32_t k = 0; k < 3; ++k) trial[v].translation[k] += g2[b + 3 + k];
      }
      const double k_try = k1 ? kd + g2[i1] : kd;
      const double z_try = k0 ? kz + g2[i0] : kz;
      double sum = 0, sum_abs = 0;
      int32_t used = 0;
      for (int32_t j = 0; j < in.points; ++j) {
        w_try_[j] = w[j];
        if (!in.point_ok[j]) continue;
        const double hd = hww_[j] * (1 + lambda) + eps;
        Eigen::Map<const Eigen::VectorXd> hcw(hcw_ + static_cast<size_t>(nr) * j, nr);
        w_try_[j] = w[j] + (gw_[j] - hcw.dot(g2)) / hd;
        sum += w_try_[j];
        sum_abs += w_try_[j] < 0 ? -w_try_[j] : w_try_[j];
        ++used;
      }
      const double new_cost = Cost(in, trial, w_try_, k_try, z_try, huber, nullptr) +
                              PriorCost(in, trial, k_try, z_try);
      if (new_cost < cost) {
        accepted = true;
        const double rel = (cost - new_cost) / cost;
        cost = new_cost;
        kd = k_try;
        kz = z_try;
        lambda = lambda / 3 > 1e-9 ? lambda / 3 : 1e-9;
        // Gauge: mean |inverse depth| 1, and a mean >= 0 (w -> -w, t -> -t leaves every w t, so
        // every pixel, unchanged). Signed: at a narrow field of view a turn across the baseline
        // looks like an offset of every inverse depth, so the fit may put some points beyond
        // infinity; only differences of w matter downstream (auto_geometry.h).
        const double mean_abs = used ? sum_abs / used : 1;
        const double scale = (mean_abs > 1e-12 ? mean_abs : 1) * (sum < 0 ? -1 : 1);
        for (int32_t j = 0; j < in.points; ++j) w[j] = w_try_[j] / scale;
        for (int32_t v = 0; v < in.views; ++v) {
          motion[v] = trial[v];
          for (int32_t k = 0; k < 3; ++k) motion[v].translation[k] *= scale;
        }
        if (rel < in.min_gain) it = max_iterations;
      } else {
        lambda *= 4;
      }
    }
    if (!accepted) break;
  }
  if (k1) *k1 = kd;
  if (k0) *k0 = kz;
  report->iterations = it;
  report->rms_px = __builtin_sqrt(2 * Cost(in, motion, w, kd, kz, huber, nullptr) / count);
  return Status::Ok();
}

}  // namespace lb
