// Merging the maps of adjacent spaces (the paper's Fig. 11 joins a corridor and a lab
// mapped apart). Both layers merge: OcTree occupancy is fused (log-odds added, then
// pruned) and the other map's blocks are re-inserted into the base map's cells by the
// rules of section IV, so a wall both maps saw becomes one block list, not two.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>

#include "mlmap/map/map.hpp"

namespace mlmap {

struct MergeStats {
  std::size_t base_blocks = 0;       // before the merge
  std::size_t other_blocks = 0;
  std::size_t merged_blocks = 0;     // after: less than the sum where the maps overlap
  std::size_t base_cells = 0;
  std::size_t other_cells = 0;
  std::size_t merged_cells = 0;
  std::size_t fused_voxels = 0;      // OcTree voxel updates made
  double dropped_tilt_deg = 0.0;     // roll/pitch of the transform that was not applied
};

// The transform without its roll and pitch (yaw and translation kept); `tilt_deg`
// receives the tilt removed.
Eigen::Isometry3d levelledTransform(const Eigen::Isometry3d& transform, double& tilt_deg);

// Merges `other` into `base`; `other_to_base` maps other's frame into base's. ML maps
// are gravity-aligned, so only yaw and translation apply: a transform tilted by up to
// `max_tilt_deg` is levelled (the tilt dropped is reported), a larger tilt throws
// mlmap::Error, as do different cell sizes or OcTree resolutions. Cells are resampled
// by nearest neighbour (each base cell takes the other map's cell under its centre).
// The base map's planes and labels are cleared: detect them again on the merged map.
MergeStats mergeInto(Map& base, const Map& other, const Eigen::Isometry3d& other_to_base,
                     double max_tilt_deg = 1.0);

}  // namespace mlmap
