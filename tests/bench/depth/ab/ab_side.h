// The depth stage of two revisions in one process (scripts/ab_depth.sh): this header names no
// namespace of the product, so that ab_side.cc can be compiled once against each revision's
// algo/, the other one's renamed by the preprocessor (-Dlb=lbref).
#pragma once

#include <cstdint>

// A scene as plain data, the same for both sides.
struct AbScene {
  int32_t width = 0, height = 0, views = 0, reference = 0, labels = 0;
  int32_t disp_min_q8 = 0, disp_max_q8 = 0;
  bool known_poses = false;  // plane sweep (planes below) instead of rectified shifts
  bool subpixel = true;
  const uint8_t* const* pixels = nullptr;  // RGB8, width * 3 bytes a row, one per view
  const int64_t* planes = nullptr;         // known_poses: [(view * labels + label) * 9 + i]
};

// A configured stage for the scene (nullptr when it refuses it), and the time of one Compute
// in milliseconds into disp (width * height), negative on failure.
void* AbMakeCurrent(const AbScene& scene);
double AbRunCurrent(void* side, uint16_t* disp);
void* AbMakeReference(const AbScene& scene);
double AbRunReference(void* side, uint16_t* disp);
