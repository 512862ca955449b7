// Pyramidal Lucas-Kanade tracking of reference points into another view, translation only,
// inverse compositional: the reference window and its gradients are sampled once per level, each
// iteration samples only the view. Coarse to fine, the displacement found at one level starts
// the next, so motions of ~(radius + 1) * 2^(levels - 1) px are followed.
//
// Formats: positions are level-0 pixel-index coordinates in Q16 (pixel i's centre is i; level L
// index i is level-0 (i + 0.5) * 2^L - 0.5). Samples are bilinear with Q8 weights, rounded to Q4
// grey (0..4080); gradients are central differences of the Q4 window (Q4 x 2, +-8160). The 5
// sums are int64; only the 2x2 solve per iteration is double (IEEE, no contraction: the same
// bits on every target), rounded to Q16 before it moves the point.
#pragma once

#include <cstdint>

#include "algo/core/arena.h"
#include "algo/core/status.h"
#include "algo/core/task_runner.h"
#include "algo/motion/pyramid.h"
#include "algo/motion/tracker_kernels.h"

namespace lb {

struct TrackerParams {
  int32_t radius = 4;           // window (2r+1)^2, 1..8
  int32_t max_iterations = 12;  // per level
  int32_t max_error_q4 = 48;    // final mean |view - reference| over the window, Q4 grey
};

class Tracker {
 public:
  // Window buffers for each of `workers` workers (1..kMaxWorkers).
  Status Carve(const TrackerParams& params, Arena& arena, int32_t workers = 1);

  // Tracks `n` points from `ref` into `view` (same sizes and levels). Start guesses are the
  // displacements in `dx_q16`/`dy_q16` (0 for none); on return they hold the tracked
  // displacement, and ok[i] is 1 where the point was followed to level 0 with a small error.
  // A point with a guess is also tracked from no motion, which wins where the guess fails or
  // matches twice as badly: a repetitive texture (bricks, tiles) locks onto a wrong period from
  // a start too far off, and a wrong guess (a frame that went back) must not cost the point
  // either.
  // Points are independent: `runner` (nullptr: the caller) tracks runs of them on its workers,
  // at most the carved number, with the same result.
  void Track(const GreyPyramid& ref, const GreyPyramid& view, const int32_t* x_q16,
             const int32_t* y_q16, int32_t n, int32_t* dx_q16, int32_t* dy_q16, uint8_t* ok,
             TaskRunner* runner = nullptr) const;

 private:
  // One worker's window.
  struct Window {
    int32_t* tmpl = nullptr;   // (2r+3)^2 reference samples, Q4
    int32_t* inner = nullptr;  // (2r+1)^2: its inner window, row after row
    int32_t* gx = nullptr;     // (2r+1)^2
    int32_t* gy = nullptr;
  };
  void TrackRange(const Window& w, const GreyPyramid& ref, const GreyPyramid& view,
                  const int32_t* x_q16, const int32_t* y_q16, int32_t begin, int32_t end,
                  int32_t* dx_q16, int32_t* dy_q16, uint8_t* ok) const;
  // Coarse to fine from level `top`; `error_q4` receives the final mean |view - reference|
  // over the window.
  bool TrackOne(const Window& w, const GreyPyramid& ref, const GreyPyramid& view, int32_t x_q16,
                int32_t y_q16, int32_t top, int32_t* dx_q16, int32_t* dy_q16,
                int32_t* error_q4) const;

  TrackerParams params_;
  const tk::Kernels* kernels_ = &tk::kReference;  // picked at Carve (tracker_kernels.h)
  Window windows_[kMaxWorkers];
  int32_t workers_ = 1;
};

}  // namespace lb
