// Internal: one scan's voxel updates applied to an octomap::OcTree in key order, on
// all threads where subtrees are independent (see octree_walk.cpp).
#pragma once

#include <octomap/OcTree.h>

#include <cstdint>
#include <vector>

#include "key_bits.hpp"

namespace mlmap::detail {

// One 16³-voxel chunk of the scan's updates: which voxels were crossed and which hit
// (either may be null). A voxel both crossed and hit counts as hit.
struct ChunkUpdate {
  std::uint64_t code;  // the chunk's Morton code: its node at depth 16 - kChunkBits
  const ChunkWords* free;
  const ChunkWords* hit;
};

// Applies the updates (in ascending chunk code) as OccupancyOcTreeBase::updateNode
// would one voxel at a time, then brings every inner node on their paths up to date
// (or prunes it) once. split_depth: the depth of the subtrees updated in parallel;
// 0 chooses one from the chunks (tests force others).
void updateTree(octomap::OcTree& tree, const std::vector<ChunkUpdate>& chunks, unsigned split_depth = 0);

}  // namespace mlmap::detail
