// The slow, straightforward floating-point renderer the product is measured against, and a small
// layered test scene with known depth.
//
// Reference: every pixel p gets the exact radius rpd * |d(p) - d_focus| (capped) from the
// full-resolution ground-truth disparity; pixels are grouped into thin depth slabs (1/8 px of
// radius) and the slabs are processed far to near. Within a slab every pixel scatters its colour
// over its aperture shape (pixel coverage from 8x8 samples per pixel, normalised to unit weight)
// into the slab's colour and coverage images; each slab is then laid over what is behind it
// ("over", coverage clamped to 1) and the result is divided by the accumulated coverage.
#pragma once

#include <cstdint>
#include <vector>

#include "algo/render/render_stage.h"

namespace lb::test {

struct PlaneF {
  int32_t width = 0, height = 0;
  std::vector<float> v;
  float& at(int32_t x, int32_t y) { return v[static_cast<size_t>(y) * width + x]; }
  float at(int32_t x, int32_t y) const { return v[static_cast<size_t>(y) * width + x]; }
};

// Renders one plane (values 0..255) whose pixels have disparities `disp` (working px, same
// size). `scale` is 1 for luma, 2 for chroma (the radius halves). No highlight boost.
PlaneF ReferenceRender(const PlaneF& value, const PlaneF& disp, float radius_per_disp,
                       float focus_disp, float max_radius, int32_t scale, const Aperture& aperture);

// A test scene: RGB8 at full size, its ground-truth disparity per full-resolution pixel, and the
// working-resolution disparity (Q8.8) sampled at working-pixel centres.
struct TestScene {
  int32_t width = 0, height = 0, scale = 1;
  std::vector<uint8_t> rgb;
  PlaneF disp;                     // full resolution, working px per view step
  std::vector<uint16_t> disp_q8;   // working resolution
  std::vector<uint8_t> y, cb, cr;  // the YCbCr 4:2:0 reference
  ConstPlanarU8 Planar() const;
  ConstImageU16 WorkingDisp() const;
  PlaneF Luma() const;
};

// Textured far wall (d = 1), a board at d = 4, a disc at d = 7 overlapping it, and a ground
// strip whose disparity grows downwards (a slanted surface); every object has its own hues.
TestScene MakeLayeredScene(int32_t width, int32_t height, int32_t scale);

// Converts ground-truth disparity to Q8.8 at working resolution (the value at the working
// pixel's centre) and fills the YCbCr reference from rgb.
void FinishScene(TestScene* scene);

double Psnr(const PlaneF& a, const PlaneF& b, const std::vector<uint8_t>* mask = nullptr);
// Pixels within `band` px (Chebyshev) of a depth edge (a neighbour differing by > 0.25 px).
std::vector<uint8_t> DepthEdgeBand(const PlaneF& disp, int32_t band);

}  // namespace lb::test
