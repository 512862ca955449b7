// How a burst's viewpoints hang together, whatever order the frames came in: the shortest tree
// joining the points (the frames' translations, or their images' shifts), grown from the
// reference's. A frame's steps from the reference are its hops along that tree: on a line (a
// rail, a rig) the frames counted along the line, in a cross or a grid the hops to the centre,
// on a hand's burst the chain of nearest viewpoints. The list's order plays no part.
#pragma once

#include <cstdint>

namespace lb {

constexpr int32_t kMaxTreePoints = 16;  // the motion stage's most views

// `count` points of `dims` (1..3) coordinates each, one after the other; `root` the
// reference's. Fills parent[i] (-1 for the root) and hops[i] (0 for the root). False for fewer
// than two points, more than kMaxTreePoints or a root out of range. Prim's tree in double
// arithmetic (squared distances, no square root); a tie goes to the lower index.
bool ViewTree(const double* points, int32_t count, int32_t dims, int32_t root, int32_t* parent,
              int32_t* hops);

}  // namespace lb
