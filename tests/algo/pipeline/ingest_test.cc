// The ingest's box downscale kernels (ingest.h) against the mean they define, on random rows
// and at the overflow bound: boxes of the largest scale full of 255.
#include "algo/pipeline/ingest.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

namespace lb {
namespace {

// Downscales `rows` full-resolution RGB8 rows (width w) by `scale` through the kernels.
std::vector<uint8_t> Downscale(const std::vector<std::vector<uint8_t>>& rows, int32_t w,
                               int32_t scale) {
  const int32_t ow = w / scale, oh = static_cast<int32_t>(rows.size()) / scale;
  std::vector<uint32_t> cols(3 * static_cast<size_t>(ow) * scale, 0);
  std::vector<uint8_t> out(3 * static_cast<size_t>(ow) * oh, 0);
  for (int32_t y = 0; y < oh * scale; ++y) {
    ingest::ColumnAccumulateRowC(rows[y].data(), 3 * ow * scale, cols.data());
    if ((y + 1) % scale == 0)
      ingest::BoxEmitColumnsC(cols.data(), ow, scale, &out[3 * ow * (y / scale)]);
  }
  for (uint32_t a : cols) EXPECT_EQ(a, 0u);  // every emit clears the column sums
  return out;
}

// The rounded (half up) mean of each box, in 64-bit.
std::vector<uint8_t> Mean(const std::vector<std::vector<uint8_t>>& rows, int32_t w, int32_t scale) {
  const int32_t ow = w / scale, oh = static_cast<int32_t>(rows.size()) / scale;
  std::vector<uint8_t> out(3 * static_cast<size_t>(ow) * oh);
  const uint64_t n = static_cast<uint64_t>(scale) * scale;
  for (int32_t oy = 0; oy < oh; ++oy)
    for (int32_t ox = 0; ox < ow; ++ox)
      for (int32_t c = 0; c < 3; ++c) {
        uint64_t sum = 0;
        for (int32_t dy = 0; dy < scale; ++dy)
          for (int32_t dx = 0; dx < scale; ++dx)
            sum += rows[oy * scale + dy][3 * (ox * scale + dx) + c];
        out[3 * (oy * ow + ox) + c] = static_cast<uint8_t>((2 * sum + n) / (2 * n));
      }
  return out;
}

TEST(Ingest, BoxDownscaleIsTheRoundedMeanOfEachBox) {
  std::mt19937 rng(5);
  for (int32_t scale = 1; scale <= 9; ++scale) {
    for (int32_t kind = 0; kind < 3; ++kind) {
      // Widths that leave a remainder: the columns past the last whole box are ignored.
      const int32_t w =
          scale * (1 + static_cast<int32_t>(rng() % 7)) + static_cast<int32_t>(rng() % scale);
      const int32_t h = scale * 3 + static_cast<int32_t>(rng() % scale);
      std::vector<std::vector<uint8_t>> rows(h, std::vector<uint8_t>(3 * w));
      for (auto& r : rows)
        for (uint8_t& v : r)
          v = static_cast<uint8_t>(kind == 0 ? rng() : kind == 1 ? 255 : (rng() & 1) * 255);
      ASSERT_EQ(Downscale(rows, w, scale), Mean(rows, w, scale))
          << "scale " << scale << " kind " << kind;
    }
  }
}

TEST(Ingest, RoundsHalfUp) {
  // One 2x2 box: red sums to 3 (mean 0.75 -> 1), green to 1 (0.25 -> 0), blue to 2 (0.5, half
  // up -> 1).
  std::vector<std::vector<uint8_t>> rows = {{1, 1, 1, 0, 0, 0}, {1, 0, 1, 1, 0, 0}};
  const std::vector<uint8_t> out = Downscale(rows, 2, 2);
  EXPECT_EQ(out, (std::vector<uint8_t>{1, 0, 1}));
}

TEST(Ingest, TheLargestBoxOfWhiteDoesNotOverflow) {
  // scale^2 x 255 + scale^2 / 2 is just below 2^32 at kMaxBoxScale.
  const int32_t s = ingest::kMaxBoxScale;
  static_assert(uint64_t{ingest::kMaxBoxScale} * ingest::kMaxBoxScale * 255 +
                    uint64_t{ingest::kMaxBoxScale} * ingest::kMaxBoxScale / 2 <
                uint64_t{1} << 32);
  const std::vector<uint8_t> white(3 * static_cast<size_t>(s), 255);
  std::vector<uint32_t> cols(3 * static_cast<size_t>(s), 0);
  for (int32_t y = 0; y < s; ++y) ingest::ColumnAccumulateRowC(white.data(), 3 * s, cols.data());
  EXPECT_EQ(cols[0], static_cast<uint32_t>(255 * s));
  uint8_t out[3] = {};
  ingest::BoxEmitColumnsC(cols.data(), 1, s, out);
  EXPECT_EQ(out[0], 255);
  EXPECT_EQ(out[1], 255);
  EXPECT_EQ(out[2], 255);
}

}  // namespace
}  // namespace lb
