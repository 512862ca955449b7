// What Pipeline::ComputeDepth does to the depth stage's map once near and far are settled, for
// the tests that run the stages one by one to look between them.
#pragma once

#include <cstdint>
#include <vector>

#include "algo/core/arena.h"
#include "algo/core/image.h"
#include "algo/depth/fattening_trim.h"

namespace lb {

// The near side's overreach at depth edges taken back (fattening_trim.h), as the pipeline does.
inline void TrimAsThePipelineDoes(const ConstImageU8& reference, ImageU16 disp_q8,
                                  const DepthConfig& depth) {
  const size_t bytes = FatteningTrim::RequiredBytes(disp_q8.width, 1);
  std::vector<uint8_t> block(bytes + Arena::kAlign);
  Arena arena(Arena::AlignUp(block.data()), bytes);
  FatteningTrim trim;
  trim.Carve(arena, disp_q8.width, 1);
  std::vector<uint16_t> in(static_cast<size_t>(disp_q8.width) * disp_q8.height);
  for (int32_t y = 0; y < disp_q8.height; ++y)
    for (int32_t x = 0; x < disp_q8.width; ++x)
      in[static_cast<size_t>(y) * disp_q8.width + x] = disp_q8.Row(y)[x];
  trim.Run(reference, MakeView(in.data(), disp_q8.width, disp_q8.height).AsConst(), disp_q8,
           FatteningTrim::LabelStepQ8(depth));
}

}  // namespace lb
