// Internal: the finest voxels inside an OcTree leaf. A pruned leaf stands for every
// voxel it covers; exports and merges need them one by one.
#pragma once

#include <Eigen/Core>
#include <cmath>

namespace mlmap {

// Calls visit(lower_corner) for each voxel of size `resolution` inside the leaf at
// `leaf` (an OcTree leaf iterator).
template <typename LeafIterator, typename Visit>
void forEachVoxelOfLeaf(const LeafIterator& leaf, double resolution, Visit&& visit) {
  const double size = leaf.getSize();
  const int per_axis = static_cast<int>(std::lround(size / resolution));
  const Eigen::Vector3d corner =
      Eigen::Vector3d(leaf.getX(), leaf.getY(), leaf.getZ()) - Eigen::Vector3d::Constant(size / 2.0);
  for (int a = 0; a < per_axis; ++a) {
    for (int b = 0; b < per_axis; ++b) {
      for (int c = 0; c < per_axis; ++c) visit(Eigen::Vector3d(corner + resolution * Eigen::Vector3d(a, b, c)));
    }
  }
}

}  // namespace mlmap
