// Points on the surfaces an ML map's blocks describe, for registration between maps
// and for voxelising a map that has no OcTree.
#pragma once

#include <vector>

#include "mlmap/map/ml_map.hpp"

namespace mlmap {

// Where in its cell a block's samples stand.
enum class SamplePlace {
  CellCentre,  // the cell's centre (the grid's own quantisation)
  PointMean,   // the mean x, y of the points the block collected where it kept them
               // (format 3 maps), else the cell's centre
};

// A horizontal block's height, and a vertical block's extent from its top down every
// `spacing` metres, each at `place` in its cell.
std::vector<Point> blockSurfacePoints(const MLMap& blocks, double spacing,
                                      SamplePlace place = SamplePlace::CellCentre);

}  // namespace mlmap
