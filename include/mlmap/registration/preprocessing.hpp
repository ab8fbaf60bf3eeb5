// Scan preprocessing before ICP: range cropping and voxel down-sampling of the source
// (one centroid per OcTree voxel, as the peers' voxel grids do).
#pragma once

#include <limits>
#include <vector>

#include "mlmap/scan.hpp"

namespace mlmap::registration {

// The centroid of the points in each voxel of size `voxel_size` (OcTree keys), ordered
// by each voxel's first point, so the result does not depend on hashing. Only the points
// whose distance from the sensor origin lies in [min_range, max_range] count: cropRange
// without the copy.
std::vector<Point> voxelDownSample(const std::vector<Point>& points, double voxel_size, double min_range = 0.0,
                                   double max_range = std::numeric_limits<double>::infinity());

// The points whose distance from the sensor origin lies in [min_range, max_range].
std::vector<Point> cropRange(const std::vector<Point>& points, double min_range, double max_range);

}  // namespace mlmap::registration
