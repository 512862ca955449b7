// The ingest's row kernels: the integer box downscale from the sensor's full resolution to the
// working resolution of the depth stage, fed one RGB8 row at a time (Pipeline::IngestRow). Each
// sensor row is added into per-column sums (a loop the compiler vectorises), and once a working
// row's `scale` sensor rows are in, each box sums its `scale` columns: the per-box grouping runs
// once per working row instead of once per sensor row. Plain C.
//
// Format: samples uint8 (0..255); a column sum holds up to scale samples, a box up to scale^2,
// in uint32; the mean is rounded half up.
// Overflow: a box sums scale^2 samples of at most 255, plus scale^2 / 2 for the rounding, which
// stays below 2^32 for scale <= kMaxBoxScale (4096^2 x 255 + 2^23 < 2^32). The pipeline's scale
// is at most PipelineConfig::kMaxWidth / 8 = 1024 (the working bound is at least 8 px; see
// Pipeline::Plan), which pipeline.cc checks at compile time.
#pragma once

#include <cstdint>

namespace lb::ingest {

inline constexpr int32_t kMaxBoxScale = 4096;

// cols[i] += rgb[i] for i < values: one sensor row's contribution to its working row's column
// sums (values = 3 x out_width x scale, the row's RGB bytes over whole boxes).
void ColumnAccumulateRowC(const uint8_t* rgb, int32_t values, uint32_t* cols);

// out[3 wx + c] = (sum over k < scale of cols[3 (wx scale + k) + c] + n / 2) / n with
// n = scale^2, for wx < out_width and the three channels c, then every column sum back to 0:
// the working row once `scale` sensor rows have been accumulated. 1 <= scale <= kMaxBoxScale.
void BoxEmitColumnsC(uint32_t* cols, int32_t out_width, int32_t scale, uint8_t* out);

}  // namespace lb::ingest
