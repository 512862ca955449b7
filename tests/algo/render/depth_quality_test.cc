// Render quality on the synthetic scene (sim/synthetic): the product's render from the
// ground-truth working-resolution depth and from the depth the pipeline estimates from a
// 5-frame burst, each against the floating-point reference rendered from the full-resolution
// ground truth with the same focus. Luma PSNR, overall and in the 8 px depth-edge band.
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "algo/pipeline/pipeline.h"
#include "sim/synthetic/scene.h"
#include "tests/algo/render/reference_render.h"
#include "tests/algo/render/render_util.h"

namespace lb {
namespace {

constexpr int32_t kW = 320, kH = 240, kViews = 5, kScale = 2, kMaxRadius = 16;

struct Figures {
  double overall = 0, edges = 0;
};

Figures Compare(const std::vector<uint8_t>& got, const test::PlaneF& ref,
                const std::vector<uint8_t>& band) {
  const test::PlaneF g{kW, kH, std::vector<float>(got.begin(), got.end())};
  return {test::Psnr(g, ref), test::Psnr(g, ref, &band)};
}

TEST(RenderDepthQuality, SyntheticBurstAgainstTheReference) {
  Scene scene;
  ASSERT_TRUE(scene.Configure(SceneParams{}, kW, kH, kViews).ok());

  PipelineConfig config;
  config.width = kW, config.height = kH, config.frames = kViews, config.reference = 2;
  config.max_working_width = kW / kScale, config.max_working_height = kH / kScale;
  config.labels = 32;
  config.disp_min_q8 = scene.disparity_min_q8(kScale) * 7 / 8;
  config.disp_max_q8 = scene.disparity_max_q8(kScale) * 9 / 8 + 1;
  config.max_blur_radius = kMaxRadius;
  size_t bytes = 0;
  ASSERT_TRUE(Pipeline::RequiredBytes(config, &bytes).ok());
  std::vector<uint8_t> block(bytes + 64);
  uint8_t* base = block.data() + (64 - reinterpret_cast<uintptr_t>(block.data()) % 64);
  Pipeline pipeline;
  ASSERT_TRUE(pipeline.Configure(config, base, bytes).ok());
  ASSERT_EQ(pipeline.working_scale(), kScale);

  std::vector<uint8_t> rgb(static_cast<size_t>(kW) * kH * 3);
  for (int32_t v = 0; v < kViews; ++v) {
    ASSERT_TRUE(scene.RenderRows(v, 0, kH, rgb.data(), kW * 3).ok());
    FrameInfo info;
    info.index = v, info.format = PixelFormat::kRgb8, info.width = kW, info.height = kH;
    ASSERT_TRUE(pipeline.BeginFrame(info).ok());
    FrameRows rows;
    rows.y0 = 0, rows.height = kH, rows.planes[0] = rgb.data(), rows.strides[0] = kW * 3;
    ASSERT_TRUE(pipeline.Rows(rows).ok());
    ASSERT_TRUE(pipeline.EndFrame().ok());
  }
  ASSERT_TRUE(pipeline.ComputeDepth().ok());

  // Ground truth: working resolution for the product, full resolution for the reference (in
  // working px per view step, as the lens model expects).
  std::vector<uint16_t> truth_q8(static_cast<size_t>(kW / kScale) * (kH / kScale));
  ASSERT_TRUE(scene.DisparityRows(kScale, 0, kH / kScale, truth_q8.data(), kW / kScale).ok());
  std::vector<uint16_t> full_q8(static_cast<size_t>(kW) * kH);
  ASSERT_TRUE(scene.DisparityRows(1, 0, kH, full_q8.data(), kW).ok());
  test::PlaneF full{kW, kH, std::vector<float>(full_q8.size())};
  for (size_t i = 0; i < full_q8.size(); ++i) full.v[i] = full_q8[i] / 256.0f / kScale;
  const std::vector<uint8_t> band = test::DepthEdgeBand(full, 8);

  const ConstPlanarU8 ref = pipeline.reference();
  test::PlaneF luma{kW, kH, std::vector<float>(static_cast<size_t>(kW) * kH)};
  for (int32_t y = 0; y < kH; ++y) {
    for (int32_t x = 0; x < kW; ++x) luma.v[y * kW + x] = ref.planes[0].Row(y)[x];
  }

  test::RenderSetup setup;
  setup.max_radius = kMaxRadius;
  setup.params.f_number = 2.0f;
  setup.params.focus = {kW / 2 - 16, kH / 2 - 16, 32, 32};
  for (int pass = 0; pass < 2; ++pass) {
    const bool estimated = pass == 1;
    const ConstImageU16 disp =
        estimated ? pipeline.disparity_q8() : MakeView(truth_q8.data(), kW / kScale, kH / kScale);
    test::Rendered out;
    ASSERT_TRUE(test::RenderAll(ref, disp, kScale, setup, &out).ok());
    const test::PlaneF reference = test::ReferenceRender(
        luma, full, out.radius_per_disp, out.focus_disp, kMaxRadius, 1, setup.params.aperture);
    const Figures f = Compare(out.y, reference, band);
    const double input = test::Psnr(luma, reference);
    std::printf(
        "[ quality ] synthetic scene, %s depth: PSNR %.2f dB overall, %.2f dB in the 8 px "
        "depth-edge band (unblurred input %.2f dB; focus disparity %.2f)\n",
        estimated ? "estimated" : "ground-truth", f.overall, f.edges, input, out.focus_disp);
    RecordProperty(estimated ? "estimated_overall_db" : "truth_overall_db",
                   static_cast<int>(f.overall * 100));
    RecordProperty(estimated ? "estimated_edge_band_db" : "truth_edge_band_db",
                   static_cast<int>(f.edges * 100));
    if (!estimated) {
      EXPECT_GE(f.overall, 35.0);
      EXPECT_GE(f.edges, 28.0);
    } else {
      EXPECT_GT(f.overall, input + 3.0);  // the estimated depth still gives a useful render
    }
  }
}

}  // namespace
}  // namespace lb
