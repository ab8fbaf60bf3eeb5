// OcTree exports for OctoMap's tools: a ColorOcTree (.ot) whose occupied voxels carry
// the colour of the plane their block belongs to, for octovis; and the plain
// occupancy tree (.bt, OctoMap's compact binary format: maximum likelihood, pruned).
#pragma once

#include <filesystem>
#include <memory>

#include <octomap/ColorOcTree.h>

#include "mlmap/map/map.hpp"

namespace mlmap::io {

// Occupied voxels only (free space is what --bt keeps), each coloured by
// planeColour() of the block it falls in, grey when none. A map built without an
// OcTree gets voxels from its blocks at the cell size.
std::unique_ptr<octomap::ColorOcTree> colouredOctree(const Map& map);

// Both written atomically; writeBinaryOctree throws when the map has no OcTree.
void writeColouredOctree(const std::filesystem::path& path, const Map& map);
void writeBinaryOctree(const std::filesystem::path& path, const Map& map);

}  // namespace mlmap::io
