#include "algo/motion/pyramid.h"

#include "algo/core/color.h"

namespace lb {

Status GreyPyramid::Carve(int32_t width, int32_t height, int32_t levels, Arena& arena) {
  if (levels < 1 || levels > kMaxLevels) {
    return Status(Code::kInvalidArgument, "pyramid: %d levels (1..%d)", levels, kMaxLevels);
  }
  if ((width >> (levels - 1)) < 8 || (height >> (levels - 1)) < 8) {
    return Status(Code::kInvalidArgument, "pyramid: %dx%d too small for %d levels", width, height,
                  levels);
  }
  levels_ = levels;
  grey_ = arena.AllocateImage<uint8_t>(width, height);
  for (int32_t i = 0; i < levels; ++i) {
    level_[i] = arena.AllocateImage<uint8_t>(width >> i, height >> i);
  }
  return Status::Ok();
}

Status GreyPyramid::Build(const ConstImageU8& view) {
  const ImageU8& l0 = level_[0];
  if (view.width != l0.width || view.height != l0.height ||
      (view.channels != 1 && view.channels != 3)) {
    return Status(Code::kInvalidArgument, "pyramid: view %dx%dx%d, expected %dx%d grey or RGB8",
                  view.width, view.height, view.channels, l0.width, l0.height);
  }
  for (int32_t y = 0; y < l0.height; ++y) {
    if (view.channels == 3) {
      RowRgb8ToY(view.Row(y), l0.width, grey_.Row(y));
    } else {
      const uint8_t* s = view.Row(y);
      uint8_t* d = grey_.Row(y);
      for (int32_t x = 0; x < l0.width; ++x) d[x] = s[x];
    }
  }
  // 3x3 binomial [1 2 1]^2 / 16, edges replicated: rounded sum of weights 16, no overflow.
  const int32_t w = l0.width, h = l0.height;
  for (int32_t y = 0; y < h; ++y) {
    const uint8_t* a = grey_.Row(y > 0 ? y - 1 : 0);
    const uint8_t* b = grey_.Row(y);
    const uint8_t* c = grey_.Row(y + 1 < h ? y + 1 : h - 1);
    uint8_t* d = l0.Row(y);
    auto col = [&](int32_t x) { return a[x] + 2 * b[x] + c[x]; };
    int32_t left = col(0), mid = left;
    for (int32_t x = 0; x < w; ++x) {
      const int32_t right = col(x + 1 < w ? x + 1 : w - 1);
      d[x] = static_cast<uint8_t>((left + 2 * mid + right + 8) >> 4);
      left = mid;
      mid = right;
    }
  }
  for (int32_t i = 1; i < levels_; ++i) {
    const ImageU8& src = level_[i - 1];
    const ImageU8& dst = level_[i];
    for (int32_t y = 0; y < dst.height; ++y) {
      const uint8_t* a = src.Row(2 * y);
      const uint8_t* b = src.Row(2 * y + 1);
      uint8_t* d = dst.Row(y);
      for (int32_t x = 0; x < dst.width; ++x) {
        d[x] = static_cast<uint8_t>((a[2 * x] + a[2 * x + 1] + b[2 * x] + b[2 * x + 1] + 2) >> 2);
      }
    }
  }
  return Status::Ok();
}

int32_t SharpnessQ4(const ConstImageU8& g) {
  int64_t sum = 0;
  int64_t count = 0;
  for (int32_t y = 1; y + 1 < g.height; ++y) {
    const uint8_t* up = g.Row(y - 1);
    const uint8_t* row = g.Row(y);
    const uint8_t* down = g.Row(y + 1);
    for (int32_t x = 1; x + 1 < g.width; ++x) {
      const int32_t dx = row[x + 1] - row[x - 1];
      const int32_t dy = down[x] - up[x];
      sum += (dx < 0 ? -dx : dx) + (dy < 0 ? -dy : dy);
    }
    count += g.width - 2;
  }
  return count > 0 ? static_cast<int32_t>((sum * 16 + count / 2) / count) : 0;
}

}  // namespace lb
