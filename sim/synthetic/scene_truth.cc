#include "sim/synthetic/scene.h"

#include <cstdint>

#include "algo/core/fixed_point.h"

// Ground truth of the reference view, with the same z-test as the renderer.

namespace lb {

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
