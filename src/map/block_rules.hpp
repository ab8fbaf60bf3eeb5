// Section IV's update rules on one cell's block list (Fig. 3), free of any storage:
// the ML map calls them on its arena, a parallel insertion on a scratch copy.
#pragma once

#include "mlmap/map/block.hpp"

namespace mlmap {

// Adds the measurement [bottom, top] (a point when bottom == top) of variance σ_m to
// the cell's blocks, sorted by height and at least `reach` (= cell_size) apart.
// `blocks` must have room for count + 1 blocks. Returns the new count. Whichever
// block takes the measurement (or is made from it) also takes its points' moments.
int addMeasurement(Block* blocks, int count, float top, float bottom, float variance, float reach,
                   const PointStats& points);

}  // namespace mlmap
