#include "algo/core/color.h"

#include "algo/core/fixed_point.h"

namespace lb {
namespace {

using fx::ClampU8;
using fx::FromDouble;
using fx::kQ15;

// JFIF (full range) RGB -> YCbCr, Q15.
constexpr int32_t kYr = FromDouble<kQ15>(0.299), kYg = FromDouble<kQ15>(0.587),
                  kYb = FromDouble<kQ15>(0.114);
constexpr int32_t kCbr = FromDouble<kQ15>(-0.168736), kCbg = FromDouble<kQ15>(-0.331264),
                  kCbb = FromDouble<kQ15>(0.5);
constexpr int32_t kCrr = FromDouble<kQ15>(0.5), kCrg = FromDouble<kQ15>(-0.418688),
                  kCrb = FromDouble<kQ15>(-0.081312);
// JFIF YCbCr -> RGB, Q15 (coefficients above 1 fit: int32 products stay below 2^24).
constexpr int32_t kRcr = FromDouble<kQ15>(1.402), kGcb = FromDouble<kQ15>(-0.344136),
                  kGcr = FromDouble<kQ15>(-0.714136), kBcb = FromDouble<kQ15>(1.772);
// BT.601 limited range YUV -> RGB, Q15 (the V4L2 default for YUV). Full range uses JFIF's.
constexpr int32_t kLy = FromDouble<kQ15>(255.0 / 219.0), kLrv = FromDouble<kQ15>(1.596027),
                  kLgu = FromDouble<kQ15>(-0.391762), kLgv = FromDouble<kQ15>(-0.812968),
                  kLbu = FromDouble<kQ15>(2.017232);
constexpr int32_t kHalf = 1 << (kQ15 - 1);

inline void LimitedYuvToRgb(int32_t y, int32_t u, int32_t v, uint8_t* rgb) {
  const int32_t yy = (y - 16) * kLy + kHalf;
  u -= 128;
  v -= 128;
  rgb[0] = ClampU8((yy + kLrv * v) >> kQ15);
  rgb[1] = ClampU8((yy + kLgu * u + kLgv * v) >> kQ15);
  rgb[2] = ClampU8((yy + kLbu * u) >> kQ15);
}

// The range is the row's, not the pixel's: one branch per row, and a loop per range the
// compiler can keep free of it.
template <typename Sample>
inline void YuvRowToRgb(YuvRange range, int32_t width, uint8_t* rgb, Sample sample) {
  int32_t y, u, v;
  if (range == YuvRange::kFull) {
    for (int32_t x = 0; x < width; ++x) {
      sample(x, &y, &u, &v);
      YCbCrToRgb8(y, u, v, rgb + 3 * x);
    }
  } else {
    for (int32_t x = 0; x < width; ++x) {
      sample(x, &y, &u, &v);
      LimitedYuvToRgb(y, u, v, rgb + 3 * x);
    }
  }
}

}  // namespace

void RowToRgb8(PixelFormat format, YuvRange range, const uint8_t* src, const uint8_t* u,
               const uint8_t* v, int32_t width, uint8_t* rgb) {
  switch (format) {
    case PixelFormat::kRgb8:
      for (int32_t i = 0; i < width * 3; ++i) rgb[i] = src[i];
      return;
    case PixelFormat::kBgr8:
      for (int32_t x = 0; x < width; ++x) {
        rgb[3 * x] = src[3 * x + 2];
        rgb[3 * x + 1] = src[3 * x + 1];
        rgb[3 * x + 2] = src[3 * x];
      }
      return;
    case PixelFormat::kGray8:
      for (int32_t x = 0; x < width; ++x) rgb[3 * x] = rgb[3 * x + 1] = rgb[3 * x + 2] = src[x];
      return;
    case PixelFormat::kGray16:
    case PixelFormat::kRgb16: {
      // 16-bit to 8-bit with rounding: (v * 255 + 32767) / 65535, exact for full-scale samples.
      const auto* s = reinterpret_cast<const uint16_t*>(src);
      const int32_t c = format == PixelFormat::kGray16 ? 1 : 3;
      for (int32_t x = 0; x < width; ++x) {
        for (int32_t k = 0; k < 3; ++k) {
          const uint32_t v = s[x * c + (c == 1 ? 0 : k)];
          rgb[3 * x + k] = static_cast<uint8_t>((v * 255u + 32767u) / 65535u);
        }
      }
      return;
    }
    case PixelFormat::kRgbx8:
    case PixelFormat::kBgrx8: {
      const int r = format == PixelFormat::kRgbx8 ? 0 : 2;
      for (int32_t x = 0; x < width; ++x) {
        rgb[3 * x] = src[4 * x + r];
        rgb[3 * x + 1] = src[4 * x + 1];
        rgb[3 * x + 2] = src[4 * x + 2 - r];
      }
      return;
    }
    case PixelFormat::kYuyv:
      YuvRowToRgb(range, width, rgb, [src](int32_t x, int32_t* y, int32_t* cb, int32_t* cr) {
        const uint8_t* p = src + (x / 2) * 4;
        *y = p[(x & 1) * 2];
        *cb = p[1];
        *cr = p[3];
      });
      return;
    case PixelFormat::kNv12:
      YuvRowToRgb(range, width, rgb, [src, u](int32_t x, int32_t* y, int32_t* cb, int32_t* cr) {
        *y = src[x];
        *cb = u[(x / 2) * 2];
        *cr = u[(x / 2) * 2 + 1];
      });
      return;
    case PixelFormat::kI420:
      YuvRowToRgb(range, width, rgb, [src, u, v](int32_t x, int32_t* y, int32_t* cb, int32_t* cr) {
        *y = src[x];
        *cb = u[x / 2];
        *cr = v[x / 2];
      });
      return;
  }
}

void RowRgb8ToY(const uint8_t* rgb, int32_t width, uint8_t* y) {
  for (int32_t x = 0; x < width; ++x) {
    const uint8_t* p = rgb + 3 * x;
    y[x] = ClampU8((kYr * p[0] + kYg * p[1] + kYb * p[2] + kHalf) >> kQ15);
  }
}

void RowsRgb8ToCbCr420(const uint8_t* rgb0, const uint8_t* rgb1, int32_t width, uint8_t* cb,
                       uint8_t* cr) {
  const int32_t cw = (width + 1) / 2;
  for (int32_t i = 0; i < cw; ++i) {
    const int32_t x0 = 2 * i, x1 = (2 * i + 1 < width) ? 2 * i + 1 : 2 * i;
    int32_t sum[3];
    for (int k = 0; k < 3; ++k) {
      sum[k] = rgb0[3 * x0 + k] + rgb0[3 * x1 + k] + rgb1[3 * x0 + k] + rgb1[3 * x1 + k];
    }
    // Sums are 4x the mean: fold the /4 into the final shift (Q15 + 2 bits).
    const int32_t half = 1 << (kQ15 + 1);
    cb[i] = ClampU8(((kCbr * sum[0] + kCbg * sum[1] + kCbb * sum[2] + half) >> (kQ15 + 2)) + 128);
    cr[i] = ClampU8(((kCrr * sum[0] + kCrg * sum[1] + kCrb * sum[2] + half) >> (kQ15 + 2)) + 128);
  }
}

void YCbCrToRgb8(int32_t y, int32_t cb, int32_t cr, uint8_t* rgb) {
  const int32_t yy = (y << kQ15) + kHalf;
  cb -= 128;
  cr -= 128;
  rgb[0] = ClampU8((yy + kRcr * cr) >> kQ15);
  rgb[1] = ClampU8((yy + kGcb * cb + kGcr * cr) >> kQ15);
  rgb[2] = ClampU8((yy + kBcb * cb) >> kQ15);
}

}  // namespace lb
