// Quality against the slow floating-point reference (reference_render.h), compared on luma:
// PSNR over the whole image and over the band of 8 px around depth edges.
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/algo/render/reference_render.h"
#include "tests/algo/render/render_util.h"

namespace lb {
namespace {

struct Case {
  const char* name;
  Aperture aperture;
  int32_t max_radius = 12;
  float f_number = 4.0f;
};

class RenderQuality : public ::testing::TestWithParam<Case> {};

TEST_P(RenderQuality, MatchesTheReferenceFromGroundTruthDepth) {
  const test::TestScene scene = test::MakeLayeredScene(160, 120, 4);
  test::RenderSetup setup;
  setup.max_radius = GetParam().max_radius;
  setup.params.f_number = GetParam().f_number;
  setup.params.aperture = GetParam().aperture;
  setup.params.focus = {36, 30, 20, 40};  // on the board at disparity 4
  test::Rendered out;
  ASSERT_TRUE(test::RenderAll(scene.Planar(), scene.WorkingDisp(), 4, setup, &out).ok());
  EXPECT_FLOAT_EQ(out.focus_disp, 4.0f);
  const test::PlaneF ref =
      test::ReferenceRender(scene.Luma(), scene.disp, out.radius_per_disp, out.focus_disp,
                            static_cast<float>(setup.max_radius), 1, setup.params.aperture);
  const test::PlaneF got = out.Luma(scene.width, scene.height);
  const std::vector<uint8_t> band = test::DepthEdgeBand(scene.disp, 8);
  const double overall = test::Psnr(got, ref), edges = test::Psnr(got, ref, &band);
  // How far the input itself is from the reference, to show the render is doing the work.
  const double input = test::Psnr(scene.Luma(), ref);
  std::printf(
      "[ quality ] %s: PSNR %.2f dB overall, %.2f dB in the 8 px depth-edge band "
      "(unblurred input: %.2f dB)\n",
      GetParam().name, overall, edges, input);
  RecordProperty("psnr_overall_db", static_cast<int>(overall * 100));
  RecordProperty("psnr_edge_band_db", static_cast<int>(edges * 100));
  EXPECT_GE(overall, 35.0);
  EXPECT_GE(edges, 28.0);
  EXPECT_LT(input, overall - 5.0);
}

INSTANTIATE_TEST_SUITE_P(Apertures, RenderQuality,
                         ::testing::Values(Case{"disc", Aperture{}},
                                           Case{"hexagon", Aperture{6, 15.0f, 0.0f}},
                                           Case{"curved7", Aperture{7, 0.0f, 0.4f}},
                                           // Radii up to 24 px: blurred at 1/2 and 1/4 size.
                                           Case{"disc_r24", Aperture{}, 24, 2.0f}),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace lb
