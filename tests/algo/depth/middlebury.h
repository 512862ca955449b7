// Loads a Middlebury multi-view set (../shared/data/middlebury) and scores a disparity map the
// way the v2 table does: the share of evaluated (nonocc mask) pixels off by more than 1 px in
// the units of the evaluated pair. Host-side test and benchmark helper; allocates freely.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "algo/core/image.h"
#include "algo/core/status.h"

namespace lb::middlebury {

struct Set {
  std::string name;
  int32_t width = 0, height = 0;
  int32_t reference = 0;
  std::vector<std::vector<uint8_t>> views;  // RGB8, tightly packed, left to right
  std::vector<float> truth;                 // px per view step, <= 0 where unknown
  std::vector<uint8_t> mask;                // nonocc: 255 = evaluated
  float eval_steps = 1;                     // view steps between the evaluated pair
  std::vector<ConstImageU8> Views() const;
};

// The data folder (from LB_SOURCE_DIR or the working directory), empty when absent.
std::string DataDir();
// name: tsukuba, venus, teddy, sawtooth or barn1 (the last two without an occlusion mask here:
// every pixel of known disparity is evaluated).
Status Load(const std::string& dir, const std::string& name, Set* set);
// Percentage of bad pixels of disparities in px per view step, Q8.
double BadPixelPercent(const Set& set, ConstImageU16 disp_q8);
// The same after the one global scale that scores best (for depth known only up to scale):
// exact, over every scale; `best_scale` receives it.
double BestScaleBadPixelPercent(const Set& set, ConstImageU16 disp_q8, double* best_scale);

}  // namespace lb::middlebury
