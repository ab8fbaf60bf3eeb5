// Internal: the map's occupied voxels one by one, each with the plane of the block it
// falls in; shared by the octovis export (ColorOcTree) and the dashboard's voxel layer,
// so both show the same voxels with the same planes.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>

#include "mlmap/map/map.hpp"

namespace mlmap::io {

// m: the OcTree's resolution, or the cell size for a map built without an OcTree.
double occupiedVoxelSize(const Map& map);

// Calls visit(centre, log_odds, plane) for every occupied voxel at that size (pruned
// leaves expanded); plane 0 = none. Without an OcTree, voxels along the blocks.
void forEachOccupiedVoxel(const Map& map, const std::function<void(const Eigen::Vector3d&, float, std::int32_t)>& visit);

}  // namespace mlmap::io
