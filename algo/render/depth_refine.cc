#include "algo/render/depth_refine.h"

#include "algo/core/int_math.h"

namespace lb {

int32_t DepthRefiner::MapScale(int32_t width, int32_t height, int32_t work_scale) {
  const int64_t half = int64_t{width / 2} * (height / 2);
  const int64_t want = half < (int64_t{1} << 20) ? half : (int64_t{1} << 20);
  int32_t s = work_scale;
  while (s > 1 && int64_t{width / s} * (height / s) < want) --s;
  return s;
}

size_t DepthRefiner::RequiredBytes(const RefineConfig& config) {
  Arena plan;
  DepthRefiner r;
  r.Carve(config, plan);
  return plan.used();
}

void DepthRefiner::Carve(const RefineConfig& c, Arena& arena) {
  config_ = c;
  config_.workers = Clamp(c.workers, 1, kMaxWorkers);
  upsampler_.Carve(arena, c.width, c.height, c.work_scale, c.work_width, c.work_height,
                   config_.workers);
  for (int32_t w = 0; w < config_.workers; ++w) {
    for (uint16_t*& row : samples_[w])
      row = arena.Allocate<uint16_t>(static_cast<size_t>(c.map_width));
  }
}

void DepthRefiner::SetRunner(TaskRunner* runner) {
  runner_ = runner != nullptr && runner->workers() <= config_.workers ? runner : &inline_;
}

// Working px to map px: times work_scale / map_scale, rounded.
uint16_t DepthRefiner::ToMap(uint32_t working_q8) const {
  const uint32_t s = static_cast<uint32_t>(config_.map_scale);
  const uint32_t v = (working_q8 * static_cast<uint32_t>(config_.work_scale) + s / 2) / s;
  return static_cast<uint16_t>(v > 65535 ? 65535 : v);
}

void DepthRefiner::Rows(ConstImageU8 conf, ImageU16 map, ImageU8 map_conf, int32_t y0, int32_t y1,
                        int32_t worker) {
  const RefineConfig& c = config_;
  const int32_t s = c.map_scale, ws = c.work_scale, mw = c.map_width;
  uint16_t* const* rows = samples_[worker];
  // The full-resolution pixels around each map pixel's centre: one when s is odd, two a side
  // when it is even.
  const int32_t taps = s % 2 == 1 ? 1 : 2;
  const int32_t first = s % 2 == 1 ? s / 2 : s / 2 - 1;
  for (int32_t my = y0; my < y1; ++my) {
    uint16_t* out = map.Row(my);
    for (int32_t ty = 0; ty < taps; ++ty) {
      for (int32_t tx = 0; tx < taps; ++tx) {
        upsampler_.Row(my * s + first + ty, rows[ty * taps + tx], worker, s, first + tx);
      }
    }
    const int32_t n = taps * taps;
    for (int32_t mx = 0; mx < mw; ++mx) {
      uint32_t sum = 0;
      for (int32_t i = 0; i < n; ++i) sum += rows[i][mx];
      out[mx] = ToMap((sum + static_cast<uint32_t>(n / 2)) / static_cast<uint32_t>(n));
    }
    if (map_conf.data == nullptr || conf.data == nullptr) continue;
    const uint8_t* src = conf.Row(Min((my * s + s / 2) / ws, c.work_height - 1));
    uint8_t* cout = map_conf.Row(my);
    for (int32_t mx = 0; mx < mw; ++mx)
      cout[mx] = src[Min((mx * s + s / 2) / ws, c.work_width - 1)];
  }
}

void DepthRefiner::Run(const ConstPlanarU8& ref, ConstImageU16 disp, ConstImageU8 conf,
                       ImageU16 map, ImageU8 map_conf) {
  const RefineConfig& c = config_;
  upsampler_.Begin(ref, disp, conf, /*one_side=*/true);
  // Bands of whole map rows, several a worker: the upsampler's guide rows are cached per worker.
  const int32_t bands = runner_->workers() > 1 ? 4 * runner_->workers() : 1;
  ParallelFor(*runner_, bands, [&](int32_t b, int32_t worker) {
    Rows(conf, map, map_conf, c.map_height * b / bands, c.map_height * (b + 1) / bands, worker);
  });
}

}  // namespace lb
