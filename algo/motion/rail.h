// The rail test of the motion stage (motion_stage.h): do a burst's adjusted frames lie on one
// line at equal steps, as a slider or a rig holds them? Small motion cannot tell a turn about the
// axis across the baseline from an offset of every inverse depth; a rail holds the camera's
// orientation, so the stage adjusts such a burst again with that turn held (bundle.h).
#pragma once

#include <cstdint>

#include "algo/motion/camera.h"

namespace lb {

constexpr int32_t kMaxRailViews = 16;  // the motion stage's most views

struct RailTolerance {
  // Every frame's translation within off_axis (the sine of the angle) of the line, and its
  // length per view step within spacing (a fraction) of their mean. off_axis 0: never a rail.
  double off_axis = 0.05;
  double spacing = 0.1;
};

// True when the `views` poses (the reference's the identity) lie on a rail: 3..kMaxRailViews
// frames, every non-reference translation along one line, and the frames, counted in their
// order along it from the reference (not in the list's order), at equal steps. `axis` then
// receives the unit axis of the turn that shifts the image along the rail (z x the rail's
// direction, the one small motion confuses with depth); a rail along the optical axis confuses
// nothing and is not one. Double arithmetic without transcendentals.
bool IsRail(const ViewMotion* motion, int32_t views, int32_t reference,
            const RailTolerance& tolerance, double axis[3]);

}  // namespace lb
