#include "tests/algo/render/render_util.h"

#include <cstring>

namespace lb::test {

Status RenderAll(const ConstPlanarU8& ref, ConstImageU16 disp_q8, int32_t scale,
                 const RenderSetup& setup, Rendered* out) {
  RenderConfig config;
  config.width = ref.planes[0].width;
  config.height = ref.planes[0].height;
  config.working_scale = scale;
  config.working_width = disp_q8.width;
  config.working_height = disp_q8.height;
  config.max_radius = setup.max_radius;
  config.workers = setup.workers;
  LB_RETURN_IF_ERROR(RenderStage::Validate(config));
  std::vector<uint8_t> block(RenderStage::RequiredBytes(config) + Arena::kAlign);
  void* base =
      block.data() + (Arena::kAlign - reinterpret_cast<uintptr_t>(block.data()) % Arena::kAlign);
  Arena arena(base, block.size() - Arena::kAlign);
  RenderStage stage;
  LB_RETURN_IF_ERROR(stage.Configure(config, arena));
  stage.SetRunner(setup.runner);
  LB_RETURN_IF_ERROR(stage.Begin(ref, disp_q8, setup.params));
  out->radius_per_disp = stage.radius_per_disp();
  out->focus_disp = static_cast<float>(stage.focus_disp_q8()) / 256.0f;
  const int32_t w = config.width, h = config.height, cw = (w + 1) / 2, ch = (h + 1) / 2;
  out->y.assign(static_cast<size_t>(w) * h, 0);
  out->cb.assign(static_cast<size_t>(cw) * ch, 0);
  out->cr.assign(static_cast<size_t>(cw) * ch, 0);
  out->strip_rows.clear();
  int32_t expect = 0;
  for (;;) {
    ConstPlanarU8 strip;
    int32_t y0 = -1, rows = -1;
    LB_RETURN_IF_ERROR(stage.NextStrip(&strip, &y0, &rows));
    if (rows == 0) break;
    if (y0 != expect) return Status(Code::kInternal, "strip at row %d, expected %d", y0, expect);
    out->strip_rows.push_back(rows);
    for (int32_t r = 0; r < rows; ++r) {
      std::memcpy(&out->y[(y0 + r) * w], strip.planes[0].Row(r), w);
    }
    for (int32_t r = 0; r < (rows + 1) / 2; ++r) {
      std::memcpy(&out->cb[(y0 / 2 + r) * cw], strip.planes[1].Row(r), cw);
      std::memcpy(&out->cr[(y0 / 2 + r) * cw], strip.planes[2].Row(r), cw);
    }
    expect += rows;
  }
  if (expect != h) return Status(Code::kInternal, "strips covered %d of %d rows", expect, h);
  return Status::Ok();
}

}  // namespace lb::test
