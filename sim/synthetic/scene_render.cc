#include "sim/synthetic/scene.h"

#include <cstdint>

#include "algo/core/fixed_point.h"

// The per-pixel path, of the views and of their ground truth: integer arithmetic only, so every
// target renders the same bytes.

namespace lb {
namespace {

// Floor division and modulo for a positive divisor.
int64_t FloorDiv(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }
int64_t FloorMod(int64_t a, int64_t b) { return a - FloorDiv(a, b) * b; }

uint32_t Hash2(int64_t a, int64_t b) {
  uint64_t h = static_cast<uint64_t>(a) * 0x9E3779B97F4A7C15ull ^ static_cast<uint64_t>(b);
  h = (h ^ (h >> 29)) * 0xBF58476D1CE4E5B9ull;
  return static_cast<uint32_t>(h >> 32);
}

// Noise octaves: colour blotches, then detail. Each octave's lattice is turned by its own
// Pythagorean angle (a/h, b/h) so the octaves' grids do not line up into visible squares, and
// scaled by 1 / (cell * h), cells in design px (cm on the ground, twice as large). The turn
// and the scale are folded into two Q16 factors: ca = a * inv, cb = b * inv.
struct Octave {
  int32_t ca, cb;
};
constexpr Octave MakeOctave(int32_t a, int32_t b, int32_t inv_q16) {
  return {a * inv_q16, b * inv_q16};
}
// [0] objects, [1] ground; octave 0 is the colour mix, 4 the 1.25 px octave of high resolutions.
constexpr Octave kOctaves[2][5] = {
    {MakeOctave(1, 0, 65536 / 56), MakeOctave(4, 3, 65536 / (20 * 5)),
     MakeOctave(12, 5, 65536 / (7 * 13)), MakeOctave(15, 8, 65536 / (3 * 17)),
     MakeOctave(21, 20, 65536 * 4 / (5 * 29))},
    {MakeOctave(1, 0, 65536 / 112), MakeOctave(4, 3, 65536 / (40 * 5)),
     MakeOctave(12, 5, 65536 / (14 * 13)), MakeOctave(15, 8, 65536 / (6 * 17)),
     MakeOctave(21, 20, 65536 * 2 / (5 * 29))},
};
// Detail weights with three and with four octaves; each set sums to 16.
constexpr int32_t kDetailWeights[2][4] = {{7, 5, 4, 0}, {6, 5, 3, 2}};

// Value noise: smoothstep-weighted bilinear lattice values, 0..65280 (Q8 of 0..255).
[[gnu::always_inline]] inline int32_t Noise(const uint8_t* lattice, const uint8_t* fade,
                                            int32_t size, int64_t u_q8, int64_t v_q8,
                                            const Octave& oct, int32_t sx, int32_t sy) {
  const int64_t lu = (u_q8 * oct.ca - v_q8 * oct.cb) >> 16;  // Q8 cells
  const int64_t lv = (u_q8 * oct.cb + v_q8 * oct.ca) >> 16;
  const int32_t mask = size - 1;
  const int32_t iu = static_cast<int32_t>((lu >> 8) + sx) & mask;
  const int32_t iv = static_cast<int32_t>((lv >> 8) + sy) & mask;
  const int32_t wu = fade[lu & 255], wv = fade[lv & 255];
  const uint8_t* r0 = lattice + iv * size;
  const uint8_t* r1 = lattice + ((iv + 1) & mask) * size;
  const int32_t iu1 = (iu + 1) & mask;
  const int32_t top = r0[iu] * (256 - wu) + r0[iu1] * wu;  // Q8
  const int32_t bot = r1[iu] * (256 - wu) + r1[iu1] * wu;
  return (top * (256 - wv) + bot * wv) >> 8;
}

// The detail octaves with compile-time constants, so the factors fold into the code.
template <int kCount, int kGround>
int32_t Detail(const uint8_t* lattice, const uint8_t* fade, int32_t size, int64_t u_q8,
               int64_t v_q8, int32_t sx, int32_t sy) {
  int32_t sum = 0;
  for (int k = 1; k <= kCount; ++k)
    sum += kDetailWeights[kCount - 3][k - 1] *
           Noise(lattice, fade, size, u_q8, v_q8, kOctaves[kGround][k], sx + 61 * k, sy + 97 * k);
  return sum >> 12;  // 0..255, mostly 90..170
}

}  // namespace

void Scene::PrepareRow(const ViewMap* maps, int32_t y2, RowState* row) const {
  for (int32_t i = 0; i < object_count_; ++i) {
    const ViewMap& m = maps[i];
    row->obj[i] = {m.nx[1] * y2 + m.nx[2], m.ny[1] * y2 + m.ny[2], m.den[1] * y2 + m.den[2],
                   m.rho[1] * y2 + m.rho[2]};
  }
  row->active_count = 0;
  for (int32_t k = 0; k < object_count_; ++k) {
    const ViewMap& m = maps[order_[k]];
    if (!m.bounded || (y2 >= m.y0 && y2 <= m.y1)) row->active[row->active_count++] = order_[k];
  }
}

void Scene::RefPoint(const ViewMap& m, const RowMap& r, int32_t x2, int64_t* xr_q16,
                     int64_t* yr_q16) const {
  const int64_t nx = m.nx[0] * x2 + r.nx;  // Q40
  const int64_t ny = m.ny[0] * x2 + r.ny;
  if (m.affine) {
    *xr_q16 = fx::RoundShift<int64_t>(nx, 24);
    *yr_q16 = fx::RoundShift<int64_t>(ny, 24);
    return;
  }
  // Q40 / Q24 -> Q16; the denominator stays within a few percent of 1 for the allowed motion.
  int64_t den_q24 = fx::RoundShift<int64_t>(m.den[0] * x2 + r.den, 16);
  if (den_q24 < (int64_t{1} << 20)) den_q24 = int64_t{1} << 20;
  *xr_q16 = nx / den_q24;
  *yr_q16 = ny / den_q24;
}

bool Scene::Inside(const Object& o, int64_t xr_q16, int64_t yr_q16) const {
  const int64_t dx = xr_q16 - o.cx_q16, dy = yr_q16 - o.cy_q16;
  if (o.shape == Shape::kBox) {
    const int64_t along = dx * o.sin_q15 + dy * o.cos_q15;  // Q31
    const int64_t across = dx * o.cos_q15 - dy * o.sin_q15;
    return along <= o.half_len_q31 && along >= -o.half_len_q31 && across <= o.half_wid_q31 &&
           across >= -o.half_wid_q31;
  }
  // A point far outside (a steep view can map there) must not overflow the squares.
  if (dx > o.r0_q16 || dx < -o.r0_q16 || dy > o.r0_q16 || dy < -o.r0_q16) return false;
  const int64_t d2 = dx * dx + dy * dy;  // Q32
  if (d2 > o.r0sq_q32) return false;
  return o.shape != Shape::kRing || d2 >= o.r1sq_q32;
}

int32_t Scene::Winner(const ViewMap* maps, const RowState& row, int32_t x2,
                      int64_t* rho_q40) const {
  int32_t best = 0;
  int64_t best_rho = 0;  // nothing behind the camera
  for (int32_t k = 0; k < row.active_count; ++k) {
    const int32_t i = row.active[k];
    const ViewMap& m = maps[i];
    if (m.bounded && (x2 < m.x0 || x2 > m.x1)) continue;
    const int64_t rho = m.rho[0] * x2 + row.obj[i].rho;
    if (rho <= best_rho) continue;
    const Object& o = objects_[i];
    if (o.shape != Shape::kWall && o.shape != Shape::kGround) {
      int64_t xr, yr;
      RefPoint(m, row.obj[i], x2, &xr, &yr);
      if (!Inside(o, xr, yr)) continue;
    }
    best = i;
    best_rho = rho;
  }
  *rho_q40 = best_rho;
  return best;
}

void Scene::Shade(int32_t index, int64_t xr_q16, int64_t yr_q16, int32_t* rgb) const {
  const Object& o = objects_[index];
  int64_t u, v;  // texture coordinates, Q8: design px, or cm on the ground
  const bool ground = o.shape == Shape::kGround;
  if (ground) {
    // Plane coordinates: Z = f h / dy and X = dx h / dy, with one division for both.
    int64_t dy_q16 = yr_q16 - half_h_q16_;
    if (dy_q16 < ground_vmin_q16_) dy_q16 = ground_vmin_q16_;
    const int64_t inv_q32 = (int64_t{1} << 48) / dy_q16;  // 1 / dy px
    // |dx / dy| <= 64 keeps the product in range; only a steep view's edge reaches the limit.
    int64_t dx_q16 = xr_q16 - half_w_q16_;
    if (dx_q16 > (dy_q16 << 6)) dx_q16 = dy_q16 << 6;
    if (dx_q16 < -(dy_q16 << 6)) dx_q16 = -(dy_q16 << 6);
    const int64_t ratio_q24 = (dx_q16 * inv_q32) >> 24;
    u = (ratio_q24 * ground_h_q8_) >> 24;
    v = (ground_fh_q8_ * inv_q32) >> 32;
  } else {
    u = ((xr_q16 - half_w_q16_) * design_per_px_q24_) >> 32;
    v = ((yr_q16 - half_h_q16_) * design_per_px_q24_) >> 32;
  }
  const int g = ground ? 1 : 0;
  const int32_t mix =
      Noise(noise_, fade_, kNoiseSize, u, v, kOctaves[g][0], o.salt_x, o.salt_y) >> 8;
  int32_t detail;
  if (detail_octaves_ == 4)
    detail = ground ? Detail<4, 1>(noise_, fade_, kNoiseSize, u, v, o.salt_x, o.salt_y)
                    : Detail<4, 0>(noise_, fade_, kNoiseSize, u, v, o.salt_x, o.salt_y);
  else
    detail = ground ? Detail<3, 1>(noise_, fade_, kNoiseSize, u, v, o.salt_x, o.salt_y)
                    : Detail<3, 0>(noise_, fade_, kNoiseSize, u, v, o.salt_x, o.salt_y);
  int32_t gain_q8 = 64 + detail * 3 / 2;  // about 0.75..1.25
  int32_t base[3];
  for (int c = 0; c < 3; ++c)
    base[c] = (o.color_a[c] * (255 - mix) + o.color_b[c] * mix + 127) / 255;

  const int64_t ui = u >> 8, vi = v >> 8;  // whole design px (cm on the ground)
  switch (o.pattern) {
    case 1:  // checker of 24 px squares
      if ((FloorDiv(ui, 24) + FloorDiv(vi, 24)) & 1)
        for (int c = 0; c < 3; ++c) base[c] = base[c] * 3 / 5;
      break;
    case 2:  // diagonal stripes
      if (FloorDiv(ui + vi, 14) & 1) gain_q8 = gain_q8 * 7 / 10;
      break;
    case 3: {  // bricks 40 x 16 with 2 px mortar and a tint per brick
      const int64_t row = FloorDiv(vi, 16);
      const int64_t uu = ui + (row & 1) * 20;
      if (FloorMod(vi, 16) < 2 || FloorMod(uu, 40) < 2) {
        base[0] = 150, base[1] = 146, base[2] = 138;
      } else {
        const int32_t tint = static_cast<int32_t>(Hash2(row, FloorDiv(uu, 40)) >> 27) - 16;
        for (int c = 0; c < 3; ++c) base[c] += tint;
      }
      break;
    }
    case 4:  // floor tiles of 40 cm with 1.5 cm grout
      if (FloorMod(u, 40 * 256) < 384 || FloorMod(v, 40 * 256) < 384)
        base[0] = base[1] = base[2] = 60;
      break;
    default:
      break;
  }
  for (int c = 0; c < 3; ++c) rgb[c] = (base[c] * gain_q8 + 128) >> 8;

  if (o.shape == Shape::kWall) {
    // Point lights: a saturated core of 2.2 design px and a glow out to 6 px.
    constexpr int64_t kCore2 = 317194;  // 2.2^2 in Q16
    constexpr int64_t kGlow2 = 6 * 256 * 6 * 256;
    for (int32_t i = 0; i < light_count_; ++i) {
      const int64_t dx = u - lights_[i].x_q8, dy = v - lights_[i].y_q8;
      if (dx > 6 * 256 || dx < -6 * 256 || dy > 6 * 256 || dy < -6 * 256) continue;
      const int64_t d2 = dx * dx + dy * dy;
      if (d2 >= kGlow2) continue;
      const int32_t t_q8 =
          d2 <= kCore2 ? 256 : static_cast<int32_t>(((kGlow2 - d2) << 8) / (kGlow2 - kCore2));
      const int32_t w_q8 = t_q8 * t_q8 >> 8;
      const int32_t light[3] = {255, 252, 240};
      for (int c = 0; c < 3; ++c) rgb[c] += ((light[c] - rgb[c]) * w_q8) >> 8;
    }
  }
}

Status Scene::RenderRows(int32_t view, int32_t y0, int32_t rows, uint8_t* out_rgb8,
                         ptrdiff_t stride) {
  if (width_ == 0) return Status(Code::kInvalidArgument, "synthetic scene: not configured");
  if (view < 0 || view >= views_)
    return Status(Code::kInvalidArgument, "synthetic scene: view %d not among %d", view, views_);
  if (y0 < 0 || rows < 0 || y0 + rows > height_)
    return Status(Code::kInvalidArgument, "synthetic scene: rows %d..%d outside 0..%d", y0,
                  y0 + rows, height_);
  if (rows > 0 && (out_rgb8 == nullptr || stride < ptrdiff_t{width_} * 3))
    return Status(Code::kInvalidArgument, "synthetic scene: output stride %td below %d bytes",
                  stride, width_ * 3);
  const ViewMap* maps = maps_[view];
  RowState corner_row, centre_row;
  uint8_t* top = corner_rows_.data();
  uint8_t* bottom = top + width_ + 1;
  int64_t rho;
  // Anti-aliasing: the visible object is found at the four pixel corners (shared with the
  // neighbours), and the pixel averages the texture of each corner's object at its centre.
  auto fill_corners = [&](int32_t y, uint8_t* ids) {
    PrepareRow(maps, 2 * y, &corner_row);
    for (int32_t x = 0; x <= width_; ++x)
      ids[x] = static_cast<uint8_t>(Winner(maps, corner_row, 2 * x, &rho));
  };
  if (rows > 0) fill_corners(y0, top);
  for (int32_t y = y0; y < y0 + rows; ++y) {
    fill_corners(y + 1, bottom);
    PrepareRow(maps, 2 * y + 1, &centre_row);
    uint8_t* out = out_rgb8 + (y - y0) * stride;
    for (int32_t x = 0; x < width_; ++x, out += 3) {
      const uint8_t ids[4] = {top[x], top[x + 1], bottom[x], bottom[x + 1]};
      if (ids[0] == ids[1] && ids[0] == ids[2] && ids[0] == ids[3]) {
        int64_t xr, yr;
        RefPoint(maps[ids[0]], centre_row.obj[ids[0]], 2 * x + 1, &xr, &yr);
        int32_t rgb[3];
        Shade(ids[0], xr, yr, rgb);
        for (int c = 0; c < 3; ++c) out[c] = fx::ClampU8(rgb[c]);
        continue;
      }
      int32_t acc[3] = {0, 0, 0};
      int32_t done = 0;  // bit mask of the objects already shaded
      for (int k = 0; k < 4; ++k) {
        const int32_t i = ids[k];
        if (done & (1 << i)) continue;
        done |= 1 << i;
        int32_t count = 0;
        for (int q = k; q < 4; ++q) count += ids[q] == i;
        int64_t xr, yr;
        RefPoint(maps[i], centre_row.obj[i], 2 * x + 1, &xr, &yr);
        int32_t rgb[3];
        Shade(i, xr, yr, rgb);
        for (int c = 0; c < 3; ++c) acc[c] += count * rgb[c];
      }
      for (int c = 0; c < 3; ++c) out[c] = fx::ClampU8((acc[c] + 2) >> 2);
    }
    uint8_t* t = top;
    top = bottom;
    bottom = t;
  }
  return Status::Ok();
}

// Ground truth of the reference view, with the same z-test as the renderer.

Status Scene::CheckTruthArgs(int32_t scale, int32_t y0, int32_t rows, const void* out,
                             ptrdiff_t stride) const {
  if (width_ == 0) return Status(Code::kInvalidArgument, "synthetic scene: not configured");
  if (scale < 1 || width_ / scale < 1 || height_ / scale < 1)
    return Status(Code::kInvalidArgument, "synthetic scene: scale %d does not fit %dx%d", scale,
                  width_, height_);
  if (y0 < 0 || rows < 0 || y0 + rows > height_ / scale)
    return Status(Code::kInvalidArgument, "synthetic scene: truth rows %d..%d outside 0..%d", y0,
                  y0 + rows, height_ / scale);
  if (rows > 0 && (out == nullptr || stride < width_ / scale))
    return Status(Code::kInvalidArgument, "synthetic scene: truth stride %td below %d", stride,
                  width_ / scale);
  return Status::Ok();
}

template <typename Fn>
void Scene::ForEachTruthSample(int32_t view, int32_t scale, int32_t y0, int32_t rows,
                               Fn&& fn) const {
  const ViewMap* maps = maps_[view];
  RowState row;
  for (int32_t y = y0; y < y0 + rows; ++y) {
    PrepareRow(maps, (2 * y + 1) * scale, &row);
    for (int32_t x = 0; x < width_ / scale; ++x) {
      int64_t rho;
      const int32_t object = Winner(maps, row, (2 * x + 1) * scale, &rho);
      fn(x, y, object, rho);
    }
  }
}

Status Scene::DisparityRows(int32_t scale, int32_t y0, int32_t rows, uint16_t* out_q8,
                            ptrdiff_t stride) const {
  LB_RETURN_IF_ERROR(CheckTruthArgs(scale, y0, rows, out_q8, stride));
  ForEachTruthSample(reference_, scale, y0, rows, [&](int32_t x, int32_t y, int32_t, int64_t rho) {
    out_q8[(y - y0) * stride + x] = static_cast<uint16_t>(DispQ8(rho, scale));
  });
  return Status::Ok();
}

Status Scene::InverseDepthRows(int32_t scale, int32_t y0, int32_t rows, uint16_t* out_q12,
                               ptrdiff_t stride) const {
  LB_RETURN_IF_ERROR(CheckTruthArgs(scale, y0, rows, out_q12, stride));
  ForEachTruthSample(reference_, scale, y0, rows, [&](int32_t x, int32_t y, int32_t, int64_t rho) {
    out_q12[(y - y0) * stride + x] = fx::Saturate<uint16_t>(fx::RoundShift<int64_t>(rho, 28));
  });
  return Status::Ok();
}

Status Scene::ObjectRows(int32_t view, int32_t scale, int32_t y0, int32_t rows, uint8_t* out,
                         ptrdiff_t stride) const {
  LB_RETURN_IF_ERROR(CheckTruthArgs(scale, y0, rows, out, stride));
  if (view < 0 || view >= views_)
    return Status(Code::kInvalidArgument, "synthetic scene: view %d not among %d", view, views_);
  ForEachTruthSample(view, scale, y0, rows, [&](int32_t x, int32_t y, int32_t object, int64_t) {
    out[(y - y0) * stride + x] = static_cast<uint8_t>(object);
  });
  return Status::Ok();
}

// Q24 (1/m) x Q16 (px per 1/m) -> Q40, / scale, -> Q8: the arithmetic of DisparityRows.
int32_t Scene::DispQ8(int64_t rho_q40, int32_t scale) const {
  const int64_t q40 = ((rho_q40 >> 16) * disp_per_rho_q16_) / scale;
  return fx::Saturate<uint16_t>(fx::RoundShift<int64_t>(q40, 32));
}

// The wall is the farthest visible surface.
int64_t Scene::RhoMinQ40() const { return maps_[reference_][0].rho[2]; }

int64_t Scene::RhoMaxQ40() const {
  int64_t rho_max = 0;
  const ViewMap* maps = maps_[reference_];
  for (int32_t i = 0; i < object_count_; ++i) {
    // Fronto-parallel planes have a constant inverse depth; the ground's peaks at the bottom.
    const int64_t rho = maps[i].rho[1] * (2 * height_) + maps[i].rho[2];
    if (rho > rho_max) rho_max = rho;
  }
  return rho_max;
}

int32_t Scene::disparity_min_q8(int32_t scale) const { return DispQ8(RhoMinQ40(), scale); }
int32_t Scene::disparity_max_q8(int32_t scale) const { return DispQ8(RhoMaxQ40(), scale); }
int32_t Scene::inverse_depth_min_q12() const {
  return fx::Saturate<uint16_t>(fx::RoundShift<int64_t>(RhoMinQ40(), 28));
}
int32_t Scene::inverse_depth_max_q12() const {
  return fx::Saturate<uint16_t>(fx::RoundShift<int64_t>(RhoMaxQ40(), 28));
}

double Scene::disparity_min(int32_t scale) const { return disparity_min_q8(scale) / 256.0; }
double Scene::disparity_max(int32_t scale) const { return disparity_max_q8(scale) / 256.0; }

}  // namespace lb
