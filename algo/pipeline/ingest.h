// The ingest's row kernels: the integer box downscale from the sensor's full resolution to the
// working resolution of the depth stage, fed one RGB8 row at a time (Pipeline::IngestRow).
// Plain C; the compiler vectorises the emit, and the accumulate runs once per sensor row.
//
// Format: samples uint8 (0..255); the accumulator holds, per working pixel and channel, the sum
// of the scale x scale samples of its box, in uint32; the mean is rounded half up.
// Overflow: a box sums scale^2 samples of at most 255, plus scale^2 / 2 for the rounding, which
// stays below 2^32 for scale <= kMaxBoxScale (4096^2 x 255 + 2^23 < 2^32). The pipeline's scale
// is at most PipelineConfig::kMaxWidth / 8 = 1024 (the working bound is at least 8 px; see
// Pipeline::Plan), which pipeline.cc checks at compile time.
#pragma once

#include <cstdint>

namespace lb::ingest {

inline constexpr int32_t kMaxBoxScale = 4096;

// acc[3 wx + c] += sum of rgb[3 (wx scale + k) + c] over k < scale, for wx < out_width and the
// three channels c: one sensor row's contribution to its working row (rgb holds at least
// out_width x scale pixels). 1 <= scale <= kMaxBoxScale.
void BoxAccumulateRowC(const uint8_t* rgb, int32_t out_width, int32_t scale, uint32_t* acc);

// out[i] = (acc[i] + n / 2) / n with n = scale^2, then acc[i] = 0, for i < values: the working
// row once `scale` sensor rows have been accumulated (values = 3 x out_width).
void BoxEmitRowC(uint32_t* acc, int32_t values, int32_t scale, uint8_t* out);

}  // namespace lb::ingest
