#include "tests/algo/render/reference_render.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "algo/core/color.h"

namespace lb::test {
namespace {

// Shape test written independently of the product's: a disc, or a regular polygon (blades
// normals at rotation + i * 360 / n) blended radially towards the circle by the curvature.
bool Inside(const Aperture& a, double x, double y, double r) {
  const double d = std::sqrt(x * x + y * y);
  if (a.blades < 3 || a.curvature >= 1.0f) return d <= r;
  if (d == 0.0) return true;
  const double pi = 3.14159265358979323846;
  double best = -1.0;
  for (int i = 0; i < a.blades; ++i) {
    const double t = (a.rotation_deg + 360.0 * i / a.blades) * pi / 180.0;
    best = std::max(best, (x * std::cos(t) + y * std::sin(t)) / d);
  }
  const double poly = r * std::cos(pi / a.blades) / best;
  return d <= (1.0 - a.curvature) * poly + a.curvature * r;
}

struct Kernel {
  int32_t half = 0;
  std::vector<float> w;  // (2 half + 1)^2, sums to 1
};

Kernel MakeKernel(const Aperture& a, double r) {
  Kernel k;
  if (r < 0.5) {
    k.w = {1.0f};
    return k;
  }
  k.half = static_cast<int32_t>(std::ceil(r + 0.5));
  const int32_t n = 2 * k.half + 1;
  k.w.assign(static_cast<size_t>(n) * n, 0.0f);
  double total = 0;
  constexpr int kS = 8;
  for (int32_t dy = -k.half; dy <= k.half; ++dy) {
    for (int32_t dx = -k.half; dx <= k.half; ++dx) {
      int count = 0;
      for (int sy = 0; sy < kS; ++sy) {
        for (int sx = 0; sx < kS; ++sx) {
          count += Inside(a, dx - 0.5 + (sx + 0.5) / kS, dy - 0.5 + (sy + 0.5) / kS, r);
        }
      }
      k.w[(dy + k.half) * n + dx + k.half] = static_cast<float>(count);
      total += count;
    }
  }
  for (float& w : k.w) w = static_cast<float>(w / total);
  return k;
}

}  // namespace

PlaneF ReferenceRender(const PlaneF& value, const PlaneF& disp, float radius_per_disp,
                       float focus_disp, float max_radius, int32_t scale, const Aperture& ap) {
  const int32_t w = value.width, h = value.height;
  // Slabs of 1/8 px of signed radius, far (negative) to near.
  std::map<int32_t, std::vector<int32_t>> slabs;
  std::vector<float> radius(static_cast<size_t>(w) * h);
  for (int32_t i = 0; i < w * h; ++i) {
    float r = radius_per_disp * (disp.v[i] - focus_disp);
    r = std::clamp(r, -max_radius, max_radius);
    radius[i] = std::fabs(r) / static_cast<float>(scale);
    slabs[static_cast<int32_t>(std::lround(r * 8.0f))].push_back(i);
  }
  std::map<int32_t, Kernel> kernels;  // by radius in 1/64 px
  std::vector<double> out_c(radius.size(), 0.0), out_a(radius.size(), 0.0);
  std::vector<double> c(radius.size()), a(radius.size());
  for (const auto& [key, pixels] : slabs) {
    std::fill(c.begin(), c.end(), 0.0);
    std::fill(a.begin(), a.end(), 0.0);
    for (int32_t i : pixels) {
      const int32_t rk = static_cast<int32_t>(std::lround(radius[i] * 64.0f));
      auto it = kernels.find(rk);
      if (it == kernels.end()) it = kernels.emplace(rk, MakeKernel(ap, rk / 64.0)).first;
      const Kernel& k = it->second;
      const int32_t px = i % w, py = i / w, n = 2 * k.half + 1;
      for (int32_t dy = -k.half; dy <= k.half; ++dy) {
        const int32_t y = py + dy;
        if (y < 0 || y >= h) continue;
        for (int32_t dx = -k.half; dx <= k.half; ++dx) {
          const int32_t x = px + dx;
          if (x < 0 || x >= w) continue;
          const double kw = k.w[(dy + k.half) * n + dx + k.half];
          c[y * w + x] += kw * value.v[i];
          a[y * w + x] += kw;
        }
      }
    }
    for (size_t i = 0; i < c.size(); ++i) {
      if (a[i] == 0.0) continue;
      const double alpha = std::min(a[i], 1.0);
      out_c[i] = out_c[i] * (1.0 - alpha) + c[i] * alpha / a[i];
      out_a[i] = out_a[i] * (1.0 - alpha) + alpha;
    }
  }
  PlaneF out{w, h, std::vector<float>(radius.size())};
  for (size_t i = 0; i < radius.size(); ++i) {
    out.v[i] = static_cast<float>(out_a[i] > 0 ? out_c[i] / out_a[i] : value.v[i]);
  }
  return out;
}

ConstPlanarU8 TestScene::Planar() const {
  ConstPlanarU8 p;
  p.count = 3;
  const int32_t cw = (width + 1) / 2, ch = (height + 1) / 2;
  p.planes[0] = MakeView(y.data(), width, height);
  p.planes[1] = MakeView(cb.data(), cw, ch);
  p.planes[2] = MakeView(cr.data(), cw, ch);
  return p;
}

ConstImageU16 TestScene::WorkingDisp() const {
  return MakeView(disp_q8.data(), width / scale, height / scale);
}

PlaneF TestScene::Luma() const {
  PlaneF p{width, height, std::vector<float>(y.begin(), y.end())};
  return p;
}

void FinishScene(TestScene* s) {
  const int32_t ww = s->width / s->scale, wh = s->height / s->scale;
  s->disp_q8.resize(static_cast<size_t>(ww) * wh);
  for (int32_t y = 0; y < wh; ++y) {
    for (int32_t x = 0; x < ww; ++x) {
      // The centre of a working pixel (between full pixels for an even scale: take the mean).
      const int32_t fx = x * s->scale + s->scale / 2, fy = y * s->scale + s->scale / 2;
      const float d = s->scale % 2 ? s->disp.at(fx, fy)
                                   : 0.25f * (s->disp.at(fx, fy) + s->disp.at(fx - 1, fy) +
                                              s->disp.at(fx, fy - 1) + s->disp.at(fx - 1, fy - 1));
      s->disp_q8[y * ww + x] = static_cast<uint16_t>(std::lround(d * 256.0f));
    }
  }
  const int32_t w = s->width, h = s->height, cw = (w + 1) / 2, ch = (h + 1) / 2;
  s->y.resize(static_cast<size_t>(w) * h);
  s->cb.resize(static_cast<size_t>(cw) * ch);
  s->cr.resize(static_cast<size_t>(cw) * ch);
  for (int32_t y = 0; y < h; ++y) RowRgb8ToY(&s->rgb[y * w * 3], w, &s->y[y * w]);
  for (int32_t y = 0; y < ch; ++y) {
    const uint8_t* r0 = &s->rgb[2 * y * w * 3];
    const uint8_t* r1 = 2 * y + 1 < h ? r0 + w * 3 : r0;
    RowsRgb8ToCbCr420(r0, r1, w, &s->cb[y * cw], &s->cr[y * cw]);
  }
}

TestScene MakeLayeredScene(int32_t w, int32_t h, int32_t scale) {
  TestScene s;
  s.width = w, s.height = h, s.scale = scale;
  s.rgb.resize(static_cast<size_t>(w) * h * 3);
  s.disp = PlaneF{w, h, std::vector<float>(static_cast<size_t>(w) * h)};
  auto hash = [](uint32_t v) {
    v ^= v >> 16, v *= 0x7feb352dU, v ^= v >> 15, v *= 0x846ca68bU, v ^= v >> 16;
    return v;
  };
  for (int32_t y = 0; y < h; ++y) {
    for (int32_t x = 0; x < w; ++x) {
      const double fx = x + 0.5, fy = y + 0.5;
      float d = 1.0f;
      int obj = 0;
      if (fy > 0.8 * h) d = 1.0f + 6.0f * static_cast<float>((fy - 0.8 * h) / (0.2 * h)), obj = 1;
      if (fx > 0.2 * w && fx < 0.55 * w && fy > 0.2 * h && fy < 0.7 * h) d = 4.0f, obj = 2;
      const double dx = fx - 0.62 * w, dy = fy - 0.45 * h;
      if (dx * dx + dy * dy < 0.04 * w * w) d = 7.0f, obj = 3;
      s.disp.at(x, y) = d;
      // Per-object texture: blocks of hashed colour plus stripes, with distinct base hues.
      static const int kBase[4][3] = {{90, 120, 160}, {120, 100, 60}, {200, 80, 60}, {60, 170, 90}};
      const uint32_t cell = hash(static_cast<uint32_t>((x / 5) * 7919 + (y / 5) * 104729 + obj));
      uint8_t* p = &s.rgb[(static_cast<size_t>(y) * w + x) * 3];
      for (int c = 0; c < 3; ++c) {
        int v = kBase[obj][c] + static_cast<int>((cell >> (8 * c)) & 63) - 32 +
                (((x + 2 * y) / 3 + c) % 4 == 0 ? 25 : 0);
        p[c] = static_cast<uint8_t>(std::clamp(v, 0, 255));
      }
      if (obj == 0 && hash(static_cast<uint32_t>(x * 31 + y * 1031)) % 997 == 0) {
        p[0] = p[1] = p[2] = 255;  // point lights on the far wall
      }
    }
  }
  FinishScene(&s);
  return s;
}

double Psnr(const PlaneF& a, const PlaneF& b, const std::vector<uint8_t>* mask) {
  double sum = 0;
  int64_t n = 0;
  for (size_t i = 0; i < a.v.size(); ++i) {
    if (mask && !(*mask)[i]) continue;
    const double e = a.v[i] - b.v[i];
    sum += e * e;
    ++n;
  }
  if (n == 0) return 0.0;
  const double mse = sum / static_cast<double>(n);
  return mse == 0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
}

std::vector<uint8_t> DepthEdgeBand(const PlaneF& d, int32_t band) {
  const int32_t w = d.width, h = d.height;
  std::vector<uint8_t> edge(static_cast<size_t>(w) * h, 0), out(edge.size(), 0);
  for (int32_t y = 0; y < h; ++y) {
    for (int32_t x = 0; x < w; ++x) {
      if ((x + 1 < w && std::fabs(d.at(x, y) - d.at(x + 1, y)) > 0.25f) ||
          (y + 1 < h && std::fabs(d.at(x, y) - d.at(x, y + 1)) > 0.25f)) {
        edge[y * w + x] = 1;
      }
    }
  }
  for (int32_t y = 0; y < h; ++y) {
    for (int32_t x = 0; x < w; ++x) {
      if (!edge[y * w + x]) continue;
      for (int32_t yy = std::max(0, y - band); yy <= std::min(h - 1, y + band); ++yy) {
        for (int32_t xx = std::max(0, x - band); xx <= std::min(w - 1, x + band); ++xx) {
          out[yy * w + xx] = 1;
        }
      }
    }
  }
  return out;
}

}  // namespace lb::test
