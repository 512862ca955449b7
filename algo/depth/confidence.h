// The depth map's confidence (DepthConfig::confidence): per pixel of the reference view, 8 bits,
// 255 = sure, 0 = a guess. Two pieces of evidence, multiplied (Q0.8 x Q0.8 -> Q0.8, rounded):
// - The data term's margin: how much lower the chosen label's D is than the best D at labels
//   away from it, as a share of the latter (confidence.cc says why a share). A small or negative
//   margin means another depth explains the pixel as well (a repeated pattern, a flat patch, a
//   label the smoothness forced against the data). Labels near the chosen one are not "away"
//   (within one label, or half the winner-take-all's label step when it tries every
//   coarse_step-th): a minimum spread over neighbouring labels is a sub-label position, not a
//   doubt.
// - The reference's texture (its luma steps summed over 3x3): on a flat patch every label
//   matches and the margin that remains is noise, so it must not read as sure.
// Occlusion is not a separate term: the data term already takes the mean of each pixel's best
// views, and does not keep which it dropped; an occluded pixel that matches no view shows as a
// small margin.
//
// The margin needs D at the labels away from the chosen one. The winner-take-all that starts the
// stage computes D at every label it tries, pixel by pixel: it keeps the two lowest (Take)
// rather than the data term running again. With coarse_step > 1 it tries every coarse_step-th
// label, all of them apart, so the two are exact; with every label (coarse_step 1), the second
// is the lowest D more than one label from the best as it stood when each label came: when the
// best moves to its neighbour, the label two below the new best is not taken, which can only
// make the margin larger on a minimum's slope. A truth between the labels the winner-take-all
// tried is not seen at all; the moves' label then matches poorly, and the share is small.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/arena.h"
#include "algo/core/image.h"

namespace lb {

struct LabelMargins {
  static constexpr uint8_t kLow = 64;  // below this a pixel counts as low confidence

  uint16_t* best = nullptr;        // the lowest D the winner-take-all saw
  uint16_t* second = nullptr;      // the lowest at a label apart from best's (above)
  uint16_t* best_label = nullptr;  // 16 bits, as the costs: the loop that keeps them vectorizes
  uint8_t* confidence = nullptr;   // the map, row stride = width
  // Finish's rows: 3 of the texture's steps, their column sums (with a 0 either side) and 2 of
  // the reference's luma.
  uint16_t* steps = nullptr;
  uint16_t* column = nullptr;
  uint16_t* luma = nullptr;
  uint32_t* share = nullptr;  // Finish: (256 << 16) / (away + floor), for each away
  int32_t width = 0, height = 0;

  void Carve(Arena& arena, int32_t w, int32_t h);
  bool carved() const { return best != nullptr; }
  // Before the winner-take-all: no label seen.
  void Reset();
  // The winner-take-all's D of `label` for pixels p0..p0+n-1 (d indexed from p0), labels
  // ascending by `step`.
  void Take(const uint16_t* d, int32_t p0, int32_t n, int32_t label, int32_t step);
  // After the moves: the map from the final labels and their D (row stride = width), the
  // winner-take-all's label step and the reference view (RGB8); returns the pixels below kLow.
  int64_t Finish(const uint8_t* labels, const uint16_t* cost, int32_t step,
                 const ConstImageU8& reference);
};

}  // namespace lb
