// Beyond the paper (as Schnabel's efficient RANSAC does): the blocks of an accepted
// plane split into connected patches on the plane's own grid, so two tables at one
// height are two patches; each patch gets its outline polygon on the plane.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "mlmap/planes/block_grid.hpp"

namespace mlmap {

struct Patch {
  std::vector<std::uint32_t> blocks;       // block ids, ascending
  double surface = 0.0;                    // surface units
  std::vector<Eigen::Vector3d> outline;    // m, outer boundary on the plane, counter-clockwise about the normal
  // Cells per raster cell of its area and outline: 1, or more for a surface sampled
  // sparser than the grid (sparse_search.hpp), whose blocks would cover their cells only.
  int raster_step = 1;
};

// A basis (u, v) of the plane with u × v = normal: u horizontal when the plane is not,
// so walls read as (along the wall, up).
void planeBasis(const Eigen::Vector3d& normal, Eigen::Vector3d& u, Eigen::Vector3d& v);

// Blocks are rasterised on a grid of cell_size in the plane (a vertical block over
// its whole height), or, for a plane within 17° of level, on the map's own grid seen
// from above; occupied grid cells within `gap_cells` (Chebyshev) of each other are
// connected. Patches are returned largest first, without outlines (outlineOf).
// `threads`: OpenMP threads for large planes; the patches do not depend on them.
std::vector<Patch> splitIntoPatches(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks,
                                    const Eigen::Vector3d& normal, const Eigen::Vector3d& point,
                                    int gap_cells = 2, int threads = 1);

// The outline of the blocks on the plane through `point`: the boundary loop of their
// raster cells enclosing the most area, counter-clockwise about the normal, corners only.
// `step`: cells per raster cell (Patch::raster_step).
std::vector<Eigen::Vector3d> outlineOf(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks,
                                       const Eigen::Vector3d& normal, const Eigen::Vector3d& point, int step = 1);

}  // namespace mlmap
