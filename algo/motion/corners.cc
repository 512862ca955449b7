#include "algo/motion/corners.h"

namespace lb {

Status CornerDetector::Carve(int32_t width, int32_t height, int32_t cell, Arena& arena) {
  if (cell < 4 || width < 2 * kBorder + cell || height < 2 * kBorder + cell) {
    return Status(Code::kInvalidArgument, "corners: %dx%d with %d px cells is too small", width,
                  height, cell);
  }
  width_ = width;
  height_ = height;
  cell_ = cell;
  cells_x_ = (width - 2 * kBorder) / cell;
  cells_y_ = (height - 2 * kBorder) / cell;
  ring_ = arena.Allocate<int32_t>(static_cast<size_t>(15) * width);
  best_ = arena.Allocate<Corner>(static_cast<size_t>(cells_x_) * cells_y_);
  return Status::Ok();
}

int32_t CornerDetector::Detect(const ConstImageU8& g, int64_t min_response, int32_t relative_div,
                               Corner* out) {
  const int32_t ncell = cells_x_ * cells_y_;
  for (int32_t i = 0; i < ncell; ++i) best_[i] = Corner{0, 0, -1};
  const int32_t x_end = kBorder + cells_x_ * cell_;
  const int32_t y_end = kBorder + cells_y_ * cell_;
  // Row r of gradient products feeds the box centred on r - 2; rows from kBorder - 2.
  for (int32_t r = kBorder - 2; r < y_end + 2; ++r) {
    int32_t* slot = ring_ + static_cast<size_t>(r % 5) * 3 * width_;
    int32_t* sxx = slot;
    int32_t* syy = slot + width_;
    int32_t* sxy = slot + 2 * width_;
    const uint8_t* up = g.Row(r - 1);
    const uint8_t* row = g.Row(r);
    const uint8_t* down = g.Row(r + 1);
    int32_t pxx[5] = {}, pyy[5] = {}, pxy[5] = {};
    int32_t axx = 0, ayy = 0, axy = 0;
    for (int32_t x = kBorder - 4; x < x_end + 2; ++x) {
      const int32_t dx = row[x + 1] - row[x - 1];
      const int32_t dy = down[x] - up[x];
      const int32_t k = (x + 8) % 5;
      axx += dx * dx - pxx[k];
      ayy += dy * dy - pyy[k];
      axy += dx * dy - pxy[k];
      pxx[k] = dx * dx;
      pyy[k] = dy * dy;
      pxy[k] = dx * dy;
      if (x >= kBorder) {  // the 5 products x-4..x are in: box centred on x - 2
        sxx[x - 2] = axx;
        syy[x - 2] = ayy;
        sxy[x - 2] = axy;
      }
    }
    const int32_t yc = r - 2;
    if (yc < kBorder) continue;
    const int32_t cy = (yc - kBorder) / cell_;
    for (int32_t x = kBorder; x < x_end; ++x) {
      int64_t a = 0, b = 0, c = 0;
      for (int32_t k = 0; k < 5; ++k) {
        const int32_t* s = ring_ + static_cast<size_t>(k) * 3 * width_;
        a += s[x];
        b += s[width_ + x];
        c += s[2 * width_ + x];
      }
      const int64_t trace = a + b;
      const int64_t resp = a * b - c * c - ((trace * trace) >> 4);
      Corner& best = best_[cy * cells_x_ + (x - kBorder) / cell_];
      if (resp > best.response) best = Corner{x, yc, resp};
    }
  }
  int64_t strongest = 0;
  for (int32_t i = 0; i < ncell; ++i)
    strongest = best_[i].response > strongest ? best_[i].response : strongest;
  const int64_t floor = strongest / (relative_div > 0 ? relative_div : 1);
  int32_t n = 0;
  for (int32_t i = 0; i < ncell; ++i) {
    if (best_[i].response >= min_response && best_[i].response >= floor) out[n++] = best_[i];
  }
  return n;
}

}  // namespace lb
