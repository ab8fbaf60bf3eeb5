// Internal to the registration module: the blocks of voxels a VoxelHashMap indexes its
// voxels by (wide searches, grown normal neighbourhoods).
#pragma once

#include <cstdint>

#include "mlmap/registration/voxel_hash_map.hpp"

namespace mlmap::registration::voxel_blocks {

// Blocks of 2^kBlockShift voxels a side. A wide search's cost is the blocks its box overlaps
// plus the occupied voxels in the blocks its sphere reaches. At 4 voxels (0.4 m at the maps'
// 0.1 m) an occupied block holds few of its 64 voxels (the stress benchmark's scans, tune
// split: mean 6.5-16, 90th percentile 16-32), and a 1.5 m gate's box holds ~600 blocks where it
// holds ~27,000 voxels: the wide basin's ICP runs took 4.5x less time searching (42 runs from
// 10-30 deg off, 32.9 -> 7.3 s, the same results to the bit).
inline constexpr int kBlockShift = 2;
inline constexpr std::int32_t kBlock = 1 << kBlockShift;
inline VoxelKey blockOf(const VoxelKey& key) {  // arithmetic shift: floor division for negative keys too
  return {key.x >> kBlockShift, key.y >> kBlockShift, key.z >> kBlockShift};
}

inline VoxelKey operator+(const VoxelKey& a, const VoxelKey& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }

}  // namespace mlmap::registration::voxel_blocks
