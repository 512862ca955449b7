#include "algo/pipeline/ingest.h"

#include "algo/core/clones.h"

namespace lb::ingest {

LB_CLONES_AVX2 void ColumnAccumulateRowC(const uint8_t* __restrict rgb, int32_t values,
                                         uint32_t* __restrict cols) {
  for (int32_t i = 0; i < values; ++i) cols[i] += rgb[i];
}

void BoxEmitColumnsC(uint32_t* cols, int32_t out_width, int32_t scale, uint8_t* out) {
  const uint32_t n = static_cast<uint32_t>(scale * scale);
  for (int32_t wx = 0; wx < out_width; ++wx) {
    uint32_t* p = cols + 3 * static_cast<int64_t>(wx) * scale;
    uint32_t r = 0, g = 0, b = 0;
    for (int32_t k = 0; k < scale; ++k) {
      r += p[3 * k];
      g += p[3 * k + 1];
      b += p[3 * k + 2];
      p[3 * k] = p[3 * k + 1] = p[3 * k + 2] = 0;
    }
    out[3 * wx] = static_cast<uint8_t>((r + n / 2) / n);
    out[3 * wx + 1] = static_cast<uint8_t>((g + n / 2) / n);
    out[3 * wx + 2] = static_cast<uint8_t>((b + n / 2) / n);
  }
}

}  // namespace lb::ingest
