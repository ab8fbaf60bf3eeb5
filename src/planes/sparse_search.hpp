// Beyond the paper: surfaces seen only sparsely, with no patch beside them to grow from.
// A single scan samples a far wall on a lattice of points as wide as the angular step
// times the range (PCL's room_scan1: its wall at 8 m is points 14-17 cm apart, one per
// 5 cm cell). No block of it has a direction (a window of r cells holds none of its
// neighbours), so no candidate is seeded there, and the sparse growth (sparse_growth.hpp)
// starts only from a patch. Here the neighbourhood is measured in metres, not cells: each
// such block's nearest such blocks within the sparse gap give it a local plane; the
// flattest local planes seed regions grown over their neighbours within ε; a region
// becomes a patch when it is a level or plumb surface as flat as a patch must be, spread in
// two directions and large enough, and its blocks lie further apart than a direction
// window reaches (else it was dense enough for the search, which did not take it).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "mlmap/planes/block_grid.hpp"
#include "mlmap/planes/patches.hpp"
#include "plane_scorer.hpp"

namespace mlmap {

struct SparseSearch {
  double max_gap = 0.0;       // m: neighbours further apart are not neighbours (ErmsmConfig::sparse_gap)
  double epsilon = 0.0;       // m: a region's blocks lie within this of its plane
  double max_tilt_rad = 0.0;  // only regions this close to level or to plumb
  double ladder_gap = 0.0;    // m: a level region takes no rung of a wall (as the sparse growth)
  std::size_t min_blocks = 6;
  double min_area = 0.0;      // m²: of its blocks' surface, as every patch (ErmsmConfig::min_patch_area)
};

struct SparseSurface {
  CandidatePlane plane;  // its blocks' least-squares plane
  Patch patch;           // blocks ascending; surface in surface units (their blocks')
};

// The sparse surfaces among the blocks with no direction (a zero vector) and no patch
// (labels[id] == 0), largest first.
std::vector<SparseSurface> findSparseSurfaces(const BlockGrid& grid, const std::vector<Eigen::Vector3f>& directions,
                                              const std::vector<std::int32_t>& labels, const SparseSearch& config);

}  // namespace mlmap
