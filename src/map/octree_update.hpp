// One scan's rays into an octomap::OcTree, with OctoMap's insertPointCloud semantics:
// every ray frees the voxels it crosses and occupies its end voxel (unless cut at the
// maximum range), a voxel both crossed and hit in one scan counts as hit, and every
// voxel is updated once per scan. The rays are cast on all threads into flat voxel
// sets; the tree is then updated in key order, each inner node once, independent
// subtrees on all threads.
#pragma once

#include <octomap/OcTree.h>

#include "mlmap/scan.hpp"

namespace mlmap::detail {

struct RayOptions {
  double max_range = -1.0;  // m; rays are cut here and their end not marked; < 0 = no limit
  // false: the end points are first merged per voxel and one ray is cast to the centre
  // of each end voxel (insertPointCloud(..., discretize = true)); true: one ray per point.
  bool exact_rays = false;
  // The depth of the subtrees updated in parallel; 0 = chosen from the scan (tests force
  // others).
  unsigned split_depth = 0;
};

void insertRays(octomap::OcTree& tree, const Scan& scan, const RayOptions& options);

}  // namespace mlmap::detail
