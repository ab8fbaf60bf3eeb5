// Points on the surfaces an ML map's blocks describe, for registration between maps
// and for voxelising a map that has no OcTree.
#pragma once

#include <vector>

#include "mlmap/map/ml_map.hpp"

namespace mlmap {

// At each cell centre: a horizontal block's height, and a vertical block's extent from
// its top down every `spacing` metres.
std::vector<Point> blockSurfacePoints(const MLMap& blocks, double spacing);

}  // namespace mlmap
