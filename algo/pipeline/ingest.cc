#include "algo/pipeline/ingest.h"

namespace lb::ingest {

void BoxAccumulateRowC(const uint8_t* rgb, int32_t out_width, int32_t scale, uint32_t* acc) {
  for (int32_t wx = 0; wx < out_width; ++wx) {
    const uint8_t* p = rgb + 3 * wx * scale;
    uint32_t r = 0, g = 0, b = 0;
    for (int32_t k = 0; k < scale; ++k) {
      r += p[3 * k];
      g += p[3 * k + 1];
      b += p[3 * k + 2];
    }
    acc[3 * wx] += r;
    acc[3 * wx + 1] += g;
    acc[3 * wx + 2] += b;
  }
}

void BoxEmitRowC(uint32_t* acc, int32_t values, int32_t scale, uint8_t* out) {
  const uint32_t n = static_cast<uint32_t>(scale * scale);
  for (int32_t i = 0; i < values; ++i) {
    out[i] = static_cast<uint8_t>((acc[i] + n / 2) / n);
    acc[i] = 0;
  }
}

}  // namespace lb::ingest
